// T-junctions (t_junctions.h): closed rooms whose walls meet part-way along an edge (a floor
// rectangle along a triangle's or a convex quad's edge, a convex quad's corner on the floor's
// edge, two triangles whose collinear edges partly overlap) are loaded as files are, centred,
// and rays from inside aimed at points of the lines where they meet must hit something; a
// mirror cell whose ceiling's edges run across its walls must keep every path in.
// Written in `real`: built into the float unit tests and into the double build's
// (build/precision_tests_double), since rounding lets different rays through in each.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include <cli.h>
#include <path_tracer.h>
#include <scene_centring.h>
#include <scene_loader.h>
#include <t_junctions.h>

namespace {

using Point = std::array<double, 3>;

// The room's box, on numbers no power of two divides, so centring rounds them.
constexpr double kX0 = -0.731, kX1 = 1.217, kY0 = -0.452, kY1 = 0.883, kZ0 = -1.377, kZ1 = -0.119;
constexpr double kXm = 0.5 * (kX0 + kX1), kWidth = kX1 - kX0, kHeight = kY1 - kY0;

Point box(int i, int j, int k) { return {i ? kX1 : kX0, j ? kY1 : kY0, k ? kZ1 : kZ0}; }

// A room as written, then turned about a generic axis and moved (in double), as a scene
// file, and the segments along which its walls meet part-way, in the same frame.
struct Room {
    std::vector<std::vector<Point>> triangles, quads;
    std::vector<std::array<Point, 2>> junctions;
    bool rotated = false;
    double scale = 1;         // applied with the rotation, before the move (times scale)
    bool background = false;  // a background of 1 (a path that leaves the room sees it)

    Point placed(Point p) const {
        if (!rotated) return p;
        // About the axis (0.3, 1, 0.2) by 23.7 degrees (Rodrigues), then moved.
        const double n = std::sqrt(0.09 + 1 + 0.04), a[3] = {0.3 / n, 1 / n, 0.2 / n};
        const double c = std::cos(23.7 * M_PI / 180), s = std::sin(23.7 * M_PI / 180);
        const double d = a[0] * p[0] + a[1] * p[1] + a[2] * p[2];
        const double x[3] = {a[1] * p[2] - a[2] * p[1], a[2] * p[0] - a[0] * p[2],
                             a[0] * p[1] - a[1] * p[0]};
        const double offset[3] = {12.37, -6.21, 3.11};
        Point out;
        for (int i = 0; i < 3; ++i)
            out[i] = (p[i] * c + x[i] * s + a[i] * d * (1 - c) + offset[i]) * scale;
        return out;
    }

    std::string json() const {
        const auto point = [&](Point p) {
            p = placed(p);
            char text[96];
            std::snprintf(text, sizeof text, "[%.17g, %.17g, %.17g]", p[0], p[1], p[2]);
            return std::string(text);
        };
        const auto list = [&](const std::vector<std::vector<Point>>& polygons) {
            std::string out;
            for (const auto& polygon : polygons) {
                out += std::string(out.empty() ? "" : ", ") + "{\"vertices\": [";
                for (size_t k = 0; k < polygon.size(); ++k)
                    out += (k ? ", " : "") + point(polygon[k]);
                out += "], \"material\": \"mirror\"}";
            }
            return out;
        };
        return "{\"camera\": {\"position\": " + point({kXm, 0.1, -0.7}) +
               ", \"look_at\": " + point({kXm, 0.1, -1.0}) + "}, " +
               (background ? "\"background\": [1, 1, 1], " : "") +
               "\"materials\": {\"mirror\": {\"type\": \"mirror\", \"albedo\": [1, 1, 1]}}, " +
               "\"triangles\": [" + list(triangles) + "], \"quads\": [" + list(quads) + "]}";
    }
};

// The box's floor, ceiling, left, right and back faces as quads (front sides inward); the
// front is the room's own.
std::vector<std::vector<Point>> walls_but_front() {
    return {{box(0, 0, 0), box(0, 0, 1), box(1, 0, 1), box(1, 0, 0)},   // floor
            {box(0, 1, 0), box(1, 1, 0), box(1, 1, 1), box(0, 1, 1)},   // ceiling
            {box(0, 0, 0), box(0, 1, 0), box(0, 1, 1), box(0, 0, 1)},   // left
            {box(1, 0, 0), box(1, 0, 1), box(1, 1, 1), box(1, 1, 0)},   // right
            {box(0, 0, 1), box(0, 1, 1), box(1, 1, 1), box(1, 0, 1)}};  // back
}

// The front closed by one triangle wider than the room, the floor's front edge lying
// part-way along its bottom edge: the floor and every other wall are rectangles.
Room rectangle_floor_on_a_triangle_wall() {
    Room room;
    room.quads = walls_but_front();
    room.triangles = {
        {{kX0 - kWidth, kY0, kZ0}, {kX1 + kWidth, kY0, kZ0}, {kXm, kY0 + 3.3 * kHeight, kZ0}}};
    room.junctions = {{box(0, 0, 0), box(1, 0, 0)}};
    return room;
}

// The front closed by a trapezoid (a convex quad) wider than the room, and the back by two
// trapezoids whose shared corner lies on the floor's back edge: the floor meets quads
// part-way along their edges and they meet it part-way along its own.
Room rectangle_floor_on_convex_quads() {
    Room room;
    room.quads = walls_but_front();
    room.quads.pop_back();
    const double top = kY1 + 0.5 * kHeight, left = kX0 - 0.5 * kWidth, right = kX1 + 0.5 * kWidth;
    const double xm_top = kXm + 0.1 * kWidth;
    room.quads.push_back(
        {{left - 0.2, kY0, kZ0}, {right + 0.2, kY0, kZ0}, {right, top, kZ0}, {left, top, kZ0}});
    room.quads.push_back({{left, kY0, kZ1}, {left, top, kZ1}, {xm_top, top, kZ1}, {kXm, kY0, kZ1}});
    room.quads.push_back(
        {{kXm, kY0, kZ1}, {xm_top, top, kZ1}, {right, top, kZ1}, {right, kY0, kZ1}});
    room.junctions = {{box(0, 0, 0), box(1, 0, 0)},
                      {box(0, 0, 1), Point{kXm, kY0, kZ1}},
                      {Point{kXm, kY0, kZ1}, box(1, 0, 1)}};
    return room;
}

// rectangle_floor_on_a_triangle_wall with the floor as two triangles, turned and moved: the
// floor's front triangle has an edge along part of the wall triangle's, and no edge of the
// room is axis-aligned (the other walls are convex quads).
Room two_triangles_overlapping_along_an_edge() {
    Room room = rectangle_floor_on_a_triangle_wall();
    const std::vector<Point> floor = room.quads.front();
    room.quads.erase(room.quads.begin());
    room.triangles.push_back({floor[0], floor[1], floor[2]});
    room.triangles.push_back({floor[0], floor[2], floor[3]});
    room.rotated = true;
    return room;
}

// A closed mirror cell whose four walls rise past its ceiling to an open top: the ceiling's
// edges lie inside the walls' faces, and its corners on the walls' upright edges. As quads
// (axis-aligned: rectangles once loaded), turned and moved (convex quads), or as triangles.
enum class CellKind { kRects, kConvexQuads, kTriangles };
Room ceiling_inside_rising_walls(CellKind kind) {
    const double top = kY1 + 0.6 * kHeight;
    const auto wall = [&](int i, int j, int k) {  // box(), with the walls' top at `top`
        Point p = box(i, j, k);
        if (j) p[1] = top;
        return p;
    };
    Room room;
    room.quads = {{box(0, 0, 0), box(0, 0, 1), box(1, 0, 1), box(1, 0, 0)},     // floor
                  {box(0, 1, 0), box(1, 1, 0), box(1, 1, 1), box(0, 1, 1)},     // ceiling
                  {wall(0, 0, 0), wall(0, 1, 0), wall(0, 1, 1), wall(0, 0, 1)},  // left
                  {wall(1, 0, 0), wall(1, 0, 1), wall(1, 1, 1), wall(1, 1, 0)},  // right
                  {wall(0, 0, 1), wall(0, 1, 1), wall(1, 1, 1), wall(1, 0, 1)},  // back
                  {wall(0, 0, 0), wall(1, 0, 0), wall(1, 1, 0), wall(0, 1, 0)}}; // front
    room.junctions = {{box(0, 1, 0), box(1, 1, 0)},
                      {box(1, 1, 0), box(1, 1, 1)},
                      {box(1, 1, 1), box(0, 1, 1)},
                      {box(0, 1, 1), box(0, 1, 0)}};
    room.rotated = kind != CellKind::kRects;
    if (kind == CellKind::kTriangles) {
        for (const auto& q : room.quads) {
            room.triangles.push_back({q[0], q[1], q[2]});
            room.triangles.push_back({q[0], q[2], q[3]});
        }
        room.quads.clear();
    }
    room.background = true;
    return room;
}

// Rays from random points inside the room toward points of its junction lines (the rendered
// points: the written ones moved as centring moves them, rounded once), `per_line` to a line,
// the first two to its ends where `ends`; the number `escapes(scene, ray)` says got out.
template <class Escapes>
int count_escaping(const Room& room, const Scene& loaded, int per_line, unsigned seed, bool ends,
                   Escapes escapes) {
    const WrittenPoint centre = centring_centre(loaded);
    const Scene scene = centre_scene(loaded);
    const auto rendered = [&](Point p) {
        p = room.placed(p);
        return moved_to_centre({p[0], p[1], p[2]}, centre);
    };
    std::mt19937 gen(seed);
    std::uniform_real_distribution<double> inner(0.05, 0.95), along(0.0, 1.0);
    int escaped = 0;
    for (const auto& line : room.junctions) {
        const Vec3 a = rendered(line[0]), b = rendered(line[1]);
        for (int i = 0; i < per_line; ++i) {
            const Point inside{kX0 + kWidth * inner(gen), kY0 + kHeight * inner(gen),
                               kZ0 + (kZ1 - kZ0) * inner(gen)};
            // A point of the segment in `real`: on it, or beside it by rounding only.
            const real s = ends && i < 2 ? real(i) : static_cast<real>(along(gen));
            const Vec3 target = a + (b - a) * s;
            const Vec3 origin = rendered(inside);
            escaped += escapes(scene, Ray{origin, normalize(target - origin)});
        }
    }
    return escaped;
}

// Paths toward points of the cell's ceiling edges, traced through the mirrors for 64 bounces:
// the number that reach the background (the cell is closed, so none should).
int escaping_paths(const Room& room, int paths_per_line) {
    return count_escaping(
        room, parse_scene(room.json(), "cell.json"), paths_per_line, 11, false,
        [](const Scene& scene, const Ray& ray) {
            return !is_black(trace_path(scene.view(), ray, SampleStream(1, 2, 3), 64));
        });
}

// Rays toward points of the room's junction lines, ends included: the number that hit nothing.
int escaping_rays(const Room& room, int rays_per_line) {
    const Scene loaded = parse_scene(room.json(), "room.json");
    EXPECT_GT(loaded.t_junction_pieces, 0);
    return count_escaping(
        room, loaded, rays_per_line, 7, true,
        [](const Scene& scene, const Ray& ray) { return !closest_hit(scene.view(), ray).found(); });
}

}  // namespace

TEST(TJunctions, RectangleFloorAlongATriangleWallLetsNoRayOut) {
    EXPECT_EQ(escaping_rays(rectangle_floor_on_a_triangle_wall(), 4000), 0);
}

TEST(TJunctions, RectangleFloorAndConvexQuadWallsLetNoRayOut) {
    EXPECT_EQ(escaping_rays(rectangle_floor_on_convex_quads(), 4000), 0);
}

TEST(TJunctions, TrianglesOverlappingAlongAnEdgeLetNoRayOut) {
    EXPECT_EQ(escaping_rays(two_triangles_overlapping_along_an_edge(), 4000), 0);
}

// The tolerance is relative: the same room tiny, or large and far from the origin.
TEST(TJunctions, TrianglesOverlappingAlongAnEdgeLetNoRayOutAtAnyScale) {
    for (double scale : {1e-3, 1e4}) {
        Room room = two_triangles_overlapping_along_an_edge();
        room.scale = scale;
        EXPECT_EQ(escaping_rays(room, 2000), 0) << "scale " << scale;
    }
}

// Splitting again finds nothing: a loaded room has no T-junction left, and a scene without
// one (the shipped scenes) keeps every bit of every primitive and written point.
TEST(TJunctions, ALoadedSceneHasNoneLeftAndOthersKeepEveryBit) {
    std::vector<Scene> scenes = {
        parse_scene(rectangle_floor_on_a_triangle_wall().json(), "a"),
        parse_scene(rectangle_floor_on_convex_quads().json(), "b"),
        parse_scene(two_triangles_overlapping_along_an_edge().json(), "c")};
    for (const char* name : {"cornell", "showcase"}) {
        scenes.push_back(load_scene(source_tree_path("common/scenes/") + name + ".json"));
        EXPECT_EQ(scenes.back().t_junction_pieces, 0) << name;
    }
    for (const Scene& loaded : scenes) {
        Scene again = loaded;
        EXPECT_EQ(split_t_junctions(again), 0) << loaded.name;
        const auto same_bytes = [](const auto& a, const auto& b) {
            return a.size() == b.size() &&
                   (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(a[0])) == 0);
        };
        EXPECT_TRUE(same_bytes(again.of<Triangle>(), loaded.of<Triangle>())) << loaded.name;
        EXPECT_TRUE(same_bytes(again.of<ConvexQuad>(), loaded.of<ConvexQuad>())) << loaded.name;
        EXPECT_TRUE(same_bytes(again.of<AxisRect>(), loaded.of<AxisRect>())) << loaded.name;
        EXPECT_TRUE(same_bytes(again.written.triangle_vertices, loaded.written.triangle_vertices));
        EXPECT_TRUE(same_bytes(again.written.quad_vertices, loaded.written.quad_vertices));
        EXPECT_TRUE(same_bytes(again.written.rect_vertices, loaded.written.rect_vertices));
    }
}

// Edges that run inside faces: the ceiling's edges run across the walls' faces. The loader
// cuts each wall along the ceiling's edge line, so the ceiling and the wall's parts share that
// edge end to end, and marks it a cut edge on the wall's parts: a path that the rounding lets
// hit the part above the ceiling steps off the edge to the side it came from (triangle.h's
// step_off_cut_edge). Before, hundreds of the paths left the cell in either precision, the
// walls as rectangles, convex quads or triangles (docs/extremes.md).
TEST(TJunctions, ACeilingInsideRisingWallsLetsNoPathOut) {
    for (CellKind kind : {CellKind::kRects, CellKind::kConvexQuads, CellKind::kTriangles}) {
        EXPECT_EQ(escaping_paths(ceiling_inside_rising_walls(kind), 1000), 0)
            << "kind " << static_cast<int>(kind);
    }
}
