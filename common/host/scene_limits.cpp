#include <scene_limits.h>

#include <cfloat>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <scene_centring.h>
#include <scene_schema.h>

const char* const kDoublePlacesIt =
    "double places it: the references switch to it by themselves (./lab01-ref), or make "
    "lab01-ref-double";

const PrecisionLimits kFloatLimits{"float", 1e9,   "1e9",   1e-9,    "1e-9",  8.0 * FLT_EPSILON,
                                   "2^-20", false, "2^-13", FLT_MAX, "3.4e38"};
const PrecisionLimits kDoubleLimits{"double", 1e30, "1e30",  1e-30,   "1e-30",  8.0 * DBL_EPSILON,
                                    "2^-49",  true, "2^-42", DBL_MAX, "1.8e308"};

const PrecisionLimits& build_limits() {
#if defined(RT_DOUBLE)
    return kDoubleLimits;
#else
    return kFloatLimits;
#endif
}

namespace {

std::string format_number(double x) {
    char text[32];
    std::snprintf(text, sizeof text, "%.3g", x);
    return text;
}

// A size, against the type's range and the extent of the primitive it belongs to.
std::string size_problem(const char* what, double size, double extent,
                         const PrecisionLimits& limits) {
    if (size < limits.min_size)
        return std::string(what) + " of " + format_number(size) + " is below " +
               limits.min_size_text + ", too small for the renderer's " + limits.name +
               " arithmetic: scale the scene up";
    if (size < limits.min_relative_size() * extent)
        return std::string(what) + " of " + format_number(size) + " is too small for " +
               limits.name + " precision that far from the scene's centre (coordinates up to " +
               format_number(extent) + "): make it larger, or the scene smaller";
    return "";
}

std::string scene_scale_problem(const char* what, double size, double reach,
                                const PrecisionLimits& limits) {
    if (!(size < limits.min_scene_relative_size() * reach)) return "";
    return std::string(what) + " of " + format_number(size) + " is below " +
           limits.scene_relative_text + " of the scene's reach (" + format_number(reach) +
           " from its centre, camera and light included), finer than " + limits.name +
           " arithmetic places it there";
}

// Whether a triangle with an area as written loses it when its points are rounded to T: the
// normal make_triangle (triangle.h) computes from the rounded points is then zero.
template <class T>
bool collapses(const WrittenPoint (&v)[3]) {
    const auto r = [](double x) { return double(static_cast<T>(x)); };
    const double e1[3] = {r(v[1].x) - r(v[0].x), r(v[1].y) - r(v[0].y), r(v[1].z) - r(v[0].z)};
    const double e2[3] = {r(v[2].x) - r(v[0].x), r(v[2].y) - r(v[0].y), r(v[2].z) - r(v[0].z)};
    return e1[1] * e2[2] - e1[2] * e2[1] == 0.0 && e1[2] * e2[0] - e1[0] * e2[2] == 0.0 &&
           e1[0] * e2[1] - e1[1] * e2[0] == 0.0;
}

double largest(const WrittenPoint& p) {
    return std::fmax(std::fabs(p.x), std::fmax(std::fabs(p.y), std::fabs(p.z)));
}

double distance(const WrittenPoint& a, const WrittenPoint& b) {
    return std::hypot(a.x - b.x, a.y - b.y, a.z - b.z);
}

// Calls f(KindTag<K>{}, pointer, written, i) for every entry i of every kind K written as fields
// (file_fields.h), in AllPrimitives' order: pointer is where the file writes it ("/spheres/0").
template <class F>
void for_each_fields_entry(const WrittenCoordinates& w, F&& f) {
    for_each_fields_kind([&](auto kind) {
        using K = typename decltype(kind)::type;
        const WrittenFields<K>& written = w.fields.of<K>();
        for (size_t i = 0; i < written.values.size() / field_values<K>(); ++i)
            f(kind, std::string("/") + K::kFileKey + "/" + std::to_string(i), written, i);
    });
}

// An entry's largest |coordinate| once centred: its points' plus its largest length (a
// sphere's centre and radius).
template <class K, class Centred>
double fields_extent(const WrittenFields<K>& written, size_t i, const Centred& centred) {
    double points = 0.0, length = 0.0;
    for_each_field<K>([&](const FileField& field, int at) {
        if (field.role == FieldRole::Point)
            points = std::fmax(points, largest(centred(written.point(i, at))));
        if (field.role == FieldRole::Length)
            length = std::fmax(length, written.values[i * field_values<K>() + at]);
    });
    return points + length;
}

}  // namespace

bool on_a_line(const WrittenPoint (&v)[3]) {
    const double e1[3] = {v[1].x - v[0].x, v[1].y - v[0].y, v[1].z - v[0].z};
    const double e2[3] = {v[2].x - v[0].x, v[2].y - v[0].y, v[2].z - v[0].z};
    const double twice_area =
        std::hypot(e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                   e1[0] * e2[1] - e1[1] * e2[0]);
    const double longest =
        std::fmax(distance(v[0], v[1]), std::fmax(distance(v[1], v[2]), distance(v[2], v[0])));
    const double coordinates = std::fmax(largest(v[0]), std::fmax(largest(v[1]), largest(v[2])));
    return !(twice_area > 8.0 * DBL_EPSILON * coordinates * longest);
}

PlacementProblem placement_problem(const Scene& scene, size_t file_triangles,
                                   const PrecisionLimits& limits) {
    const WrittenPoint c = centring_centre(scene);
    const auto centred = [&](const WrittenPoint& p) {
        return WrittenPoint{p.x - c.x, p.y - c.y, p.z - c.z};
    };
    const WrittenCoordinates& w = scene.written;
    // Where the i-th triangle of the scene is written: a triangle, or one half of a quad.
    const auto triangle_pointer = [&](size_t i) {
        return i < file_triangles ? std::string("/") + kTriangleList.key + "/" + std::to_string(i)
                                  : std::string("/") + kQuadList.key + "/" +
                                        std::to_string((i - file_triangles) / 2);
    };
    // A triangle's k-th point in the file: a quad's second half is its v0 v2 v3.
    const auto vertex_pointer = [&](size_t i, int k) {
        const bool second_half = i >= file_triangles && (i - file_triangles) % 2 == 1;
        const int index = second_half && k > 0 ? k + 1 : k;
        return triangle_pointer(i) + "/vertices/" + std::to_string(index);
    };

    // Every point once centred, within the type's range: the primitives', then the light's
    // and the camera's.
    const auto coordinate = [&](const WrittenPoint& p, const std::string& pointer) {
        const WrittenPoint q = centred(p);
        const double axes[3] = {q.x, q.y, q.z};
        for (int axis = 0; axis < 3; ++axis) {
            if (std::fabs(axes[axis]) <= limits.max_coordinate) continue;
            return PlacementProblem{
                pointer + "/" + std::to_string(axis),
                std::string("expected a coordinate within +-") + limits.max_coordinate_text +
                    " of the scene's centre (beyond it the renderer's " + limits.name +
                    " arithmetic overflows): scale the scene down or bring it nearer its "
                    "camera and light"};
        }
        return PlacementProblem{};
    };
    PlacementProblem first;  // the first problem found
    for_each_fields_entry(w, [&](auto kind, const std::string& p, const auto& written, size_t i) {
        using K = typename decltype(kind)::type;
        for_each_field<K>([&](const FileField& field, int at) {
            if (first.empty() && field.role == FieldRole::Point)
                first = coordinate(written.point(i, at), p + "/" + field.key);
        });
    });
    if (!first.empty()) return first;
    // A triangle on a line is left out by the loader (on_a_line): no limit judges it.
    const auto line = [&](size_t i) {
        const WrittenPoint* v = &w.triangle_vertices[3 * i];
        return on_a_line({v[0], v[1], v[2]});
    };
    for (size_t i = 0; i < w.triangle_vertices.size(); ++i) {
        if (line(i / 3)) continue;
        const PlacementProblem problem =
            coordinate(w.triangle_vertices[i], vertex_pointer(i / 3, static_cast<int>(i % 3)));
        if (!problem.empty()) return problem;
    }

    if (scene.camera.written) {
        for (const auto& [p, pointer] :
             {std::pair{scene.camera.written_position, "/camera/position"},
              std::pair{scene.camera.written_look_at, "/camera/look_at"}}) {
            const PlacementProblem problem = coordinate(p, pointer);
            if (!problem.empty()) return problem;
        }
    }
    if (scene.has_light) {
        const PlacementProblem problem = coordinate(w.light_position, "/light/position");
        if (!problem.empty()) return problem;
    }
    // The scene's extent once centred: its largest |coordinate|.
    double extent = 0.0;
    for_each_fields_entry(w, [&](auto kind, const std::string&, const auto& written, size_t i) {
        extent =
            std::fmax(extent, fields_extent<typename decltype(kind)::type>(written, i, centred));
    });
    for (size_t i = 0; i < w.triangle_vertices.size(); ++i)
        if (!line(i / 3)) extent = std::fmax(extent, largest(centred(w.triangle_vertices[i])));
    // The scene's reach: the extent, or the distance of the camera or the light from the
    // centre, where a ray's first offset is sized (ray.h: it grows with t).
    const WrittenPoint origin{0.0, 0.0, 0.0};
    double reach = extent;
    if (scene.camera.written)
        reach = std::fmax(reach, distance(centred(scene.camera.written_position), origin));
    if (scene.has_light) reach = std::fmax(reach, distance(centred(w.light_position), origin));

    // Each length against the type's range, its own entry's extent and the scene's.
    for_each_fields_entry(w, [&](auto kind, const std::string& p, const auto& written, size_t i) {
        using K = typename decltype(kind)::type;
        const double own_extent = fields_extent<K>(written, i, centred);
        for_each_field<K>([&](const FileField& field, int at) {
            if (first.empty() && field.role == FieldRole::Length) {
                const std::string what = std::string("a ") + field.key;
                const double size = written.values[i * field_values<K>() + at];
                std::string found;
                if (size > limits.max_coordinate)
                    found = what + " of " + format_number(size) + " is above " +
                            limits.max_coordinate_text + ", too large for the renderer's " +
                            limits.name + " arithmetic: scale the scene down";
                if (found.empty()) found = size_problem(what.c_str(), size, own_extent, limits);
                if (found.empty()) found = scene_scale_problem(what.c_str(), size, reach, limits);
                if (!found.empty()) first = {p + "/" + field.key, found};
            }
        });
    });
    if (!first.empty()) return first;
    for (size_t i = 0; 3 * i < w.triangle_vertices.size(); ++i) {
        const WrittenPoint v[3] = {centred(w.triangle_vertices[3 * i]),
                                   centred(w.triangle_vertices[3 * i + 1]),
                                   centred(w.triangle_vertices[3 * i + 2])};
        // The written points, whose differences centring leaves as they were.
        const WrittenPoint* raw = &w.triangle_vertices[3 * i];
        if (line(i)) continue;
        const auto edge = [&](int a, int b) {
            return std::hypot(raw[a].x - raw[b].x, raw[a].y - raw[b].y, raw[a].z - raw[b].z);
        };
        const double longest = std::fmax(edge(0, 1), std::fmax(edge(1, 2), edge(2, 0)));
        const double own_extent = std::fmax(largest(v[0]), std::fmax(largest(v[1]), largest(v[2])));
        const char* what = "a triangle with a longest edge";
        std::string problem = size_problem(what, longest, own_extent, limits);
        if (problem.empty()) problem = scene_scale_problem(what, longest, reach, limits);
        if (problem.empty() && (limits.is_double ? collapses<double>(v) : collapses<float>(v)))
            problem = std::string(
                          "the triangle collapses to a line when its vertices are "
                          "rounded to ") +
                      limits.name + ": make it larger, or the scene smaller";
        if (!problem.empty()) return {triangle_pointer(i) + "/vertices", problem};
    }
    return {};
}

PlacementProblem render_problem(const Scene& scene, int image_height, int bounces,
                                const PrecisionLimits& limits) {
    // The view: the angle one pixel spans at the image's centre, 2 tan(vfov / 2) / height.
    const double pixel_angle =
        2.0 * std::tan(double(scene.camera.vfov_degrees) * 0.5 * 3.14159265358979323846 / 180.0) /
        image_height;
    if (pixel_angle < limits.min_pixel_angle())
        return {"/camera/vfov", "a field of view of " + format_number(scene.camera.vfov_degrees) +
                                    " degrees over " + std::to_string(image_height) +
                                    " pixels spans " + format_number(pixel_angle) +
                                    " rad a pixel, finer than " + limits.name +
                                    " ray directions resolve (256 ulps, " +
                                    format_number(limits.min_pixel_angle()) +
                                    " rad): widen the view, or render more pixels"};
    if (!scene.has_light) return {};
    const double intensity =
        std::fmax(double(scene.light.intensity.x),
                  std::fmax(double(scene.light.intensity.y), double(scene.light.intensity.z)));
    if (!(intensity > 0.0)) return {};
    // The light's distance to the nearest primitive's bounding box, from the file's points
    // once centred; at least one ray offset of the scene's reach.
    const WrittenPoint c = centring_centre(scene);
    const WrittenCoordinates& w = scene.written;
    const WrittenPoint light{w.light_position.x - c.x, w.light_position.y - c.y,
                             w.light_position.z - c.z};
    double nearest = INFINITY, reach = 0.0;
    const auto box = [&](const WrittenPoint* points, int n, double margin) {
        double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
        for (int k = 0; k < n; ++k) {
            const double p[3] = {points[k].x - c.x, points[k].y - c.y, points[k].z - c.z};
            for (int axis = 0; axis < 3; ++axis) {
                lo[axis] = std::fmin(lo[axis], p[axis] - margin);
                hi[axis] = std::fmax(hi[axis], p[axis] + margin);
                reach = std::fmax(reach, std::fmax(std::fabs(lo[axis]), std::fabs(hi[axis])));
            }
        }
        const double l[3] = {light.x, light.y, light.z};
        double d2 = 0.0;
        for (int axis = 0; axis < 3; ++axis) {
            const double out = std::fmax(lo[axis] - l[axis], std::fmax(0.0, l[axis] - hi[axis]));
            d2 += out * out;
        }
        nearest = std::fmin(nearest, std::sqrt(d2));
    };
    for_each_fields_entry(w, [&](auto kind, const std::string&, const auto& written, size_t i) {
        using K = typename decltype(kind)::type;
        double margin = 0.0;
        std::vector<WrittenPoint> points;
        for_each_field<K>([&](const FileField& field, int at) {
            if (field.role == FieldRole::Point) points.push_back(written.point(i, at));
            if (field.role == FieldRole::Length)
                margin = std::fmax(margin, written.values[i * field_values<K>() + at]);
        });
        box(points.data(), static_cast<int>(points.size()), margin);
    });
    for (size_t i = 0; 3 * i < w.triangle_vertices.size(); ++i)
        box(&w.triangle_vertices[3 * i], 3, 0.0);
    for (size_t i = 0; 4 * i < w.quad_vertices.size(); ++i) box(&w.quad_vertices[4 * i], 4, 0.0);
    for (size_t i = 0; 4 * i < w.rect_vertices.size(); ++i) box(&w.rect_vertices[4 * i], 4, 0.0);
    if (!std::isfinite(nearest)) return {};  // nothing to light
    reach = std::fmax(reach, distance(light, WrittenPoint{0.0, 0.0, 0.0}));
    if (scene.camera.written) {
        const WrittenPoint& p = scene.camera.written_position;
        reach = std::fmax(reach, distance({p.x - c.x, p.y - c.y, p.z - c.z}, {0.0, 0.0, 0.0}));
    }
    const double d = std::fmax(nearest, limits.relative_offset * reach);
    const double background =
        std::fmax(double(scene.background.x),
                  std::fmax(double(scene.background.y), double(scene.background.z)));
    const double brightest = bounces * (intensity / (3.14159265358979323846 * d * d)) + background;
    if (brightest <= limits.max_value) return {};
    return {"/light/intensity",
            "a light of intensity " + format_number(intensity) + " as near as " + format_number(d) +
                " to a surface gives a path of " + std::to_string(bounces) + " bounces up to " +
                format_number(brightest) + ", beyond " + limits.name + "'s range (" +
                limits.max_value_text + "): dim the light or move it away"};
}
