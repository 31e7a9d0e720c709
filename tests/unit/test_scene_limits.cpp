// The scene loader accepts exactly what the renderer's float arithmetic can show once the
// scene is centred (common/host/scene_limits.h): coordinates up to 1e9 of the scene's centre,
// sizes from 1e-9 and from 2^-18 of their distance from it, triangles that keep their area in
// float. Everything else is one InputError line that names the place and says what to do;
// where the scene sits does not matter.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "errors.h"
#include "scene_limits.h"
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
    // The camera counts in the scene's reach (scene_limits.h): a tiny scene is seen from near.
    EXPECT_EQ(refusal(scene(sphere("[0, 0, 0]", "1e-9"), "[0, 0, 5e-9]")), "");
    EXPECT_EQ(refusal(scene(sphere("[0, -1e9, 0]", "1e9"))), "");  // a floor of radius 1e9
    EXPECT_EQ(refusal(scene(sphere("[2e4, -1.4e4, 6e3]", "2"), "[2e4, -1.4e4, 6005]",
                            "[2e4, -1.4e4, 6e3]")),
              "");  // moved 1e4 radii, with its camera
    EXPECT_EQ(refusal(scene(triangle("[-1e9, 0, -1e9]", "[-1e9, 0, 1e9]", "[1e9, 0, 0]"))), "");
    EXPECT_EQ(refusal(scene(triangle("[0, 0, 0]", "[1e-9, 0, 0]", "[0, 1e-9, 0]"), "[0, 0, 5e-9]")),
              "");
    // On a line as written: nothing to show, left out by the loader, judged by no limit.
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
                         sphere("[0, 0, 0]", "1000")),
                   {"/triangles/0/vertices", "too small for float precision"});
}

// Centred, the third vertex is (4e6, 4000000.1), which rounds to (4e6, 4e6) in float (spacing
// 0.25): it lands on the line of the others, and the triangle, which has an area as written,
// would never be hit.
TEST(SceneLimits, RefusesTrianglesThatCollapseInFloat) {
    expect_refused(scene(triangle("[0, 0, 0]", "[1e7, 1e7, 0]", "[9e6, 9000000.1, 0]")),
                   {"/triangles/0/vertices", "collapses", "rounded to float"});
}

// What depends on the image's settings (render_problem): a view whose pixels span fewer than
// 256 ulps of a unit direction, and a light whose brightest path leaves the type's range.
TEST(SceneLimits, ANarrowViewAndABrightLightNeedTheirType) {
    const auto view = [](double vfov) {
        char camera[160];
        std::snprintf(camera, sizeof camera,
                      "{\n  \"camera\": { \"position\": [0, 0, 5], \"look_at\": [0, 0, 0], "
                      "\"vfov\": %.17g },\n",
                      vfov);
        return parse_scene(std::string(camera) +
                               "  \"materials\": { \"m\": { \"type\": \"diffuse\", \"albedo\": "
                               "[0.5, 0.5, 0.5] } },\n" +
                               sphere("[0, 0, 0]", "1") + "\n}\n",
                           "view.json");
    };
    // 24 pixels spanning 2 tan(vfov / 2): the limit is 256 * 2^-23 rad a pixel in float.
    const double limit = 2 * std::atan(12 * 256 * std::ldexp(1.0, -23)) * 180 / M_PI;
    EXPECT_TRUE(render_problem(view(limit * 1.01), 24, 4, kFloatLimits).empty());
    const PlacementProblem narrow = render_problem(view(limit * 0.99), 24, 4, kFloatLimits);
    EXPECT_EQ(narrow.pointer, "/camera/vfov");
    EXPECT_NE(narrow.message.find("finer than float ray directions resolve"), std::string::npos)
        << narrow.message;
    EXPECT_TRUE(render_problem(view(limit * 0.99), 24, 4, kDoubleLimits).empty());
    EXPECT_FALSE(render_problem(view(1e-12), 24, 4, kDoubleLimits).empty());
    EXPECT_TRUE(render_problem(view(limit * 0.99), 12, 4, kFloatLimits).empty());  // wider pixels

    // A light 0.01 from a sphere: falloff up to 1 / (pi 1e-4); with 4 bounces, an intensity
    // of 2.67e34 reaches float's largest value.
    const auto light = [](double intensity) {
        char text[200];
        std::snprintf(text, sizeof text,
                      "  \"light\": { \"position\": [1.01, 0, 0], \"intensity\": [1, %.17g, 1] "
                      "},\n",
                      intensity);
        return parse_scene(scene(text + sphere("[0, 0, 0]", "1")), "light.json");
    };
    EXPECT_TRUE(render_problem(light(2.6e34), 24, 4, kFloatLimits).empty());
    const PlacementProblem bright = render_problem(light(2.7e34), 24, 4, kFloatLimits);
    EXPECT_EQ(bright.pointer, "/light/intensity");
    EXPECT_NE(bright.message.find("beyond float's range"), std::string::npos) << bright.message;
    EXPECT_TRUE(render_problem(light(2.7e34), 24, 4, kDoubleLimits).empty());
    EXPECT_TRUE(render_problem(light(2.7e34), 24, 3, kFloatLimits).empty());  // fewer bounces
    // In the float build a PrecisionError (a reference switches); in double it renders.
    Scene bright_scene = light(3e38);
    if (std::string(kPrecisionName) == "float")
        EXPECT_THROW(check_render_limits(bright_scene, 24, 4), PrecisionError);
    else EXPECT_NO_THROW(check_render_limits(bright_scene, 24, 4));
}
