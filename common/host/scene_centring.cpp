#include <scene_centring.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include <scene_limits.h>

namespace {

struct BoundsD {
    double lo[3] = {std::numeric_limits<double>::max(), std::numeric_limits<double>::max(),
                    std::numeric_limits<double>::max()};
    double hi[3] = {-std::numeric_limits<double>::max(), -std::numeric_limits<double>::max(),
                    -std::numeric_limits<double>::max()};
    bool empty = true;

    void add(WrittenPoint p, double margin = 0.0) {
        const double c[3] = {p.x, p.y, p.z};
        for (int i = 0; i < 3; ++i) {
            lo[i] = std::min(lo[i], c[i] - margin);
            hi[i] = std::max(hi[i], c[i] + margin);
        }
        empty = false;
    }
};

WrittenPoint exact(Vec3 p) { return {p.x, p.y, p.z}; }
Vec3 rounded(WrittenPoint p) {
    return {static_cast<real>(p.x), static_cast<real>(p.y), static_cast<real>(p.z)};
}

// The written point while `own` still stands for it, else `own`.
WrittenPoint pick(bool have, const WrittenPoint& written, Vec3 own) {
    return have && written.rounds_to(own) ? written : exact(own);
}

// The scene's points in double: as the file writes them where the scene still holds them
// (the written point rounds to the scene's own), else the scene's own: a scene built in
// code, or a point changed after loading.
struct ExactPoints {
    const Scene& scene;
    bool sized() const {
        bool fields_sized = true;
        for_each_fields_kind([&](auto kind) {
            using K = typename decltype(kind)::type;
            fields_sized = fields_sized && scene.written.fields.of<K>().values.size() ==
                                               field_values<K>() * scene.of<K>().size();
        });
        return scene.written.present && fields_sized &&
               scene.written.triangle_vertices.size() == 3 * scene.of<Triangle>().size() &&
               scene.written.quad_vertices.size() == 4 * scene.of<ConvexQuad>().size() &&
               scene.written.rect_vertices.size() == 4 * scene.of<AxisRect>().size();
    }
    // Entry i of a kind written as fields (file_fields.h), its values in double: a point or
    // direction as written while its rounded numbers still stand for it, else its own; a length
    // as rendered (which keeps every centre as it was), unless `real` cannot hold it: a radius
    // past float's range is placed by the file's number (scene_limits.h then says float cannot
    // render it).
    template <class K>
    void field_values_of(size_t i, double* out) const {
        real own[field_values<K>()];
        fields_of(scene.of<K>()[i], own);
        const bool have = sized();
        const WrittenFields<K>& written = scene.written.fields.of<K>();
        for_each_field<K>([&](const FileField& field, int at) {
            if (field.role == FieldRole::Length) {
                out[at] = have && !std::isfinite(own[at])
                              ? written.values[i * field_values<K>() + at]
                              : double(own[at]);
            } else {
                const WrittenPoint p = pick(have, have ? written.point(i, at) : WrittenPoint{},
                                            Vec3(own[at], own[at + 1], own[at + 2]));
                p.store(out + at);
            }
        });
    }
    WrittenPoint vertex(size_t i, int k) const {
        const Triangle& t = scene.of<Triangle>()[i];
        return pick(sized(), sized() ? scene.written.triangle_vertices[3 * i + k] : WrittenPoint{},
                    k == 0 ? t.v0 : (k == 1 ? t.v1 : t.v2));
    }
    WrittenPoint quad_vertex(size_t i, int k) const {
        const ConvexQuad& q = scene.of<ConvexQuad>()[i];
        const Vec3 own[4] = {q.v0, q.v1, q.v2, q.v3};
        return pick(sized(), sized() ? scene.written.quad_vertices[4 * i + k] : WrittenPoint{},
                    own[k]);
    }
    // A rectangle keeps its bounds, not its corners: its written corners stand while the
    // rectangle is the one the loader built from them (each rounded where it is written),
    // else its own corners (rect_corners) are used. Not "each written corner rounds to a
    // corner": a floor whose corners wobble by 1e-10 about 1e6 + 2^-5, a tie in float, rounds
    // them apart, and was then placed from those corners, off by up to 0.04.
    WrittenPoint rect_vertex(size_t i, int k) const {
        const AxisRect& r = scene.of<AxisRect>()[i];
        bool written_stand = sized();
        if (written_stand) {
            const WrittenPoint* w = &scene.written.rect_vertices[4 * i];
            const Vec3 loaded[4] = {rounded(w[0]), rounded(w[1]), rounded(w[2]), rounded(w[3])};
            const AxisRect built = make_axis_rect(loaded, rect_axis(r), r.material);
            written_stand = built.plane == r.plane && built.lo_u == r.lo_u &&
                            built.lo_v == r.lo_v && built.hi_u == r.hi_u && built.hi_v == r.hi_v &&
                            built.axis_side == r.axis_side;
        }
        if (written_stand) return scene.written.rect_vertices[4 * i + k];
        Vec3 own[4];
        rect_corners(r, own);
        return exact(own[k]);
    }
    WrittenPoint camera_position() const {
        return pick(scene.camera.written, scene.camera.written_position, scene.camera.position);
    }
    WrittenPoint camera_look_at() const {
        return pick(scene.camera.written, scene.camera.written_look_at, scene.camera.look_at);
    }
    WrittenPoint light() const {
        return pick(scene.written.present, scene.written.light_position, scene.light.position);
    }
};

void centre_of_bounds(const Scene& scene, double centre[3]) {
    const ExactPoints points{scene};
    BoundsD box;
    for_each_fields_kind([&](auto kind) {  // each point, by its entry's largest length
        using K = typename decltype(kind)::type;
        for (size_t i = 0; i < scene.of<K>().size(); ++i) {
            double v[field_values<K>()];
            points.template field_values_of<K>(i, v);
            double margin = 0.0;
            for_each_field<K>([&](const FileField& field, int at) {
                if (field.role == FieldRole::Length) margin = std::max(margin, v[at]);
            });
            for_each_field<K>([&](const FileField& field, int at) {
                if (field.role == FieldRole::Point) box.add({v[at], v[at + 1], v[at + 2]}, margin);
            });
        }
    });
    for (size_t i = 0; i < scene.of<Triangle>().size(); ++i) {
        const WrittenPoint v[3] = {points.vertex(i, 0), points.vertex(i, 1), points.vertex(i, 2)};
        if (on_a_line(v)) continue;  // left out by the loader: the centre is the same without it
        for (const WrittenPoint& p : v) box.add(p);
    }
    for (size_t i = 0; i < scene.of<ConvexQuad>().size(); ++i) {
        for (int k = 0; k < 4; ++k) box.add(points.quad_vertex(i, k));
    }
    for (size_t i = 0; i < scene.of<AxisRect>().size(); ++i) {
        for (int k = 0; k < 4; ++k) box.add(points.rect_vertex(i, k));
    }
    for (int axis = 0; axis < 3; ++axis)
        centre[axis] = box.empty ? 0.0 : 0.5 * (box.lo[axis] + box.hi[axis]);
}

// p - centre, in double, rounded once.
WrittenPoint minus(WrittenPoint p, const double centre[3]) {
    return {p.x - centre[0], p.y - centre[1], p.z - centre[2]};
}
}  // namespace

WrittenPoint centring_centre(const Scene& scene) {
    double centre[3];
    centre_of_bounds(scene, centre);
    return {centre[0], centre[1], centre[2]};
}

Vec3 moved_to_centre(const WrittenPoint& p, const WrittenPoint& centre) {
    const double c[3] = {centre.x, centre.y, centre.z};
    return rounded(minus(p, c));
}

Vec3 centring_offset(const Scene& scene) {
    double centre[3];
    centre_of_bounds(scene, centre);
    return {static_cast<real>(-centre[0]), static_cast<real>(-centre[1]),
            static_cast<real>(-centre[2])};
}

Scene centre_scene(Scene scene) {
    double centre[3];
    centre_of_bounds(scene, centre);
    if (centre[0] == 0.0 && centre[1] == 0.0 && centre[2] == 0.0)
        return scene;  // already centred: keep every bit as loaded
    const ExactPoints points{scene};
    WrittenCoordinates moved;
    moved.present = true;
    for_each_fields_kind([&](auto kind) {  // the points moved, the rest as they are
        using K = typename decltype(kind)::type;
        for (size_t i = 0; i < scene.of<K>().size(); ++i) {
            double v[field_values<K>()];
            points.template field_values_of<K>(i, v);
            for_each_field<K>([&](const FileField& field, int at) {
                if (field.role == FieldRole::Point) {
                    const WrittenPoint p = minus({v[at], v[at + 1], v[at + 2]}, centre);
                    p.store(v + at);
                } else if (field.role == FieldRole::Length && points.sized()) {
                    v[at] = scene.written.fields.of<K>().values[i * field_values<K>() + at];
                }
            });
            std::vector<double>& values = moved.fields.of<K>().values;
            values.insert(values.end(), v, v + field_values<K>());
        }
    });
    for (size_t i = 0; i < scene.of<Triangle>().size(); ++i) {
        for (int k = 0; k < 3; ++k)
            moved.triangle_vertices.push_back(minus(points.vertex(i, k), centre));
    }
    for (size_t i = 0; i < scene.of<ConvexQuad>().size(); ++i) {
        for (int k = 0; k < 4; ++k)
            moved.quad_vertices.push_back(minus(points.quad_vertex(i, k), centre));
    }
    for (size_t i = 0; i < scene.of<AxisRect>().size(); ++i) {
        for (int k = 0; k < 4; ++k)
            moved.rect_vertices.push_back(minus(points.rect_vertex(i, k), centre));
    }
    const WrittenPoint camera_position = minus(points.camera_position(), centre);
    const WrittenPoint camera_look_at = minus(points.camera_look_at(), centre);
    moved.light_position = minus(points.light(), centre);

    for_each_fields_kind([&](auto kind) {  // each rebuilt with its points moved
        using K = typename decltype(kind)::type;
        for (size_t i = 0; i < scene.of<K>().size(); ++i) {
            real v[field_values<K>()];
            fields_of(scene.of<K>()[i], v);
            for_each_field<K>([&](const FileField& field, int at) {
                if (field.role == FieldRole::Point) {
                    const Vec3 p = rounded(moved.fields.of<K>().point(i, at));
                    for (int axis = 0; axis < 3; ++axis) v[at + axis] = p[axis];
                }
            });
            scene.of<K>()[i] = from_fields(KindTag<K>{}, v, scene.of<K>()[i].material);
        }
    });
    for (size_t i = 0; i < scene.of<Triangle>().size(); ++i) {
        const WrittenPoint* v = &moved.triangle_vertices[3 * i];
        const int cut_edges = scene.of<Triangle>()[i].cut_edges;  // the loader's (t_junctions.h)
        scene.of<Triangle>()[i] = make_triangle(rounded(v[0]), rounded(v[1]), rounded(v[2]),
                                                scene.of<Triangle>()[i].material);
        scene.of<Triangle>()[i].cut_edges = cut_edges;
    }
    // Each quad and rectangle keeps its kind: the loader chose it on these very points
    // (scene_loader.cpp), so a rectangle's corners still share their coordinates exactly.
    for (size_t i = 0; i < scene.of<ConvexQuad>().size(); ++i) {
        const WrittenPoint* v = &moved.quad_vertices[4 * i];
        const int cut_edges = scene.of<ConvexQuad>()[i].cut_edges;
        scene.of<ConvexQuad>()[i] =
            make_convex_quad(rounded(v[0]), rounded(v[1]), rounded(v[2]), rounded(v[3]),
                             scene.of<ConvexQuad>()[i].material);
        scene.of<ConvexQuad>()[i].cut_edges = cut_edges;
    }
    for (size_t i = 0; i < scene.of<AxisRect>().size(); ++i) {
        const WrittenPoint* v = &moved.rect_vertices[4 * i];
        const Vec3 corners[4] = {rounded(v[0]), rounded(v[1]), rounded(v[2]), rounded(v[3])};
        scene.of<AxisRect>()[i] = make_axis_rect(corners, rect_axis(scene.of<AxisRect>()[i]),
                                                 scene.of<AxisRect>()[i].material);
    }
    scene.camera.position = rounded(camera_position);
    scene.camera.look_at = rounded(camera_look_at);
    scene.camera.written = true;
    scene.camera.written_position = camera_position;
    scene.camera.written_look_at = camera_look_at;
    scene.light.position = rounded(moved.light_position);
    scene.written = moved;
    return scene;
}
