// Strict scene loading: valid files load as written (each quad as the kind it is: an
// axis-aligned rectangle, a planar convex quad, or two triangles), and every
// mistake is an InputError naming the file, the line and column of the offending token, and
// what was expected.
//
// Error cases mark the offending token with '@' in the text: the test computes the expected
// "line L, column C" from the marker's place, then removes it before parsing.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "cli.h"
#include "errors.h"
#include "json_with_positions.h"
#include "scene_centring.h"
#include "scene_loader.h"

namespace {

const char* const kName = "case.json";

struct Marked {
    std::string text;      // without the marker
    std::string position;  // "case.json:line L, column C:", the marker's place as reported
};

Marked unmark(const std::string& marked, char marker = '@') {
    const size_t at = marked.find(marker);
    EXPECT_NE(at, std::string::npos) << "test bug: no marker";
    EXPECT_EQ(marked.find(marker, at + 1), std::string::npos) << "test bug: two markers";
    int line = 1, column = 1;
    for (size_t i = 0; i < at; ++i) {
        if (marked[i] == '\n') {
            ++line;
            column = 1;
        } else {
            ++column;
        }
    }
    std::string text = marked;
    text.erase(at, 1);
    return {text, std::string(kName) + ":line " + std::to_string(line) + ", column " +
                      std::to_string(column) + ":"};
}

// The message of the InputError that parsing throws, or "" (with a failure) if none.
std::string error_of(const std::string& text) {
    try {
        parse_scene(text, kName);
    } catch (const InputError& e) {
        return e.what();
    } catch (const std::exception& e) {
        ADD_FAILURE() << "threw something other than InputError: " << e.what();
        return "";
    }
    ADD_FAILURE() << "parsed without error:\n" << text;
    return "";
}

// Parses `marked`, expects an InputError at the marker naming the file and every word.
void expect_error(const std::string& marked, const std::vector<std::string>& words) {
    const Marked m = unmark(marked);
    const std::string message = error_of(m.text);
    if (message.empty()) return;
    EXPECT_EQ(message.rfind(kName, 0), 0u) << "does not start with the file name: " << message;
    EXPECT_NE(message.find(m.position), std::string::npos)
        << "expected " << m.position << " in: " << message;
    for (const std::string& w : words)
        EXPECT_NE(message.find(w), std::string::npos) << "no '" << w << "' in: " << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << "not one line: " << message;
}

// A valid scene with a hole for one more top-level member and a sphere's fields.
std::string scene_with(const std::string& sphere_fields, const std::string& extra = "") {
    return "{\n"
           "  \"camera\": { \"position\": [0, 0, 5], \"look_at\": [0, 0, 0] },\n"
           "  \"materials\": {\n"
           "    \"white\": { \"type\": \"diffuse\", \"albedo\": [0.5, 0.5, 0.5] }\n"
           "  },\n" +
           extra +
           "  \"spheres\": [\n"
           "    { " +
           sphere_fields +
           " }\n"
           "  ]\n"
           "}\n";
}

const std::string kGoodSphere = "\"center\": [0, 0, 0], \"radius\": 1, \"material\": \"white\"";

}  // namespace

// ---- valid scenes ------------------------------------------------------------------------

TEST(SceneLoader, CornellLoads) {
    const Scene s = load_scene(source_tree_path("common/scenes/cornell.json"));
    EXPECT_EQ(s.of<Sphere>().size(), 1u);
    EXPECT_EQ(s.of<Triangle>().size(), 0u);
    EXPECT_EQ(s.of<ConvexQuad>().size(), 0u);
    EXPECT_EQ(s.of<AxisRect>().size(), 5u);  // five axis-aligned walls
    EXPECT_EQ(s.materials.size(), 4u);
    EXPECT_EQ(s.material_names.size(), s.materials.size());
    EXPECT_TRUE(s.has_light);
    // The light is inside the unit box and shines; the camera looks in through the open side.
    for (float c : {s.light.position.x, s.light.position.y}) {
        EXPECT_GT(c, 0.0f);
        EXPECT_LT(c, 1.0f);
    }
    EXPECT_GT(s.light.intensity.x, 0.0f);
    EXPECT_GT(s.camera.position.z, 0.0f);
    EXPECT_GT(s.camera.vfov_degrees, 0.0f);
    EXPECT_GT(s.of<Sphere>()[0].radius, 0.0f);
    // The design's baseline: 600x600, 512 spp, 4 bounces.
    EXPECT_EQ(s.render.width, 600);
    EXPECT_EQ(s.render.height, 600);
    EXPECT_EQ(s.render.spp, 512);
    EXPECT_EQ(s.render.bounces, 4);
    for (const AxisRect& r : s.of<AxisRect>()) {
        ASSERT_GE(r.material, 0);
        ASSERT_LT(r.material, static_cast<int>(s.materials.size()));
        EXPECT_LT(r.lo_u, r.hi_u);
        EXPECT_LT(r.lo_v, r.hi_v);
    }
    // The sphere uses "ball".
    EXPECT_EQ(s.material_names[s.of<Sphere>()[0].material], "ball");
    EXPECT_EQ(s.materials[s.of<Sphere>()[0].material].type, material_type<Diffuse>);
    // Every wall faces into the box, towards its centre (0.5, 0.5, -0.5).
    for (const AxisRect& r : s.of<AxisRect>()) {
        const Vec3 to_centre = Vec3(0.5f, 0.5f, -0.5f) - along_axis(rect_axis(r), r.plane);
        EXPECT_GT(dot(rect_normal(r), to_centre), 0.0f);
    }
}

TEST(SceneLoader, EveryShippedSceneLoads) {
    const std::string dir = source_tree_path("common/scenes");
    int count = 0;
    for (const auto& entry : std::filesystem::directory_iterator(dir)) {
        if (entry.path().extension() != ".json") continue;
        ++count;
        EXPECT_NO_THROW(load_scene(entry.path().string())) << entry.path();
    }
    EXPECT_GE(count, 1);
}

TEST(SceneLoader, MissingFileIsAnInputErrorNamingIt) {
    const std::string path = source_tree_path("no/such/scene.json");
    try {
        load_scene(path);
        FAIL() << "no error";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    }
}

TEST(SceneLoader, ErrorsFromAFileNameThePath) {
    const std::string path = ::testing::TempDir() + "rt-unit-bad-scene.json";
    {
        std::ofstream out(path);
        out << "{\n  \"camera\": { \"position\": [0, 0, 5], \"look_at\": [0, 0, 0] },\n"
               "  \"materials\": { \"w\": { \"type\": \"diffuse\", \"albedo\": [0.5, 0.5, 0.5] } },\n"
               "  \"spheres\": [ { \"center\": [0, 0, 0], \"radius\": -2, \"material\": \"w\" } ]\n}\n";
    }
    try {
        load_scene(path);
        ADD_FAILURE() << "no error";
    } catch (const InputError& e) {
        const std::string m = e.what();
        EXPECT_EQ(m.rfind(path + ":line 4, column 49:", 0), 0u) << m;
        EXPECT_NE(m.find("radius > 0"), std::string::npos) << m;
    }
    std::remove(path.c_str());
}

TEST(SceneLoader, MinimalSceneGetsDefaults) {
    const Scene s = parse_scene(R"({"camera": {"position": [0, 0, 5], "look_at": [0, 0, 0]},
        "materials": {"m": {"type": "diffuse", "albedo": [0.1, 0.2, 0.3]}}})",
                                "min");
    EXPECT_EQ(s.name, "min");
    EXPECT_FALSE(s.has_light);
    EXPECT_TRUE(is_black(s.background));
    EXPECT_TRUE(s.of<Sphere>().empty());
    EXPECT_TRUE(s.of<Triangle>().empty());
    EXPECT_EQ(s.render.width, 600);
    EXPECT_EQ(s.render.height, 600);
    EXPECT_EQ(s.render.spp, 512);
    EXPECT_EQ(s.render.bounces, 4);
    EXPECT_EQ(s.render.seed, 0u);
    EXPECT_FLOAT_EQ(s.camera.up.y, 1.0f);
    EXPECT_FLOAT_EQ(s.camera.vfov_degrees, 55.0f);
    ASSERT_EQ(s.materials.size(), 1u);
    EXPECT_EQ(s.materials[0].type, material_type<Diffuse>);
    EXPECT_FLOAT_EQ(s.materials[0].albedo.z, 0.3f);
}

TEST(SceneLoader, EverythingAsWritten) {
    const Scene s = parse_scene(R"({
  "camera": { "position": [1, 2, 3], "look_at": [0, 0, 0], "up": [0, 0, 1], "vfov": 40 },
  "background": [0.1, 0.2, 0.3],
  "light": { "position": [4, 5, 6], "intensity": [7, 8, 9] },
  "materials": {
    "glass": { "type": "glass", "ior": 1.5 },
    "white": { "type": "diffuse", "albedo": [0.73, 0.73, 0.73] },
    "steel": { "type": "mirror",  "albedo": [0.9, 0.8, 0.7] }
  },
  "spheres":   [ { "center": [0.5, 0.2, -0.25], "radius": 0.2, "material": "steel" },
                 { "center": [1, 1, 1], "radius": 3e-3, "material": "glass" } ],
  "triangles": [ { "vertices": [[0,0,0], [1,0,0], [1,0,-1]], "material": "white" } ],
  "quads":     [ { "vertices": [[0,0,0], [0,1,0], [0,1,-1.5], [0,0,-1]], "material": "glass" } ],
  "render":    { "width": 320, "height": 240, "spp": 16, "bounces": 7, "seed": 99 }
})",
                                kName);
    EXPECT_FLOAT_EQ(s.camera.up.z, 1.0f);
    EXPECT_FLOAT_EQ(s.camera.vfov_degrees, 40.0f);
    EXPECT_FLOAT_EQ(s.background.y, 0.2f);
    EXPECT_TRUE(s.has_light);
    EXPECT_FLOAT_EQ(s.light.position.z, 6.0f);
    EXPECT_FLOAT_EQ(s.light.intensity.x, 7.0f);
    ASSERT_EQ(s.materials.size(), 3u);
    auto material = [&](const std::string& name) -> const Material& {
        for (size_t i = 0; i < s.material_names.size(); ++i)
            if (s.material_names[i] == name) return s.materials[i];
        ADD_FAILURE() << "no material " << name;
        return s.materials[0];
    };
    EXPECT_EQ(material("glass").type, material_type<Glass>);
    EXPECT_FLOAT_EQ(material("glass").ior, 1.5f);
    EXPECT_EQ(material("steel").type, material_type<Mirror>);
    EXPECT_FLOAT_EQ(material("steel").albedo.z, 0.7f);
    EXPECT_EQ(material("white").type, material_type<Diffuse>);
    ASSERT_EQ(s.of<Sphere>().size(), 2u);
    EXPECT_EQ(s.material_names[s.of<Sphere>()[0].material], "steel");
    EXPECT_EQ(s.material_names[s.of<Sphere>()[1].material], "glass");
    EXPECT_FLOAT_EQ(s.of<Sphere>()[1].radius, 3e-3f);
    // One triangle, and a quad that is planar but no rectangle, and shares an edge with the
    // triangle: a convex quad.
    ASSERT_EQ(s.of<Triangle>().size(), 1u);
    ASSERT_EQ(s.of<ConvexQuad>().size(), 1u);
    EXPECT_EQ(s.material_names[s.of<Triangle>()[0].material], "white");
    EXPECT_EQ(s.material_names[s.of<ConvexQuad>()[0].material], "glass");
    EXPECT_EQ(s.of<ConvexQuad>()[0].v2.z, -1.5f);
    EXPECT_EQ(s.of<ConvexQuad>()[0].normal.x, -1.0f);  // (v1 - v0) x (v2 - v0) points to -x
    EXPECT_EQ(s.render.width, 320);
    EXPECT_EQ(s.render.height, 240);
    EXPECT_EQ(s.render.spp, 16);
    EXPECT_EQ(s.render.bounces, 7);
    EXPECT_EQ(s.render.seed, 99u);
}

namespace {

// A scene of the given quads (JSON arrays of four points) and triangles, all white.
std::string scene_of(
    const std::vector<std::string>& quads, const std::vector<std::string>& triangles = {},
    const std::string& camera = R"("position": [0.5, 0.5, 3], "look_at": [0.5, 0.5, 0])") {
    std::string text = R"({"camera": {)" + camera + R"(},
        "materials": {"white": {"type": "diffuse", "albedo": [0.5, 0.5, 0.5]}}, "quads": [)";
    for (size_t i = 0; i < quads.size(); ++i)
        text +=
            (i ? ", " : "") + std::string(R"({"material": "white", "vertices": )") + quads[i] + "}";
    text += R"(], "triangles": [)";
    for (size_t i = 0; i < triangles.size(); ++i)
        text += (i ? ", " : "") + std::string(R"({"material": "white", "vertices": )") +
                triangles[i] + "}";
    return text + "]}";
}

struct PrimitiveCounts {
    size_t triangles, quads, rects;
};
PrimitiveCounts kinds_of(const std::string& text) {
    const Scene s = parse_scene(text, kName);
    return {s.of<Triangle>().size(), s.of<ConvexQuad>().size(), s.of<AxisRect>().size()};
}

}  // namespace

TEST(SceneLoader, EachQuadBecomesTheKindItIs) {
    const auto one = [](const std::string& quad) { return kinds_of(scene_of({quad})); };
    const auto is = [](PrimitiveCounts k, size_t t, size_t q, size_t r) {
        return k.triangles == t && k.quads == q && k.rects == r;
    };
    EXPECT_TRUE(is(one("[[0,0,0], [1,0,0], [1,1,0], [0,1,0]]"), 0, 0, 1));  // a rectangle
    EXPECT_TRUE(is(one("[[0,0,0], [1,0,0], [1.5,1,0], [0.5,1,0]]"), 0, 1, 0));  // parallelogram
    EXPECT_TRUE(is(one("[[0,0,0], [1,0,0.5], [1,1,0.5], [0,1,0]]"), 0, 1, 0));  // tilted
    // A parallelogram in decimal, rounded to float, tilted about all three axes.
    EXPECT_TRUE(is(one("[[0.1,0.2,0.3], [1.3,0.7,-0.1], [1.9,1.6,0.4], [0.7,1.1,0.8]]"), 0, 1, 0));
    EXPECT_TRUE(is(one("[[0,0,0], [1,0,0], [1,1,0.01], [0,1,0]]"), 2, 0, 0));  // not planar
    EXPECT_TRUE(is(one("[[0,0,0], [1,0,0], [0.2,0.2,0], [0,1,0]]"), 2, 0, 0));  // not convex
    EXPECT_TRUE(is(one("[[0,0,0], [1,1,0], [1,0,0], [0,1,0]]"), 2, 0, 0));      // a bow tie
    EXPECT_TRUE(is(one("[[0,0,0], [1,0,0], [2,0,0], [3,0,0]]"), 0, 0, 0));  // a line: left out
    // Two halves of a split quad keep the file's order: (v0 v1 v2), (v0 v2 v3).
    const Scene s = parse_scene(scene_of({"[[0,0,0], [1,0,0], [1,1,0.01], [0,1,0]]"}), kName);
    EXPECT_EQ(s.of<Triangle>()[1].v0.x, 0.0f);
    EXPECT_EQ(s.of<Triangle>()[1].v1.z, 0.01f);
    EXPECT_EQ(s.of<Triangle>()[1].v2.y, 1.0f);
}

// A rectangle that shares an edge with a triangle or a convex quad becomes a convex quad, and
// so does a rectangle that shares an edge with that one: no edge is tested two ways.
TEST(SceneLoader, RectanglesThatShareAnEdgeWithAnotherKindBecomeQuads) {
    const std::string floor = "[[0,0,0], [1,0,0], [1,0,-1], [0,0,-1]]";
    const std::string back = "[[0,0,-1], [1,0,-1], [1,1,-1], [0,1,-1]]";
    const std::string left = "[[0,0,0], [0,0,-1], [0,1,-1], [0,1,0]]";
    const std::string far_wall = "[[5,0,0], [5,1,0], [5,1,-1], [5,0,-1]]";
    PrimitiveCounts k = kinds_of(scene_of({floor, back, left, far_wall}));
    EXPECT_EQ(k.rects, 4u);
    // A triangle on the floor's front edge (z = 0): the floor, and the back and left walls
    // that share its edges, become quads; the far wall, apart from them, stays a rectangle.
    k = kinds_of(scene_of({floor, back, left, far_wall}, {"[[0,0,0], [0,-1,0.5], [1,0,0]]"}));
    EXPECT_EQ(k.triangles, 1u);
    EXPECT_EQ(k.quads, 3u);
    EXPECT_EQ(k.rects, 1u);
    // A tilted quad on the back wall's top edge does the same.
    k = kinds_of(scene_of({floor, back, left, far_wall, "[[0,1,-1], [1,1,-1], [1,2,0], [0,2,0]]"}));
    EXPECT_EQ(k.quads, 4u);
    EXPECT_EQ(k.rects, 1u);
    // Sharing only a corner, or part of an edge, changes nothing.
    k = kinds_of(scene_of({floor, back, left, far_wall}, {"[[1,0,0], [2,0,0], [2,1,1]]"}));
    EXPECT_EQ(k.rects, 4u);
}

// The kind is chosen on the points the renderer uses: the same file moved anywhere gives the
// same kinds, and centring (which the driver applies) keeps them.
TEST(SceneLoader, KindsDoNotDependOnWhereTheSceneIs) {
    const std::vector<std::string> quads = {
        "[[0,0,0], [1,0,0], [1,1,0], [0,1,0]]", "[[2,0,0], [3,0,0], [3.5,1,0], [2.5,1,0]]",
        "[[4,0,0], [5,0,0], [5,1,0.01], [4,1,0]]"};  // apart: no shared edges
    const PrimitiveCounts here = kinds_of(scene_of(quads));
    EXPECT_EQ(here.rects, 1u);
    EXPECT_EQ(here.quads, 1u);
    EXPECT_EQ(here.triangles, 2u);
    for (double shift : {0.1, 12345.678, -98765.4321}) {
        std::vector<std::string> moved;
        for (const std::string& q : quads) {
            std::string out = "[";
            double v[4][3];
            std::sscanf(q.c_str(), "[[%lf,%lf,%lf], [%lf,%lf,%lf], [%lf,%lf,%lf], [%lf,%lf,%lf]]",
                        &v[0][0], &v[0][1], &v[0][2], &v[1][0], &v[1][1], &v[1][2], &v[2][0],
                        &v[2][1], &v[2][2], &v[3][0], &v[3][1], &v[3][2]);
            for (int k = 0; k < 4; ++k) {
                char point[128];
                std::snprintf(point, sizeof point, "%s[%.17g, %.17g, %.17g]", k ? ", " : "",
                              v[k][0] + shift, v[k][1] - shift, v[k][2] + 0.5 * shift);
                out += point;
            }
            moved.push_back(out + "]");
        }
        char camera[256];  // moved with the quads: the camera's distance counts in the limits
        std::snprintf(camera, sizeof camera,
                      R"("position": [%.17g, %.17g, %.17g], "look_at": [%.17g, %.17g, %.17g])",
                      0.5 + shift, 0.5 - shift, 3 + 0.5 * shift, 0.5 + shift, 0.5 - shift,
                      0.5 * shift);
        const Scene s = parse_scene(scene_of(moved, {}, camera), kName);
        EXPECT_EQ(s.of<AxisRect>().size(), here.rects) << shift;
        EXPECT_EQ(s.of<ConvexQuad>().size(), here.quads) << shift;
        EXPECT_EQ(s.of<Triangle>().size(), here.triangles) << shift;
        const Scene centred = centre_scene(s);
        ASSERT_EQ(centred.of<AxisRect>().size(), 1u);
        Vec3 corners[4];
        rect_corners(centred.of<AxisRect>()[0], corners);
        const Vec3(&c)[4] = corners;
        EXPECT_EQ(axis_rect_axis(c), rect_axis(centred.of<AxisRect>()[0])) << shift;
        EXPECT_EQ(centred.of<AxisRect>()[0].hi_u - centred.of<AxisRect>()[0].lo_u, 1.0f) << shift;
    }
}

TEST(SceneLoader, QuadAsTwoTrianglesKeepsItsHalves) {
    const Scene s = parse_scene(R"({
  "camera": { "position": [1, 2, 3], "look_at": [0, 0, 0] },
  "materials": { "white": { "type": "diffuse", "albedo": [0.73, 0.73, 0.73] },
                 "glass": { "type": "glass", "ior": 1.5 } },
  "triangles": [ { "vertices": [[0,0,0], [1,0,0], [1,0,-1]], "material": "white" } ],
  "quads":     [ { "vertices": [[0,0,0], [0,1,0], [0,1,-1], [0,0.8,-0.3]], "material": "glass" } ]
})",
                                kName);
    // One triangle plus a quad that is not convex, as two: (v0 v1 v2) and (v0 v2 v3).
    ASSERT_EQ(s.of<Triangle>().size(), 3u);
    EXPECT_EQ(s.material_names[s.of<Triangle>()[0].material], "white");
    const Triangle& q0 = s.of<Triangle>()[1];
    const Triangle& q1 = s.of<Triangle>()[2];
    EXPECT_EQ(s.material_names[q0.material], "glass");
    EXPECT_EQ(q1.material, q0.material);
    EXPECT_FLOAT_EQ(q0.v1.y, 1.0f);
    EXPECT_FLOAT_EQ(q0.v2.z, -1.0f);
    EXPECT_FLOAT_EQ(q1.v1.z, -1.0f);  // v2 of the quad
    EXPECT_FLOAT_EQ(q1.v1.y, 1.0f);
    EXPECT_FLOAT_EQ(q1.v2.y, 0.8f);   // v3 of the quad
    EXPECT_FLOAT_EQ(q1.v2.z, -0.3f);
    EXPECT_FLOAT_EQ(std::fabs(q0.normal.x), 1.0f);
}

TEST(SceneLoader, ViewMirrorsTheArrays) {
    const Scene s = load_scene(source_tree_path("common/scenes/cornell.json"));
    const SceneView v = s.view();
    EXPECT_EQ(v.of<Sphere>().items, s.of<Sphere>().data());
    EXPECT_EQ(v.of<Sphere>().count, 1);
    EXPECT_EQ(v.of<Triangle>().items, s.of<Triangle>().data());
    EXPECT_EQ(v.of<Triangle>().count, 0);
    EXPECT_EQ(v.of<ConvexQuad>().items, s.of<ConvexQuad>().data());
    EXPECT_EQ(v.of<ConvexQuad>().count, 0);
    EXPECT_EQ(v.of<AxisRect>().items, s.of<AxisRect>().data());
    EXPECT_EQ(v.of<AxisRect>().count, 5);
    EXPECT_EQ(v.num_materials, 4);
    EXPECT_EQ(v.materials, s.materials.data());
    EXPECT_TRUE(v.has_light);
    EXPECT_EQ(v.light.intensity.z, s.light.intensity.z);
    EXPECT_EQ(v.light.position.x, s.light.position.x);
    EXPECT_EQ(v.background.x, s.background.x);
}

// ---- JSON syntax ---------------------------------------------------------------------------

TEST(SceneLoaderErrors, TrailingComma) {
    expect_error("{\n  \"camera\": { \"position\": [0, 0, 5], \"look_at\": [0, 0, 0] },\n@}\n",
                 {"invalid JSON", "expected"});
}

TEST(SceneLoaderErrors, MissingCommaBetweenMembers) {
    expect_error(
        "{\n"
        "  \"camera\": { \"position\": [0, 0, 5], \"look_at\": [0, 0, 0] }\n"
        "  @\"materials\": {}\n"
        "}\n",
        {"invalid JSON", "expected"});
}

TEST(SceneLoaderErrors, MissingCommaInArray) {
    expect_error("{\n  \"camera\": { \"position\": [0, 0 @5], \"look_at\": [0, 0, 0] }\n}\n",
                 {"invalid JSON", "expected"});
}

// A token of several characters that is well formed but out of place is reported at its
// first character, like every other error.
TEST(SceneLoaderErrors, UnexpectedLongTokenAtItsStart) {
    expect_error("{\n  \"camera\": { \"position\": [0, 0 @-12.5], \"look_at\": [0, 0, 0] }\n}\n",
                 {"invalid JSON", "expected"});
    expect_error("{\n  \"background\": [0, 0, 0] @true\n}\n", {"invalid JSON", "expected"});
    expect_error("{\n  \"background\" @\"black\"\n}\n", {"invalid JSON", "expected ':'"});
}

// Lexical errors are reported at the first character that cannot continue the token.
TEST(SceneLoaderErrors, BadLiteral) {
    expect_error("{\n  \"background\": n@ope\n}\n", {"invalid JSON"});
    expect_error("{\n  \"background\": [0, 0, @.5]\n}\n", {"invalid JSON"});
}

TEST(SceneLoaderErrors, UnterminatedString) {
    expect_error(
        "{\n  \"camera\": { \"position\": [0, 0, 5], \"look_at\": [0, 0, 0] },\n"
        "  \"materials: {}@\n}\n",
        {"invalid JSON"});
}

TEST(SceneLoaderErrors, EmptyText) {
    expect_error("@", {"invalid JSON"});
    expect_error("\n\n  @", {"invalid JSON"});
}

TEST(SceneLoaderErrors, TrailingGarbageAfterTheObject) {
    expect_error(scene_with(kGoodSphere) + "@x\n", {"invalid JSON"});
}

// ---- structure -----------------------------------------------------------------------------

TEST(SceneLoaderErrors, UnknownTopLevelKey) {
    expect_error(scene_with(kGoodSphere, "  @\"lights\": [],\n"),
                 {"unknown key", "\"lights\"", "\"light\"", "expected"});
}

TEST(SceneLoaderErrors, RootNotAnObject) {
    expect_error("\n  @[1, 2, 3]\n", {"expected an object"});
}

TEST(SceneLoaderErrors, UnknownKeyInsideMaterial) {
    expect_error(
        "{\n"
        "  \"camera\": { \"position\": [0, 0, 5], \"look_at\": [0, 0, 0] },\n"
        "  \"materials\": {\n"
        "    \"white\": { \"type\": \"diffuse\",\n"
        "               @\"colour\": [0.5, 0.5, 0.5] }\n"
        "  }\n"
        "}\n",
        {"unknown key", "\"colour\"", "\"albedo\""});
}

TEST(SceneLoaderErrors, KeyOfAnotherMaterialType) {
    // "ior" belongs to glass, not to a diffuse material.
    expect_error(
        "{\n"
        "  \"camera\": { \"position\": [0, 0, 5], \"look_at\": [0, 0, 0] },\n"
        "  \"materials\": {\n"
        "    \"white\": { \"type\": \"diffuse\", \"albedo\": [0.5, 0.5, 0.5], @\"ior\": 1.5 }\n"
        "  }\n"
        "}\n",
        {"unknown key", "\"ior\""});
}

TEST(SceneLoaderErrors, UnknownMaterialType) {
    expect_error(
        "{\n"
        "  \"camera\": { \"position\": [0, 0, 5], \"look_at\": [0, 0, 0] },\n"
        "  \"materials\": {\n"
        "    \"white\": { \"type\": @\"lambert\", \"albedo\": [0.5, 0.5, 0.5] }\n"
        "  }\n"
        "}\n",
        {"unknown material type", "lambert", "\"diffuse\"", "\"glass\""});
}

TEST(SceneLoaderErrors, MaterialTypeNotAString) {
    expect_error(
        "{\n"
        "  \"camera\": { \"position\": [0, 0, 5], \"look_at\": [0, 0, 0] },\n"
        "  \"materials\": {\n"
        "    \"white\": { \"type\": @3, \"albedo\": [0.5, 0.5, 0.5] }\n"
        "  }\n"
        "}\n",
        {"material type", "expected"});
}

TEST(SceneLoaderErrors, UndefinedMaterialName) {
    expect_error(scene_with("\"center\": [0, 0, 0], \"radius\": 1, \"material\": @\"chrome\""),
                 {"unknown material", "chrome", "materials"});
}

TEST(SceneLoaderErrors, MaterialNameNotAString) {
    expect_error(scene_with("\"center\": [0, 0, 0], \"radius\": 1, \"material\": @0"),
                 {"expected a material name", "number"});
}

TEST(SceneLoaderErrors, DuplicateKey) {
    expect_error(
        "{\n"
        "  \"camera\": { \"position\": [0, 0, 5], \"look_at\": [0, 0, 0] },\n"
        "  \"materials\": {\n"
        "    \"white\": { \"type\": \"diffuse\", \"albedo\": [0.5, 0.5, 0.5] }\n"
        "  },\n"
        "  @\"camera\": { \"position\": [0, 0, 9], \"look_at\": [0, 0, 0] }\n"
        "}\n",
        {"duplicate key", "\"camera\""});
    expect_error(scene_with("\"center\": [0, 0, 0], \"radius\": 1,\n      @\"radius\": 2, "
                            "\"material\": \"white\""),
                 {"duplicate key", "\"radius\""});
}

TEST(SceneLoaderErrors, MissingCamera) {
    expect_error(
        "\n"
        "@{\n"
        "  \"materials\": {\n"
        "    \"white\": { \"type\": \"diffuse\", \"albedo\": [0.5, 0.5, 0.5] }\n"
        "  }\n"
        "}\n",
        {"missing required key", "\"camera\""});
}

TEST(SceneLoaderErrors, MissingRequiredInsideAnObject) {
    // Reported at the object that lacks the key.
    expect_error(
        "{\n"
        "  \"camera\": { \"position\": [0, 0, 5], \"look_at\": [0, 0, 0] },\n"
        "  \"materials\": { \"w\": { \"type\": \"diffuse\", \"albedo\": [0.5, 0.5, 0.5] } },\n"
        "  \"spheres\": [\n"
        "    { \"center\": [0, 0, 0], \"radius\": 1, \"material\": \"w\" },\n"
        "    @{ \"center\": [0, 0, 0], \"material\": \"w\" }\n"
        "  ]\n"
        "}\n",
        {"missing required key", "\"radius\"", "/spheres/1"});
    expect_error(
        "{\n"
        "  \"camera\": { \"position\": [0, 0, 5], \"look_at\": [0, 0, 0] },\n"
        "  \"materials\": { \"w\": @{ \"albedo\": [0.5, 0.5, 0.5] } }\n"
        "}\n",
        {"missing required key", "\"type\""});
    expect_error(
        "{ \"camera\": @{ \"look_at\": [0, 0, 0] },\n"
        "  \"materials\": { \"w\": { \"type\": \"diffuse\", \"albedo\": [0.5, 0.5, 0.5] } }\n"
        "}\n",
        {"missing required key", "\"position\""});
    expect_error(
        "{ \"camera\": { \"position\": [0, 0, 5], \"look_at\": [0, 0, 0] },\n"
        "  \"materials\": @{ }\n"
        "}\n",
        {"expected an object of named materials"});
}

// ---- types ---------------------------------------------------------------------------------

TEST(SceneLoaderErrors, StringWhereNumberExpected) {
    expect_error(scene_with("\"center\": [0, 0, 0], \"radius\": @\"big\", \"material\": \"white\""),
                 {"expected a number", "string", "radius"});
}

TEST(SceneLoaderErrors, StringInsideAVector) {
    expect_error(scene_with("\"center\": [0, @\"0\", 0], \"radius\": 1, \"material\": \"white\""),
                 {"expected a number", "center"});
}

TEST(SceneLoaderErrors, ArrayOfTwoWhereThreeExpected) {
    expect_error(scene_with("\"center\": @[0, 0], \"radius\": 1, \"material\": \"white\""),
                 {"expected an array of 3 numbers", "an array of 2", "center"});
}

TEST(SceneLoaderErrors, ArrayOfFourWhereThreeExpected) {
    expect_error(
        "{\n"
        "  \"camera\": { \"position\": @[0, 0, 5, 1], \"look_at\": [0, 0, 0] },\n"
        "  \"materials\": { \"w\": { \"type\": \"diffuse\", \"albedo\": [0.5, 0.5, 0.5] } }\n"
        "}\n",
        {"expected an array of 3 numbers", "an array of 4"});
}

// A coordinate is judged once the scene is centred (test_scene_limits.cpp); any other number
// beyond float's range, which double holds, is a PrecisionError in the float build (a
// reference renders it in double) and loads in the double build.
TEST(SceneLoaderErrors, NumberBeyondFloatsRangeIsForDouble) {
    const Marked m = unmark(scene_with(kGoodSphere,
                                       "  \"light\": { \"position\": [0, 1, 0], "
                                       "\"intensity\": [1, @1e39, 1] },\n"));
    if (std::string(kPrecisionName) == "double") {
        EXPECT_EQ(parse_scene(m.text, kName).light.intensity.y, real(1e39));
        return;
    }
    try {
        parse_scene(m.text, kName);
        ADD_FAILURE() << "an intensity of 1e39 loaded in float";
    } catch (const PrecisionError& e) {
        const std::string message = e.what();
        EXPECT_NE(message.find(m.position), std::string::npos) << message;
        EXPECT_NE(message.find("1e+39 is beyond float's range"), std::string::npos) << message;
        EXPECT_NE(message.find("double places it"), std::string::npos) << message;
    }
}

// A value out of its field's range as written is refused in every build with the same
// message, even where float rounds it into the range (1 + 1e-9 rounds to 1, 5 + 1e-7 to 5).
TEST(SceneLoaderErrors, RangesAreJudgedOnTheWrittenNumber) {
    const auto material = [](const std::string& fields) {
        return "{\n"
               "  \"camera\": { \"position\": [0, 0, 5], \"look_at\": [0, 0, 0] },\n"
               "  \"materials\": { \"m\": { " +
               fields +
               " } },\n"
               "  \"spheres\": [ { \"center\": [0, 0, 0], \"radius\": 1, \"material\": \"m\" } ]\n"
               "}\n";
    };
    expect_error(material("\"type\": \"diffuse\", \"albedo\": @[0.5, 1.000000001, 0.5]"),
                 {"/materials/m/albedo", "in [0, 1]"});
    expect_error(material("\"type\": \"diffuse\", \"albedo\": @[0.5, -1e-50, 0.5]"),
                 {"/materials/m/albedo", ">= 0"});
    expect_error(material("\"type\": \"glass\", \"ior\": @5.0000001"),
                 {"/materials/m/ior", "an index of refraction in [1, 5]"});
    expect_error(material("\"type\": \"glass\", \"ior\": @0.99999999999"),
                 {"/materials/m/ior", "in [1, 5]"});
    expect_error(material("\"type\": \"diffuse\", \"albedo\": @[0.5, 1e39, 0.5]"),
                 {"in [0, 1]"});  // out of its own range first: not a precision matter
    expect_error(scene_with(kGoodSphere, "  \"background\": @[0, -1e-40, 0],\n"),
                 {"/background", ">= 0"});
    // Within the range as written: loads in both builds, at the value as written.
    EXPECT_EQ(parse_scene(material("\"type\": \"glass\", \"ior\": 5"), kName).materials[0].ior,
              real(5));
}

// A field of view of 179.99999999 degrees lies in (0, 180) as written: double renders it;
// float rounds it to 180, so the float build sends it to double with a message that says so.
TEST(SceneLoaderErrors, FieldOfViewThatFloatRoundsOutOfItsRange) {
    const Marked m = unmark(
        "{\n"
        "  \"camera\": { \"position\": [0, 0, 5], \"look_at\": [0, 0, 0], \"vfov\": @179.99999999 },\n"
        "  \"materials\": { \"w\": { \"type\": \"diffuse\", \"albedo\": [0.5, 0.5, 0.5] } },\n"
        "  \"spheres\": [ { \"center\": [0, 0, 0], \"radius\": 1, \"material\": \"w\" } ]\n"
        "}\n");
    if (std::string(kPrecisionName) == "double") {
        EXPECT_LT(parse_scene(m.text, kName).camera.vfov_degrees, 180.0);
        return;
    }
    try {
        parse_scene(m.text, kName);
        ADD_FAILURE() << "a field of view float rounds to 180 loaded in float";
    } catch (const PrecisionError& e) {
        const std::string message = e.what();
        EXPECT_NE(message.find(m.position), std::string::npos) << message;
        EXPECT_NE(message.find("179.99999999 rounds to 180 in float"), std::string::npos)
            << message;
    }
    // 180 itself and beyond are out of the range as written, in every build.
    expect_error(
        "{\n"
        "  \"camera\": { \"position\": [0, 0, 5], \"look_at\": [0, 0, 0], \"vfov\": @180.0000001 },\n"
        "  \"materials\": { \"w\": { \"type\": \"diffuse\", \"albedo\": [0.5, 0.5, 0.5] } }\n"
        "}\n",
        {"expected a field of view in degrees, in (0, 180)"});
}

// Nesting deeper than any scene file needs is refused before parsing, at the bracket that
// goes past the limit, at once (the parser took time and memory as the depth squared).
TEST(SceneLoaderErrors, DeepNestingIsRefusedAtOnce) {
    std::string text = "{\"camera\": " + std::string(kMaxJsonDepth - 1, '[');
    const size_t column = text.size() + 1;  // the bracket one past the limit
    text += std::string(100000, '[') + std::string(100000 + kMaxJsonDepth - 1, ']') + "}";
    const auto start = std::chrono::steady_clock::now();
    const std::string message = error_of(text);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    EXPECT_LT(seconds, 0.5);
    EXPECT_NE(message.find("line 1, column " + std::to_string(column) + ": nesting deeper than 32"),
              std::string::npos)
        << message;
    // Brackets inside strings are text, not nesting: this is refused for its key, not its depth.
    const std::string in_string = "{\"camera\": {\"name\": \"" + std::string(100, '[') + "\\\"" +
                                  std::string(100, '{') + "\"}}";
    EXPECT_NE(error_of(in_string).find("unknown key \"name\""), std::string::npos);
}

TEST(SceneLoaderErrors, QuadWithThreeVertices) {
    expect_error(scene_with(kGoodSphere,
                            "  \"quads\": [ { \"vertices\": @[[0,0,0], [1,0,0], [1,1,0]],\n"
                            "                 \"material\": \"white\" } ],\n"),
                 {"expected an array of 4 points", "an array of 3"});
}

TEST(SceneLoaderErrors, SpheresNotAnArray) {
    expect_error(
        "{\n"
        "  \"camera\": { \"position\": [0, 0, 5], \"look_at\": [0, 0, 0] },\n"
        "  \"materials\": { \"w\": { \"type\": \"diffuse\", \"albedo\": [0.5, 0.5, 0.5] } },\n"
        "  \"spheres\": @{ \"center\": [0, 0, 0], \"radius\": 1, \"material\": \"w\" }\n"
        "}\n",
        {"expected an array", "an object"});
}

// ---- values --------------------------------------------------------------------------------

TEST(SceneLoaderErrors, NegativeRadius) {
    expect_error(scene_with("\"center\": [0, 0, 0], \"radius\": @-1, \"material\": \"white\""),
                 {"expected a radius > 0", "radius"});
    expect_error(scene_with("\"center\": [0, 0, 0], \"radius\": @-1e-3, \"material\": \"white\""),
                 {"expected a radius > 0"});
}

TEST(SceneLoaderErrors, ZeroRadius) {
    expect_error(scene_with("\"center\": [0, 0, 0], \"radius\": @0, \"material\": \"white\""),
                 {"expected a radius > 0"});
    expect_error(
        scene_with("\"center\": [0, 0, 0], \"radius\":\n        @0.0, \"material\": \"white\""),
        {"expected a radius > 0"});
}

TEST(SceneLoaderErrors, AlbedoAboveOne) {
    // The offending value is the array (or, better still, its component 1.2); accept either.
    const std::string marked =
        "{\n"
        "  \"camera\": { \"position\": [0, 0, 5], \"look_at\": [0, 0, 0] },\n"
        "  \"materials\": {\n"
        "    \"white\": { \"type\": \"diffuse\", \"albedo\": @[0.5, #1.2, 0.5] }\n"
        "  }\n"
        "}\n";
    std::string array_marked = marked, component_marked = marked;
    array_marked.erase(array_marked.find('#'), 1);
    component_marked.erase(component_marked.find('@'), 1);
    const Marked a = unmark(array_marked);
    const Marked c = unmark(component_marked, '#');
    const std::string message = error_of(a.text);
    EXPECT_NE(message.find(kName), std::string::npos) << message;
    EXPECT_TRUE(message.find(a.position) != std::string::npos ||
                message.find(c.position) != std::string::npos)
        << "expected " << a.position << " or " << c.position << " in: " << message;
    EXPECT_NE(message.find("albedo"), std::string::npos) << message;
    EXPECT_NE(message.find("[0, 1]"), std::string::npos) << message;
}

TEST(SceneLoaderErrors, NegativeAlbedoAndIntensity) {
    expect_error(
        "{\n"
        "  \"camera\": { \"position\": [0, 0, 5], \"look_at\": [0, 0, 0] },\n"
        "  \"materials\": {\n"
        "    \"white\": { \"type\": \"mirror\", \"albedo\": @[0.5, -0.1, 0.5] }\n"
        "  }\n"
        "}\n",
        {"expected components >= 0"});
    expect_error(
        scene_with(kGoodSphere,
                   "  \"light\": { \"position\": [0, 9, 0], \"intensity\": @[1, 1, -1] },\n"),
        {"expected components >= 0"});
}

TEST(SceneLoaderErrors, IorOutOfRange) {
    expect_error(
        "{\n"
        "  \"camera\": { \"position\": [0, 0, 5], \"look_at\": [0, 0, 0] },\n"
        "  \"materials\": { \"g\": { \"type\": \"glass\", \"ior\": @0.5 } }\n"
        "}\n",
        {"index of refraction"});
}

TEST(SceneLoaderErrors, VfovOutOfRange) {
    for (const char* bad : {"0", "180", "-30", "360", "1e9"}) {
        expect_error(
            std::string("{\n"
                        "  \"camera\": { \"position\": [0, 0, 5], \"look_at\": [0, 0, 0],\n"
                        "              \"vfov\": @") +
                bad +
                " },\n"
                "  \"materials\": { \"w\": { \"type\": \"diffuse\", \"albedo\": [0.5, 0.5, 0.5] } }\n"
                "}\n",
            {"field of view", "(0, 180)"});
    }
    expect_error(
        "{\n"
        "  \"camera\": { \"position\": [0, 0, 5], \"look_at\": [0, 0, 0], \"vfov\": @\"wide\" },\n"
        "  \"materials\": { \"w\": { \"type\": \"diffuse\", \"albedo\": [0.5, 0.5, 0.5] } }\n"
        "}\n",
        {"expected a number", "string"});
}

TEST(SceneLoaderErrors, CameraLookingAtItself) {
    expect_error(
        "{\n"
        "  \"camera\": { \"position\": [1, 2, 3], \"look_at\": @[1, 2, 3] },\n"
        "  \"materials\": { \"w\": { \"type\": \"diffuse\", \"albedo\": [0.5, 0.5, 0.5] } }\n"
        "}\n",
        {"look_at", "different from the camera position"});
    expect_error(
        "{\n"
        "  \"camera\": { \"position\": [0, 5, 0], \"look_at\": [0, 0, 0], \"up\": @[0, 2, 0] },\n"
        "  \"materials\": { \"w\": { \"type\": \"diffuse\", \"albedo\": [0.5, 0.5, 0.5] } }\n"
        "}\n",
        {"up", "not parallel"});
}

TEST(SceneLoaderErrors, RenderWidthZeroOrAbsurd) {
    for (const char* bad : {"0", "-5", "16385", "100000", "1e9"}) {
        expect_error(scene_with(kGoodSphere, std::string("  \"render\": { \"height\": 100,\n"
                                                         "              \"width\": @") +
                                                 bad + " },\n"),
                     {"width", "expected an integer"});
    }
    expect_error(scene_with(kGoodSphere, "  \"render\": { \"width\": @600.5 },\n"),
                 {"width", "expected an integer", "a number"});
    expect_error(scene_with(kGoodSphere, "  \"render\": { \"width\": @\"600\" },\n"),
                 {"width", "expected an integer", "a string"});
    expect_error(scene_with(kGoodSphere, "  \"render\": { \"spp\": @0 },\n"), {"spp", "1.."});
    expect_error(scene_with(kGoodSphere, "  \"render\": { \"bounces\": @0 },\n"), {"bounces"});
    expect_error(scene_with(kGoodSphere, "  \"render\": { \"height\": @16385 },\n"),
                 {"height", "16384"});
    expect_error(scene_with(kGoodSphere, "  \"render\": { \"spp\": 3, @\"samples\": 3 },\n"),
                 {"unknown key", "\"samples\"", "\"spp\""});
}

// Integers beyond 64-bit signed range are rejected with the value as written, not as it
// wraps around in a long long.
TEST(SceneLoaderErrors, HugeIntegerReportedAsWritten) {
    expect_error(scene_with(kGoodSphere, "  \"render\": { \"width\": @18446744073709551615 },\n"),
                 {"width", "expected an integer", "found 18446744073709551615"});
    expect_error(scene_with(kGoodSphere, "  \"render\": { \"spp\": @9223372036854775808 },\n"),
                 {"spp", "found 9223372036854775808"});
}

TEST(SceneLoaderErrors, RenderLimitsAreInclusive) {
    const Scene s = parse_scene(
        scene_with(kGoodSphere,
                   "  \"render\": { \"width\": 16384, \"height\": 1, \"bounces\": 64 },\n"),
        kName);
    EXPECT_EQ(s.render.width, 16384);
    EXPECT_EQ(s.render.height, 1);
    EXPECT_EQ(s.render.bounces, 64);
}

// Keys with the characters a JSON pointer escapes ('/' and '~') must still be located.
TEST(SceneLoaderErrors, UnknownKeyWithSlashIsLocated) {
    expect_error(scene_with(kGoodSphere, "  @\"light/position\": [0, 1, 0],\n"),
                 {"unknown key", "\"light/position\""});
}

TEST(SceneLoaderErrors, DuplicateKeyWithSlashIsNamed) {
    expect_error(scene_with(kGoodSphere, "  \"a/b\": 1,\n  @\"a/b\": 2,\n"),
                 {"duplicate key \"a/b\""});
}

TEST(SceneLoaderErrors, MaterialNameWithSlashIsLocated) {
    expect_error(
        "{\n"
        "  \"camera\": { \"position\": [0, 0, 5], \"look_at\": [0, 0, 0] },\n"
        "  \"materials\": {\n"
        "    \"red/matte\": { \"type\": @\"paint\" }\n"
        "  }\n"
        "}\n",
        {"unknown material type"});
}

// Seeds have one range, in scene files and on the command line alike (0 .. 2^53 - 1).
TEST(SceneLoader, SeedRangeIsTheCommandLines) {
    const std::string top = std::to_string(kMaxSeed);
    const Scene s =
        parse_scene(scene_with(kGoodSphere, "  \"render\": { \"seed\": " + top + " },\n"), kName);
    EXPECT_EQ(s.render.seed, static_cast<uint64_t>(kMaxSeed));
    const std::string message = error_of(scene_with(
        kGoodSphere, "  \"render\": { \"seed\": " + std::to_string(kMaxSeed + 1) + " },\n"));
    EXPECT_NE(message.find("expected an integer in 0.." + top), std::string::npos) << message;
}
