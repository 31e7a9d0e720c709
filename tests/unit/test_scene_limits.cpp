// The scene loader accepts exactly what the renderer's float arithmetic can show
// (common/host/scene_limits.h): coordinates up to 1e9, sizes from 1e-9 and from 2^-18 of their
// distance from the origin, triangles that keep their area in float. Everything else is one
// InputError line that names the place and says what to do.
#include <gtest/gtest.h>

#include <string>

#include "errors.h"
#include "scene_loader.h"

namespace {

// A scene with a camera and one material around `primitives` (top-level members).
std::string scene(const std::string& primitives, const std::string& camera_position = "[0, 0, 5]") {
    return "{\n  \"camera\": { \"position\": " + camera_position +
           ", \"look_at\": [0, 0, 0] },\n"
           "  \"materials\": { \"m\": { \"type\": \"diffuse\", \"albedo\": [0.5, 0.5, 0.5] } },\n" +
           primitives + "\n}\n";
}

std::string sphere(const std::string& center, const std::string& radius) {
    return "  \"spheres\": [ { \"center\": " + center + ", \"radius\": " + radius +
           ", \"material\": \"m\" } ]";
}

std::string triangle(const std::string& a, const std::string& b, const std::string& c) {
    return "  \"triangles\": [ { \"vertices\": [" + a + ", " + b + ", " + c +
           "], \"material\": \"m\" } ]";
}

// The one-line message parsing throws, or "" when it accepts the scene.
std::string refusal(const std::string& text) {
    try {
        parse_scene(text, "case.json");
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}

void expect_refused(const std::string& text, const std::vector<std::string>& words) {
    const std::string message = refusal(text);
    ASSERT_FALSE(message.empty()) << "accepted:\n" << text;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    for (const std::string& w : words)
        EXPECT_NE(message.find(w), std::string::npos) << "no '" << w << "' in: " << message;
}

}  // namespace

TEST(SceneLimits, AcceptsTheRangeTheRendererHandles) {
    EXPECT_EQ(refusal(scene(sphere("[0, 0, 0]", "1e-9"))), "");
    EXPECT_EQ(refusal(scene(sphere("[0, -1e9, 0]", "1e9"))), "");  // a floor of radius 1e9
    EXPECT_EQ(refusal(scene(sphere("[2e4, -1.4e4, 6e3]", "2"))), "");  // moved 1e4 radii
    EXPECT_EQ(refusal(scene(triangle("[-1e9, 0, -1e9]", "[-1e9, 0, 1e9]", "[1e9, 0, 0]"))), "");
    EXPECT_EQ(refusal(scene(triangle("[0, 0, 0]", "[1e-9, 0, 0]", "[0, 1e-9, 0]"))), "");
    // Zero area as written: nothing to show, kept (and never hit).
    EXPECT_EQ(refusal(scene(triangle("[0, 0, 0]", "[1, 1, 1]", "[2, 2, 2]"))), "");
    EXPECT_EQ(refusal(scene(triangle("[0, 0, 0]", "[0, 0, 0]", "[0, 0, 0]"))), "");
}

TEST(SceneLimits, RefusesCoordinatesPast1e9) {
    expect_refused(scene(sphere("[0, 2e9, 0]", "1")),
                   {"/spheres/0/center/1", "1e9", "scale the scene down"});
    expect_refused(scene(triangle("[0, 0, 0]", "[1, 0, 0]", "[0, 0, -3e9]")),
                   {"/triangles/0/vertices/2/2", "1e9"});
    expect_refused(scene(sphere("[0, 0, 0]", "1"), "[0, 0, 1e10]"), {"/camera/position/2", "1e9"});
    expect_refused(scene(sphere("[0, 0, 0]", "2e9")), {"/spheres/0/radius", "above 1e9"});
    expect_refused(scene("  \"light\": { \"position\": [5e9, 0, 0], \"intensity\": [1, 1, 1] },\n" +
                         sphere("[0, 0, 0]", "1")),
                   {"/light/position/0", "1e9"});
}

TEST(SceneLimits, RefusesPrimitivesTooSmallForFloat) {
    expect_refused(scene(sphere("[0, 0, 0]", "1e-10")),
                   {"/spheres/0/radius", "below 1e-9", "scale the scene up"});
    expect_refused(scene(triangle("[0, 0, 0]", "[1e-12, 0, 0]", "[0, 1e-12, 0]")),
                   {"/triangles/0/vertices", "below 1e-9"});
    expect_refused(
        scene("  \"quads\": [ { \"vertices\": [[0, 0, 0], [1e-10, 0, 0], [1e-10, 1e-10, 0], "
              "[0, 1e-10, 0]], \"material\": \"m\" } ]"),
        {"/quads/0/vertices", "below 1e-9"});
}

// Float spacing near 1e5 is ~0.008: a sphere of radius 0.2 there is a few ray offsets across.
TEST(SceneLimits, RefusesPrimitivesTooSmallForTheirPosition) {
    expect_refused(scene(sphere("[1e5, 0, 0]", "0.2")),
                   {"/spheres/0/radius", "too small for float precision", "nearer the origin"});
    expect_refused(scene(triangle("[1e6, 0, 0]", "[1e6, 1, 0]", "[1e6, 0, 1]")),
                   {"/triangles/0/vertices", "too small for float precision"});
}

// 5e6 + 0.1 rounds to 5e6 in float (spacing 0.5): the third vertex lands on the line of the
// others and the triangle, which has an area as written, would never be hit.
TEST(SceneLimits, RefusesTrianglesThatCollapseInFloat) {
    expect_refused(scene(triangle("[0, 0, 0]", "[1e7, 1e7, 0]", "[5e6, 5000000.1, 0]")),
                   {"/triangles/0/vertices", "collapses", "rounded to float"});
}
