// Where a scene sits never decides how it renders (scene_limits.h, scene_centring.h): every
// primitive is built from the file's numbers moved to the scene's centre and rounded once,
// and the loader judges what a precision can place on those numbers. Compiled into the float
// unit tests and the double ones (tests/precision/), so both builds hold it.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <string>

#include "errors.h"
#include "scene_centring.h"
#include "scene_loader.h"

namespace {

std::string number(double x) {
    char text[40];
    std::snprintf(text, sizeof text, "%.17g", x);
    return text;
}

std::string point(double x, double y, double z) {
    return "[" + number(x) + ", " + number(y) + ", " + number(z) + "]";
}

// A closed box of side 10 (six quads, one sphere inside) with its corner at (x, 0, 0), the
// camera and light inside it.
std::string box_at(double x) {
    const double s = 10;
    const auto quad = [&](std::array<std::array<double, 3>, 4> v) {
        std::string text = "{\"vertices\": [";
        for (int k = 0; k < 4; ++k) text += (k ? ", " : "") + point(x + v[k][0], v[k][1], v[k][2]);
        return text + "], \"material\": \"w\"}";
    };
    return "{\"camera\": {\"position\": " + point(x + 5, 5, 9) +
           ", \"look_at\": " + point(x + 5, 5, 0) +
           "},\n\"light\": {\"position\": " + point(x + 5, 9, 5) +
           ", \"intensity\": [1, 1, 1]},\n"
           "\"materials\": {\"w\": {\"type\": \"diffuse\", \"albedo\": [0.5, 0.5, 0.5]}},\n"
           "\"spheres\": [{\"center\": " +
           point(x + 3, 2, 4) + ", \"radius\": 2, \"material\": \"w\"}],\n\"quads\": [" +
           quad({{{0, 0, 0}, {s, 0, 0}, {s, 0, s}, {0, 0, s}}}) + ",\n" +
           quad({{{0, s, 0}, {0, s, s}, {s, s, s}, {s, s, 0}}}) + ",\n" +
           quad({{{0, 0, 0}, {0, 0, s}, {0, s, s}, {0, s, 0}}}) + ",\n" +
           quad({{{s, 0, 0}, {s, s, 0}, {s, s, s}, {s, 0, s}}}) + ",\n" +
           quad({{{0, 0, 0}, {0, s, 0}, {s, s, 0}, {s, 0, 0}}}) + ",\n" +
           quad({{{0, 0, s}, {s, 0, s}, {s, s, s}, {0, s, s}}}) + "]}";
}

void expect_same_rects(const Scene& a, const Scene& b) {
    ASSERT_EQ(a.of<AxisRect>().size(), b.of<AxisRect>().size());
    for (size_t i = 0; i < a.of<AxisRect>().size(); ++i) {
        EXPECT_EQ(a.of<AxisRect>()[i].plane, b.of<AxisRect>()[i].plane) << i;
        EXPECT_EQ(a.of<AxisRect>()[i].lo_u, b.of<AxisRect>()[i].lo_u) << i;
        EXPECT_EQ(a.of<AxisRect>()[i].hi_u, b.of<AxisRect>()[i].hi_u) << i;
        EXPECT_EQ(a.of<AxisRect>()[i].lo_v, b.of<AxisRect>()[i].lo_v) << i;
        EXPECT_EQ(a.of<AxisRect>()[i].hi_v, b.of<AxisRect>()[i].hi_v) << i;
    }
}

}  // namespace

// A box of side 10 at x = 1e8 is the box at the origin once centred, to the bit: refused
// before ("too small for float precision that far from the origin"), in both builds.
TEST(ScenePlacement, ASmallSceneFarAwayIsTheSceneAtTheOrigin) {
    const Scene near = centre_scene(parse_scene(box_at(0), "near.json"));
    for (double x : {1e6, 1e8, 1e12}) {
        const Scene far = centre_scene(parse_scene(box_at(x), "far.json"));
        expect_same_rects(near, far);
        ASSERT_EQ(far.of<Sphere>().size(), 1u);
        EXPECT_EQ(far.of<Sphere>()[0].center.x, near.of<Sphere>()[0].center.x) << x;
        EXPECT_EQ(far.light.position.y, near.light.position.y) << x;
        EXPECT_EQ(far.camera.position.z, near.camera.position.z) << x;
    }
}

// A floor of side 8 about x = 1e6 + 2^-5 whose corners wobble by 1e-10: its corners lie at
// ties of float's spacing there (2^-4), and the wobble rounded them apart. Centred, it is the
// floor of side 8 at the origin (a rectangle in float; in double, where the wobble is
// resolved, a convex quad within 1e-9 of it).
TEST(ScenePlacement, ANearRectangleFarAwayIsPlacedFromItsCentredCorners) {
    const double x = 1e6 + 0.03125, w = 1e-10;
    const std::string text =
        "{\"camera\": {\"position\": " + point(x, 3, 0) + ", \"look_at\": " + point(x, 0, 0) +
        ", \"up\": [0, 0, 1]},\n"
        "\"materials\": {\"w\": {\"type\": \"diffuse\", \"albedo\": [0.5, 0.5, 0.5]}},\n"
        "\"quads\": [{\"vertices\": [" +
        point(x - 4 + w, 0, -4) + ", " + point(x - 4 - w, 0, 4) + ", " + point(x + 4 + w, 0, 4) +
        ", " + point(x + 4 - w, 0, -4) + "], \"material\": \"w\"}]}";
    const Scene scene = centre_scene(parse_scene(text, "wobble.json"));
    ASSERT_EQ(scene.of<AxisRect>().size() + scene.of<ConvexQuad>().size(), 1u);
    double worst = 0;
    if (!scene.of<AxisRect>().empty()) {
        const AxisRect& r = scene.of<AxisRect>()[0];
        for (double value : {double(r.lo_u) + 4, double(r.hi_u) - 4, double(r.lo_v) + 4,
                             double(r.hi_v) - 4, double(r.plane)})
            worst = std::max(worst, std::fabs(value));
    } else {
        const ConvexQuad& q = scene.of<ConvexQuad>()[0];
        for (const Vec3& v : {q.v0, q.v1, q.v2, q.v3})
            worst = std::max({worst, std::fabs(std::fabs(double(v.x)) - 4), std::fabs(double(v.y)),
                              std::fabs(std::fabs(double(v.z)) - 4)});
    }
    EXPECT_LT(worst, 1e-9) << "placed off its centred corners by " << worst;
}

// What neither precision places is a plain InputError; what only float cannot place is a
// PrecisionError (a reference hands it to its double build), in the float build only.
TEST(ScenePlacement, OnlyWhatDoublePlacesIsAPrecisionError) {
    const auto mixed = [](double radius) {
        return "{\"camera\": {\"position\": [0, 1, 3], \"look_at\": [0, 0, 0]},\n"
               "\"materials\": {\"w\": {\"type\": \"diffuse\", \"albedo\": [0.5, 0.5, 0.5]}},\n"
               "\"spheres\": [{\"center\": [0, 0, 0], \"radius\": " +
               number(radius) +
               ", \"material\": \"w\"}],\n"
               "\"quads\": [{\"vertices\": [[-1e4, 0, -1e4], [-1e4, 0, 1e4], [1e4, 0, 1e4], "
               "[1e4, 0, -1e4]], \"material\": \"w\"}]}";
    };
    bool precision_error = false;
    try {
        parse_scene(mixed(1e-4), "mixed.json");
    } catch (const PrecisionError&) {
        precision_error = true;
    }
    EXPECT_EQ(precision_error, std::string(kPrecisionName) == "float");
    // 1e-40 is below what either type holds: refused, and not for precision.
    try {
        parse_scene(mixed(1e-40), "tiny.json");
        ADD_FAILURE() << "a radius of 1e-40 was accepted";
    } catch (const PrecisionError& e) {
        ADD_FAILURE() << "refused as a precision error: " << e.what();
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("/spheres/0/radius"), std::string::npos) << e.what();
    }
}

// A triangle whose written points lie on a line, exactly or to within the rounding of the
// file's decimals, has no area at any precision: left out alike in float and double (this
// file is compiled into both), counted, the first named; a thin triangle with an area is kept.
// Nearly collinear as written, a triangle used to collapse in float (a switch to double, a
// refusal in lab 02) or keep a sliver of area made of rounding.
TEST(ScenePlacement, TrianglesOnALineAreLeftOutInEveryPrecision) {
    const auto scene = [](const std::string& triangles, const std::string& quads) {
        return parse_scene(
            "{\"camera\": {\"position\": [0, 1, 3], \"look_at\": [0, 0, 0]},\n"
            "\"materials\": {\"w\": {\"type\": \"diffuse\", \"albedo\": [0.5, 0.5, 0.5]}},\n"
            "\"spheres\": [{\"center\": [0, 0, 0], \"radius\": 1, \"material\": \"w\"}],\n"
            "\"triangles\": [" +
                triangles + "],\n\"quads\": [" + quads + "]}",
            "lines.json");
    };
    const auto triangle = [](const std::string& points) {
        return "{\"vertices\": " + points + ", \"material\": \"w\"}";
    };
    for (const char* line : {
             "[[0.1, 0.2, 0.3], [0.2, 0.4, 0.6], [0.3, 0.6, 0.9]]",  // not exactly, in double
             "[[0, 0, 0], [0.1, 0.3, 0.7], [0.3, 0.9, 2.1]]",
             "[[0.1, 0.7, 0.3], [1.1, 1.7, 1.3], [3.7, 4.3, 3.9]]",
             "[[1000000.1, 0.2, 0.3], [1000000.2, 0.4, 0.6], [1000000.3, 0.6, 0.9]]",
             "[[0, 0, 0], [1, 1, 1], [2, 2, 2]]",  // exactly
         }) {
        const Scene s =
            scene(triangle("[[-1, 0, -1], [1, 0, -1], [0, 0, 1]]") + ", " + triangle(line), "");
        EXPECT_EQ(s.of<Triangle>().size(), 1u) << line;
        EXPECT_EQ(s.line_triangles, 1) << line;
        EXPECT_EQ(s.first_line_triangle, "/triangles/1") << line;
    }
    // Thin, with an area far above the rounding: kept.
    const Scene thin = scene(triangle("[[0, 0, 0], [1, 0, 0], [0.5, 1e-9, 0]]"), "");
    EXPECT_EQ(thin.of<Triangle>().size(), 1u);
    EXPECT_EQ(thin.line_triangles, 0);
    // A quad with three points on a line: its other half is kept, as a triangle.
    const Scene quad = scene("", triangle("[[0, 0, 0], [0.5, 0, 0], [1, 0, 0], [0.5, 0, -1]]"));
    EXPECT_EQ(quad.of<Triangle>().size(), 1u);
    EXPECT_EQ(quad.of<ConvexQuad>().size() + quad.of<AxisRect>().size(), 0u);
    EXPECT_EQ(quad.line_triangles, 1);
    EXPECT_EQ(quad.first_line_triangle, "/quads/0");
}
