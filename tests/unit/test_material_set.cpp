// The material sets of material_set.h: which scenes a DiffuseOnly renderer may render, and that
// on those it computes exactly what the renderer for every material computes (the GPU labs
// launch the DiffuseOnly kernel for such scenes and promise the same image).
#include <gtest/gtest.h>

#include <cstring>

#include "path_tracer.h"
#include "scene_loader.h"

namespace {

Material material(MaterialType type) {
    Material m{};
    m.type = type;
    m.albedo = Vec3(0.6f, 0.5f, 0.4f);
    m.ior = 1.5f;
    return m;
}

// A closed diffuse box of two walls' worth of triangles (a floor and a ceiling) and a ball,
// lit from inside: paths bounce between diffuse surfaces until their budget runs out.
Scene diffuse_box() {
    Scene s;
    s.materials = {material(material_type<Diffuse>), material(material_type<Diffuse>)};
    s.material_names = {"walls", "ball"};
    const Vec3 a(-1, 0, -1), b(-1, 0, 1), c(1, 0, 1), d(1, 0, -1);
    const Vec3 up(0, 2, 0);
    s.of<Triangle>() = {make_triangle(a, b, c, 0), make_triangle(a, c, d, 0),
                        make_triangle(a + up, c + up, b + up, 0),
                        make_triangle(a + up, d + up, c + up, 0)};
    Sphere ball{};
    ball.center = {0.3f, 0.4f, 0.1f};
    ball.radius = 0.3f;
    ball.material = 1;
    s.of<Sphere>() = {ball};
    s.has_light = true;
    s.light.position = {-0.2f, 1.5f, 0.2f};
    s.light.intensity = Vec3(2.0f);
    s.background = {0.05f, 0.1f, 0.2f};
    return s;
}

bool same_bits(Vec3 a, Vec3 b) { return std::memcmp(&a, &b, sizeof(Vec3)) == 0; }

}  // namespace

TEST(MaterialKinds, OnlyMirrorOrGlassNeedsTheRendererForEveryMaterial) {
    const Material diffuse = material(material_type<Diffuse>);
    const Material mirror = material(material_type<Mirror>);
    const Material glass = material(material_type<Glass>);
    const Material all_diffuse[] = {diffuse, diffuse, diffuse};
    const Material with_mirror[] = {diffuse, mirror, diffuse};
    const Material with_glass[] = {diffuse, diffuse, glass};
    EXPECT_FALSE(has_specular_material(all_diffuse, 3));
    EXPECT_TRUE(has_specular_material(with_mirror, 3));
    EXPECT_TRUE(has_specular_material(with_glass, 3));
    EXPECT_TRUE(has_specular_material(with_glass + 2, 1));
    EXPECT_FALSE(has_specular_material(with_glass, 2));  // only the table's first two entries
    EXPECT_FALSE(has_specular_material(nullptr, 0));
    static_assert(!has_specular<DiffuseOnly> && has_kind<AnyMaterial, Mirror> &&
                  has_kind<AnyMaterial, Glass>);
}

// Every path of a diffuse scene, traced by the DiffuseOnly renderer and by the one for every
// material, gives the same bits: the specialisation removes code, never changes arithmetic.
TEST(MaterialKinds, DiffuseOnlyTracesADiffuseSceneBitForBit) {
    const Scene scene = diffuse_box();
    const SceneView v = scene.view();
    ASSERT_FALSE(has_specular_material(v.materials, v.num_materials));
    int lit = 0;
    for (uint64_t s = 0; s < 400; ++s) {
        const SampleStream rng(7, s % 17, s);
        const Ray ray{{0.1f, 1.0f, -0.2f},
                      normalize(Vec3(rng.at(0) - 0.5f, rng.at(1) - 0.5f, 0.3f))};
        const Vec3 any = trace_path<AnyMaterial>(v, ray, rng, 8);
        const Vec3 diffuse = trace_path<DiffuseOnly>(v, ray, rng, 8);
        ASSERT_TRUE(same_bits(any, diffuse)) << "sample " << s;
        lit += any.x > 0.0f;
    }
    EXPECT_GT(lit, 300);  // the comparison saw light, not 400 black paths
}

// The set is a promise about the scene: a DiffuseOnly renderer treats a mirror as diffuse,
// so the dispatch (has_specular_material) must be asked, which this shows is not a no-op.
// A ray straight down between mirror floor and mirror ceiling bounces up and down and never
// sees the light; treated as diffuse, the floor samples the light (unblocked) at once.
TEST(MaterialKinds, DiffuseOnlyRendersAMirrorWrong) {
    Scene scene = diffuse_box();
    scene.materials[0] = material(material_type<Mirror>);
    const SceneView v = scene.view();
    ASSERT_TRUE(has_specular_material(v.materials, v.num_materials));
    const Ray down{{-0.5f, 1.0f, -0.5f}, {0.0f, -1.0f, 0.0f}};
    for (uint64_t s = 0; s < 20; ++s) {
        const SampleStream rng(7, 3, s);
        EXPECT_TRUE(is_black(trace_path<AnyMaterial>(v, down, rng, 4))) << "sample " << s;
        EXPECT_GT(trace_path<DiffuseOnly>(v, down, rng, 4).x, 0.0f) << "sample " << s;
    }
}
