// Lab 05's choices on the host (no GPU needed): which kernel a scene gets
// (common/cuda/kernel_choice.cuh), where its pool lives (scene_constant.cuh), the scene's
// primitives re-expressed (general_geometry.h) and RT_LAB05_GEOMETRY's values. Exits 0 when
// every case holds, else prints each that does not and exits 1. Built and run by
// tests/labs/test_lab05.py.
#include <cstdio>
#include <string>
#include <type_traits>

#include <general_geometry.h>
#include <kernel_choice.cuh>
#include <scene_constant.cuh>

static int failures = 0;

static void expect(bool ok, const std::string& what) {
    if (ok) return;
    std::printf("FAIL %s\n", what.c_str());
    ++failures;
}

// The kernel with_kernel_choice picks, as "memory/materials/primitives".
template <class Choice>
static std::string name_of() {
    using M = typename Choice::Materials;
    using P = typename Choice::Primitives;
    std::string s = Choice::kMemory == SceneMemory::Constant ? "constant" : "global";
    s += std::is_same_v<M, DiffuseOnly> ? "/diffuse" : "/any-material";
    s += std::is_same_v<P, BoxGeometry>       ? "/box"
         : std::is_same_v<P, GeneralGeometry> ? "/general"
         : std::is_same_v<P, AnyGeometry>     ? "/any-geometry"
                                              : "/other";
    return s;
}

static std::string choice(SceneMemory memory, bool specular, GeometryKinds kinds) {
    return with_kernel_choice(memory, specular, kinds,
                              [](auto c) { return name_of<decltype(c)>(); });
}

static void expect_choice(SceneMemory memory, bool specular, GeometryKinds kinds,
                          const std::string& wanted) {
    const std::string got = choice(memory, specular, kinds);
    expect(got == wanted, "kernel choice: got " + got + ", wanted " + wanted);
}

int main() {
    expect_choice(SceneMemory::Constant, false, geometry_kinds_of<Kinds<Sphere, AxisRect>>(),
                  "constant/diffuse/box");
    expect_choice(SceneMemory::Global, true, geometry_kinds_of<Kinds<AxisRect>>(),
                  "global/any-material/box");
    expect_choice(SceneMemory::Constant, false, geometry_kinds_of<Kinds<Sphere, ConvexQuad>>(),
                  "constant/diffuse/general");
    expect_choice(SceneMemory::Constant, true,
                  geometry_kinds_of<Kinds<Sphere, Triangle, ConvexQuad>>(),
                  "constant/any-material/general");
    expect_choice(SceneMemory::Constant, false, geometry_kinds_of<Kinds<Triangle, AxisRect>>(),
                  "constant/diffuse/any-geometry");
    expect_choice(SceneMemory::Global, false,
                  geometry_kinds_of<Kinds<Sphere, Triangle, ConvexQuad, AxisRect>>(),
                  "global/diffuse/any-geometry");

    // The constant bank while the pool fits in it, else global memory.
    SceneLayout layout;
    layout.words = static_cast<int>(kConstantPoolBytes / 16);
    expect(choose_megakernel_scene_memory(layout) == SceneMemory::Constant, "a full bank");
    layout.words += 1;
    expect(choose_megakernel_scene_memory(layout) == SceneMemory::Global, "one word too many");

    // A scene with one of each kind of primitive.
    const Vec3 corners[4] = {{0, 0, -1}, {1, 0, -1}, {1, 1, -1}, {0, 1, -1}};  // z = -1, +z front
    const AxisRect rect = make_axis_rect(corners, axis_rect_axis(corners), 2);
    const ConvexQuad quad = make_convex_quad({0, 0, 0}, {0, 0, -1}, {0, 1, -1}, {0, 1, 0}, 1);
    const Triangle triangle = make_triangle({1, 0, 0}, {1, 1, 0}, {1, 1, -1}, 0);
    const Sphere sphere{{0.5f, 0.2f, -0.5f}, 0.2f, 0};
    const Material material{};
    SceneView scene{{}, &material, 1, {}, false, {}};
    scene.of<Sphere>() = {&sphere, 1};
    scene.of<Triangle>() = {&triangle, 1};
    scene.of<ConvexQuad>() = {&quad, 1};
    scene.of<AxisRect>() = {&rect, 1};

    const SceneInForm as_loaded(scene, GeometryForm::AsLoaded);
    expect(
        as_loaded.view.of<AxisRect>().count == 1 && as_loaded.view.of<AxisRect>().items == &rect &&
            as_loaded.view.of<ConvexQuad>().count == 1 && as_loaded.view.of<Triangle>().count == 1,
        "as loaded: the scene's own arrays");

    const SceneInForm quads(scene, GeometryForm::Quads);
    expect(quads.view.of<AxisRect>().count == 0 && quads.view.of<ConvexQuad>().count == 2 &&
               quads.view.of<Triangle>().count == 1 && quads.view.of<Sphere>().count == 1 &&
               quads.view.of<Triangle>().items == &triangle,
           "quads: the rectangle joins the quads, the rest stays");
    const ConvexQuad& from_rect = quads.view.of<ConvexQuad>()[1];
    const Vec3 n = rect_normal(rect);
    expect(from_rect.normal.x == n.x && from_rect.normal.y == n.y && from_rect.normal.z == n.z &&
               from_rect.material == rect.material && from_rect.extent == rect.extent,
           "quads: the rectangle's normal, material and extent");
    // The same surface to the last bit for rays through its inside, and no hit off it.
    for (float x : {0.1f, 0.37f, 0.5f, 0.93f, 1.2f}) {
        for (float y : {-0.3f, 0.05f, 0.5f, 0.77f}) {
            const Ray ray{Vec3(0.3f, 0.6f, 0.5f), normalize(Vec3(x - 0.3f, y - 0.6f, -1.5f))};
            const real t_rect = intersect_rect(ray, rect, kRealMax);
            const real t_quad = intersect_quad(ray, RayShear(ray.direction), from_rect, kRealMax);
            expect(t_rect == t_quad, "quads: the same distance for the ray through (" +
                                         std::to_string(x) + ", " + std::to_string(y) + ")");
        }
    }

    const SceneInForm triangles(scene, GeometryForm::Triangles);
    expect(triangles.view.of<AxisRect>().count == 0 && triangles.view.of<ConvexQuad>().count == 0 &&
               triangles.view.of<Triangle>().count == 5,
           "triangles: every quad and rectangle as two triangles");
    expect(geometry_kinds(triangles.view).fits<Kinds<Sphere, Triangle>>(),
           "triangles: spheres and triangles only");

    // RT_LAB05_GEOMETRY.
    expect(lab05_geometry_form(nullptr) == GeometryForm::AsLoaded, "unset");
    expect(lab05_geometry_form("") == GeometryForm::AsLoaded, "empty");
    expect(lab05_geometry_form("scene") == GeometryForm::AsLoaded, "scene");
    expect(lab05_geometry_form("general") == GeometryForm::Quads, "general");
    for (const char* bad : {"General", "general ", "quads", "1"}) {
        try {
            lab05_geometry_form(bad);
            expect(false, std::string("'") + bad + "' is refused");
        } catch (const InputError& e) {
            expect(std::string(e.what()).find("RT_LAB05_GEOMETRY") != std::string::npos,
                   "the error names the variable");
        }
    }

    if (failures == 0) std::printf("lab 05 kernel choice: every case holds\n");
    return failures == 0 ? 0 : 1;
}
