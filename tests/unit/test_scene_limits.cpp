// The scene loader accepts exactly what the renderer's float arithmetic can show once the
// scene is centred (common/host/scene_limits.h): coordinates up to 1e9 of the scene's centre,
// sizes from 1e-9 and from 2^-18 of their distance from it, triangles that keep their area in
// float. Everything else is one InputError line that names the place and says what to do;
// where the scene sits does not matter.
#include <gtest/gtest.h>

#include <string>

#include "errors.h"
#include "scene_loader.h"

namespace {

// A scene with a camera and one material around `primitives` (top-level members).
std::string scene(const std::string& primitives, const std::string& camera_position = "[0, 0, 5]",
                  const std::string& look_at = "[0, 0, 0]") {
    return "{\n  \"camera\": { \"position\": " + camera_position + ", \"look_at\": " + look_at +
           " },\n"
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

TEST(SceneLimits, RefusesCoordinatesPast1e9OfTheScenesCentre) {
    expect_refused(scene(sphere("[0, 2e9, 0]", "1")),
                   {"/camera/position/1", "1e9", "scale the scene down"});
    // The same sphere with its camera beside it: the scene is small, wherever it is.
    EXPECT_EQ(refusal(scene(sphere("[0, 2e9, 0]", "1"), "[0, 2e9, 5]", "[0, 2e9, 0]")), "");
    expect_refused(scene(triangle("[0, 0, 0]", "[1, 0, 0]", "[0, 0, -3e9]")),
                   {"/triangles/0/vertices/0/2", "1e9"});
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

// Float spacing near 5e4 is ~0.004: a sphere of radius 0.1 there, 5e4 from the scene's
// centre, is under 4 ray offsets across. Alone, at the same place, it is the whole scene.
TEST(SceneLimits, RefusesPrimitivesTooSmallForTheirPlaceInTheScene) {
    const std::string far_and_near =
        "  \"spheres\": [ { \"center\": [1e5, 0, 0], \"radius\": "
        "0.1, \"material\": \"m\" }, { \"center\": [0, 0, 0], "
        "\"radius\": 1, \"material\": \"m\" } ]";
    expect_refused(scene(far_and_near),
                   {"/spheres/0/radius", "too small for float precision", "scene's centre"});
    EXPECT_EQ(refusal(scene(sphere("[1e5, 0, 0]", "0.1"), "[1e5, 0, 5]", "[1e5, 0, 0]")), "");
    expect_refused(scene(triangle("[1e6, 0, 0]", "[1e6, 1, 0]", "[1e6, 0, 1]") + ",\n" +
                         sphere("[0, 0, 0]", "3")),
                   {"/triangles/0/vertices", "too small for float precision"});
}

// Centred, the third vertex is (4e6, 4000000.1), which rounds to (4e6, 4e6) in float (spacing
// 0.25): it lands on the line of the others, and the triangle, which has an area as written,
// would never be hit.
TEST(SceneLimits, RefusesTrianglesThatCollapseInFloat) {
    expect_refused(scene(triangle("[0, 0, 0]", "[1e7, 1e7, 0]", "[9e6, 9000000.1, 0]")),
                   {"/triangles/0/vertices", "collapses", "rounded to float"});
}
