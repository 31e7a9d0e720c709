// What the driver tells about a scene (scene_report.h): the counts by kind, the sizes, and the
// note on triangles of the file left out because their points lie on a line.
#include <gtest/gtest.h>

#include "scene_loader.h"
#include "scene_report.h"

namespace {

Scene scene_with(double detail_radius, double wall) {
    Scene s;
    Material diffuse{};
    diffuse.type = material_type<Diffuse>;
    Material glass = diffuse;
    glass.type = material_type<Glass>;
    s.materials = {diffuse, glass};
    s.material_names = {"wall", "bead"};
    const float w = static_cast<float>(wall);
    s.of<Triangle>() = {make_triangle({-w, 0, -w}, {-w, 0, w}, {w, 0, w}, 0)};
    Sphere bead{};
    bead.center = {0.0f, 1.0f, 0.0f};
    bead.radius = static_cast<float>(detail_radius);
    bead.material = 1;
    s.of<Sphere>() = {bead};
    s.has_light = true;
    return s;
}

}  // namespace

TEST(SceneReport, CountsWhatTheSceneUses) {
    const SceneUse use = scene_use(scene_with(0.25, 2.0));
    EXPECT_EQ(use.primitives_of<Sphere>(), 1);
    EXPECT_EQ(use.primitives_of<Triangle>(), 1);
    EXPECT_EQ(use.materials_of<Diffuse>(), 1);
    EXPECT_EQ(use.materials_of<Glass>(), 1);
    EXPECT_EQ(use.materials_of<Mirror>(), 0);
    EXPECT_TRUE(use.light);
    EXPECT_FALSE(use.background);
    EXPECT_FLOAT_EQ(static_cast<float>(use.smallest), 0.25f);
    EXPECT_FLOAT_EQ(static_cast<float>(use.extent), 2.0f);
    const std::string line = describe(use);
    EXPECT_NE(line.find("scene: 1 sphere, 1 triangle;"), std::string::npos) << line;
    EXPECT_NE(line.find("1 diffuse, 1 glass"), std::string::npos) << line;
    EXPECT_NE(line.find("1 : 8"), std::string::npos) << line;
    EXPECT_EQ(lines_left_out(use), "");
}

// Quads and rectangles are counted by kind, and their edges are sizes; kinds the scene does
// not have are not named.
TEST(SceneReport, CountsQuadsAndRectanglesByKind) {
    Scene s = scene_with(0.25, 2.0);
    s.of<Triangle>().clear();
    const Vec3 r[4] = {{0, 0, 0}, {0.125f, 0, 0}, {0.125f, 0.1f, 0}, {0, 0.1f, 0}};
    s.of<AxisRect>() = {make_axis_rect(r, 2, 0), make_axis_rect(r, 2, 0)};
    s.of<ConvexQuad>() = {make_convex_quad({0, 0, 0}, {3, 0, 0}, {3.5f, 1, 0}, {0.5f, 1, 0}, 0)};
    const SceneUse use = scene_use(s);
    EXPECT_EQ(use.primitives_of<Triangle>(), 0);
    EXPECT_EQ(use.primitives_of<ConvexQuad>(), 1);
    EXPECT_EQ(use.primitives_of<AxisRect>(), 2);
    EXPECT_FLOAT_EQ(static_cast<float>(use.smallest), 0.125f);  // the rectangle's longer side
    EXPECT_FLOAT_EQ(static_cast<float>(use.extent), 3.5f);      // the quad's corner
    const std::string line = describe(use);
    EXPECT_NE(line.find("scene: 1 sphere, 1 convex quad, 2 rectangles;"), std::string::npos)
        << line;
    const std::string json = to_json(use);
    EXPECT_NE(json.find("\"quads\": 1, \"rects\": 2"), std::string::npos) << json;
    EXPECT_NE(json.find("\"triangles\": 0"), std::string::npos) << json;
    EXPECT_NE(describe(scene_use(Scene())).find("scene: no primitives;"), std::string::npos);
}

// The primitives that splitting at T-junctions added are said after the counts, which include
// them; a scene that needed none says nothing of it.
TEST(SceneReport, SaysHowManyPrimitivesSplittingAdded) {
    Scene s = scene_with(0.25, 2.0);
    EXPECT_EQ(describe(scene_use(s)).find("T-junctions"), std::string::npos);
    s.t_junction_pieces = 3;
    const std::string line = describe(scene_use(s));
    EXPECT_NE(line.find("scene: 1 sphere, 1 triangle (splitting at T-junctions added 3);"),
              std::string::npos)
        << line;
}

// Triangles left out for lying on a line: one note line naming the first, and --json's count.
TEST(SceneReport, SaysWhichTrianglesOnALineWereLeftOut) {
    Scene s = scene_with(0.25, 2.0);
    EXPECT_NE(to_json(scene_use(s)).find("\"lines_left_out\": 0"), std::string::npos);
    s.line_triangles = 2;
    s.first_line_triangle = "/quads/4";
    const std::string note = lines_left_out(scene_use(s));
    EXPECT_EQ(note,
              "note: 2 triangles of the file left out, their points on a line (no area at any "
              "precision; the first: /quads/4)");
    EXPECT_NE(to_json(scene_use(s)).find("\"lines_left_out\": 2"), std::string::npos);
}

TEST(SceneReport, AnEmptySceneHasNoSizes) {
    Scene s;
    const SceneUse use = scene_use(s);
    EXPECT_EQ(use.smallest, 0.0);
    EXPECT_EQ(lines_left_out(use), "");
    EXPECT_EQ(describe(use).find("sizes"), std::string::npos);
}
