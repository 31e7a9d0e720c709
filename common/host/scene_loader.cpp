#include <scene_loader.h>

#include <array>
#include <cerrno>
#include <cfloat>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>
#include <utility>
#include <vector>

#include <errors.h>
#include <json_with_positions.h>
#include <scene_centring.h>
#include <scene_limits.h>
#include <scene_schema.h>
#include <t_junctions.h>

using nlohmann::json;

namespace {

// The shortest decimal that reads back as x: a number as the file wrote it (179.99999999, not
// 180 or 179.99999999000001).
std::string shortest(double x) {
    char text[40];
    const std::to_chars_result end = std::to_chars(text, text + sizeof text, x);
    return std::string(text, end.ptr);
}

// Walks the DOM with knowledge of where each value sits in the text.
class SceneReader {
public:
    SceneReader(const std::string& name, const std::string& text,
                const std::map<std::string, size_t>& offsets)
        : name_(name), text_(text), offsets_(offsets) {}

    [[noreturn]] void fail(const std::string& pointer, const std::string& what) const {
        auto it = offsets_.find(pointer);
        const size_t offset = it == offsets_.end() ? 0 : it->second;
        throw InputError(name_ + ":" + line_column(text_, offset) + ": " +
                         (pointer.empty() ? std::string("top level") : pointer) + ": " + what);
    }

    // Rejects keys outside `allowed`, naming the first unknown one.
    void check_keys(const json& obj, const std::string& pointer,
                    const std::vector<const char*>& allowed) const {
        if (!obj.is_object()) fail(pointer, "expected an object, found " + type_of(obj));
        for (auto it = obj.begin(); it != obj.end(); ++it) {
            bool known = false;
            std::string list;
            for (const char* a : allowed) {
                known = known || it.key() == a;
                list += std::string(list.empty() ? "" : ", ") + "\"" + a + "\"";
            }
            if (!known)
                fail_key(pointer + "/" + pointer_token(it.key()),
                         "unknown key \"" + it.key() + "\" (expected one of " + list + ")");
        }
    }

    // The same, for what only the float build cannot place: a PrecisionError.
    [[noreturn]] void fail_precision(const std::string& pointer, const std::string& what) const {
        try {
            fail(pointer, what);
        } catch (const InputError& e) {
            throw PrecisionError(e.what());
        }
    }

    [[noreturn]] void fail_key(const std::string& pointer, const std::string& what) const {
        auto it = offsets_.find(pointer + "#key");
        throw InputError(name_ + ":" + line_column(text_, it == offsets_.end() ? 0 : it->second) +
                         ": " + what);
    }

    const json& require(const json& obj, const std::string& pointer, const char* key) const {
        if (!obj.contains(key)) fail(pointer, std::string("missing required key \"") + key + "\"");
        return obj.at(key);
    }

    // Every range is judged on the number as the file writes it (a double), alike in both
    // builds: float would accept an albedo of 1 + 1e-9 (it rounds to 1) that double refuses.
    // What float alone cannot hold (a number beyond its range, or one it rounds out of its
    // field's range) is noted here, the first of it, and made a PrecisionError in the float
    // build once the whole file has been read (check_placement): a reference renders it in
    // double, and an error later in the file is still reported as an input error.
    mutable PlacementProblem float_problem;

    void note_float_problem(const std::string& pointer, const std::string& what) const {
        if (float_problem.empty()) float_problem = {pointer, what};
    }

    // The number as the file writes it: any finite double. A coordinate or a length is judged
    // once the scene is centred (scene_limits.h); any other number must be within float's
    // range for the float build.
    double written_number(const json& v, const std::string& pointer,
                          bool coordinate = false) const {
        if (!v.is_number()) fail(pointer, "expected a number, found " + type_of(v));
        const double d = v.get<double>();
        if (!std::isfinite(d)) fail(pointer, "expected a finite number");
        if (!coordinate && std::fabs(d) > FLT_MAX)
            note_float_problem(pointer, shortest(d) + " is beyond float's range (3.4e38)");
        return d;
    }

    std::array<double, 3> written_vec3(const json& v, const std::string& pointer) const {
        if (!v.is_array() || v.size() != 3)
            fail(pointer, "expected an array of 3 numbers, found " + type_of(v));
        return {written_number(v[0], pointer + "/0"), written_number(v[1], pointer + "/1"),
                written_number(v[2], pointer + "/2")};
    }

    static Vec3 rounded(const std::array<double, 3>& w) {
        return {static_cast<real>(w[0]), static_cast<real>(w[1]), static_cast<real>(w[2])};
    }

    Vec3 vec3(const json& v, const std::string& pointer) const {
        return rounded(written_vec3(v, pointer));
    }

    Vec3 non_negative_vec3(const json& v, const std::string& pointer) const {
        const std::array<double, 3> w = written_vec3(v, pointer);
        if (w[0] < 0 || w[1] < 0 || w[2] < 0) fail(pointer, "expected components >= 0");
        return rounded(w);
    }

    Vec3 albedo(const json& v, const std::string& pointer) const {
        const std::array<double, 3> w = written_vec3(v, pointer);
        if (w[0] < 0 || w[1] < 0 || w[2] < 0) fail(pointer, "expected components >= 0");
        if (w[0] > 1 || w[1] > 1 || w[2] > 1)
            fail(pointer, "expected an albedo with components in [0, 1] (energy conservation)");
        return rounded(w);
    }

    // A number within (lo, hi), or [lo, hi] when `closed`, as written; refused with `what`
    // otherwise. One that float rounds out of the range is noted for the float build.
    real ranged(const json& v, const std::string& pointer, double lo, double hi, bool closed,
                const std::string& what) const {
        const double d = written_number(v, pointer);
        const auto within = [&](double x) {
            return closed ? x >= lo && x <= hi : x > lo && x < hi;
        };
        if (!within(d)) fail(pointer, what);
        const double in_float = static_cast<float>(d);
        if (!within(in_float))
            note_float_problem(pointer, shortest(d) + " rounds to " + shortest(in_float) +
                                            " in float, outside the range");
        return static_cast<real>(d);
    }

    long long integer(const json& v, const std::string& pointer, long long lo, long long hi) const {
        if (!v.is_number_integer()) fail(pointer, "expected an integer, found " + type_of(v));
        const long long x = v.get<long long>();
        if (x < lo || x > hi)
            fail(pointer, "expected an integer in " + std::to_string(lo) + ".." +
                              std::to_string(hi) + ", found " + v.dump());
        return x;
    }

    static std::string type_of(const json& v) {
        switch (v.type()) {
            case json::value_t::null: return "null";
            case json::value_t::boolean: return "a boolean";
            case json::value_t::string: return "a string";
            case json::value_t::array: return "an array of " + std::to_string(v.size());
            case json::value_t::object: return "an object";
            default: return "a number";
        }
    }

private:
    const std::string& name_;
    const std::string& text_;
    const std::map<std::string, size_t>& offsets_;
};

// A point of the scene: rounded to `real`, and as the file writes it, in double. What the
// renderer can place is judged once every point is read and the scene centred
// (scene_limits.h), not here, where the point may lie far from the scene's centre.
Vec3 read_position(const SceneReader& r, const json& v, const std::string& pointer,
                   WrittenPoint& written) {
    if (!v.is_array() || v.size() != 3)
        r.fail(pointer, "expected an array of 3 numbers, found " + SceneReader::type_of(v));
    double c[3];
    for (int axis = 0; axis < 3; ++axis)
        c[axis] = r.written_number(v[axis], pointer + "/" + std::to_string(axis), true);
    written = {c[0], c[1], c[2]};
    return {static_cast<real>(c[0]), static_cast<real>(c[1]), static_cast<real>(c[2])};
}

// The triangle of vertices a, b, c of a primitive's "vertices"; its written points go to
// scene.written.
Triangle read_triangle(const json& obj, const std::vector<Vec3>& v, int a, int b, int c,
                       int material, Scene& scene) {
    const int corners[3] = {a, b, c};
    for (int k = 0; k < 3; ++k) {
        const json& point = obj["vertices"][corners[k]];
        scene.written.triangle_vertices.push_back(
            {point[0].get<double>(), point[1].get<double>(), point[2].get<double>()});
    }
    return make_triangle(v[a], v[b], v[c], material);
}

// The parts of a scene file, one reader each, in the order of the format's description.

// The view's direction and its checks are the file's numbers, in double: in float, a look_at
// 1e-23 away (or a whole scene at scale 1e-25) has a squared distance that underflows to 0,
// and the camera was refused as looking at itself.
void read_camera(const SceneReader& r, const json& root, Scene& scene) {
    CameraSpec& camera = scene.camera;
    WrittenPoint& from = camera.written_position;
    WrittenPoint& to = camera.written_look_at;
    camera.written = true;
    const json& cam = r.require(root, "", "camera");
    r.check_keys(cam, "/camera", {"position", "look_at", "up", "vfov"});
    camera.position =
        read_position(r, r.require(cam, "/camera", "position"), "/camera/position", from);
    camera.look_at = read_position(r, r.require(cam, "/camera", "look_at"), "/camera/look_at", to);
    std::array<double, 3> written_up = {0.0, 1.0, 0.0};
    if (cam.contains("up")) {
        written_up = r.written_vec3(cam["up"], "/camera/up");
        camera.up = SceneReader::rounded(written_up);
    }
    if (cam.contains("vfov"))
        camera.vfov_degrees = r.ranged(cam["vfov"], "/camera/vfov", 0.0, 180.0, false,
                                       "expected a field of view in degrees, in (0, 180)");
    const double forward[3] = {to.x - from.x, to.y - from.y, to.z - from.z};
    if (forward[0] == 0.0 && forward[1] == 0.0 && forward[2] == 0.0)
        r.fail("/camera/look_at",
               "expected a point different from the camera position (as doubles, they are "
               "equal)");
    // Parallel or not, on unit vectors: a cross product of raw ones can underflow. Judged on
    // the up vector as written; one that only float rounds to zero or parallel is noted.
    const double f_length = std::hypot(forward[0], forward[1], forward[2]);
    const auto usable = [&](double ux, double uy, double uz) {
        const double up_length = std::hypot(ux, uy, uz);
        double f[3];
        for (int axis = 0; axis < 3; ++axis) f[axis] = forward[axis] / f_length;
        const double u[3] = {ux / up_length, uy / up_length, uz / up_length};
        const double right[3] = {f[1] * u[2] - f[2] * u[1], f[2] * u[0] - f[0] * u[2],
                                 f[0] * u[1] - f[1] * u[0]};
        return up_length > 0.0 && std::hypot(right[0], right[1], right[2]) >= 1e-30;
    };
    if (!usable(written_up[0], written_up[1], written_up[2]))
        r.fail("/camera/up", "expected an up vector not parallel to the viewing direction");
    if (!usable(static_cast<float>(written_up[0]), static_cast<float>(written_up[1]),
                static_cast<float>(written_up[2])))
        r.note_float_problem("/camera/up",
                             "the up vector rounds to one parallel to the view (or zero) in float");
}

void read_light(const SceneReader& r, const json& root, Scene& scene) {
    if (!root.contains("light")) return;
    const json& light = root["light"];
    r.check_keys(light, "/light", {"position", "intensity"});
    scene.has_light = true;
    scene.light.position = read_position(r, r.require(light, "/light", "position"),
                                         "/light/position", scene.written.light_position);
    scene.light.intensity =
        r.non_negative_vec3(r.require(light, "/light", "intensity"), "/light/intensity");
}

// A material of the kind whose kName is its "type" (AllMaterials, material.h), with the
// albedo and the number its kind reads.
Material read_material(const SceneReader& r, const json& m, const std::string& p) {
    if (!m.is_object()) r.fail(p, "expected an object, found " + SceneReader::type_of(m));
    const json& type = r.require(m, p, "type");
    Material mat{material_type<Diffuse>, Vec3(0.0f), 1.0f};
    bool known = false;
    std::string names;  // the types a file may name: "\"diffuse\", \"mirror\" or \"glass\""
    for_each_kind(AllMaterials{}, [&](auto kind) {
        using K = typename decltype(kind)::type;
        const bool last = kind_index<AllMaterials, K> + 1 == AllMaterials::kCount;
        names += (names.empty() ? "\"" : last ? " or \"" : ", \"") + std::string(K::kName) + '"';
        if (known || type != K::kName) return;
        known = true;
        mat.type = material_type<K>;
        std::vector<const char*> keys = {"type"};
        if (K::kAlbedo) keys.push_back("albedo");
        if (K::kNumber.key) keys.push_back(K::kNumber.key);
        r.check_keys(m, p, keys);
        if (K::kAlbedo) mat.albedo = r.albedo(r.require(m, p, "albedo"), p + "/albedo");
        if (K::kNumber.key) {
            const std::string at = p + "/" + K::kNumber.key;
            std::ostringstream range;  // [1, 5]
            range << '[' << K::kNumber.lo << ", " << K::kNumber.hi << ']';
            mat.*K::kNumber.field =
                r.ranged(r.require(m, p, K::kNumber.key), at, K::kNumber.lo, K::kNumber.hi, true,
                         std::string("expected ") + K::kNumber.what + " in " + range.str());
        }
    });
    if (!known)
        r.fail(p + "/type", "unknown material type " + type.dump() + " (expected " + names + ")");
    return mat;
}

// Fills scene.materials and scene.material_names; returns each name's index.
std::map<std::string, int> read_materials(const SceneReader& r, const json& root, Scene& scene) {
    const json& materials = r.require(root, "", "materials");
    if (!materials.is_object() || materials.empty())
        r.fail("/materials",
               "expected an object of named materials, found " + SceneReader::type_of(materials));
    std::map<std::string, int> index;
    for (auto it = materials.begin(); it != materials.end(); ++it) {
        index[it.key()] = static_cast<int>(scene.materials.size());
        scene.materials.push_back(
            read_material(r, it.value(), "/materials/" + pointer_token(it.key())));
        scene.material_names.push_back(it.key());
    }
    return index;
}

// Reads the primitives of a scene file: their lists, vertices and material names.
class PrimitiveReader {
public:
    PrimitiveReader(const SceneReader& r, const json& root, std::map<std::string, int> materials)
        : r_(r), root_(root), materials_(std::move(materials)) {}

    // The array under `key`, or an empty one when the file has none.
    const json& list(const char* key) const {
        static const json empty = json::array();
        if (!root_.contains(key)) return empty;
        const json& v = root_[key];
        if (!v.is_array())
            r_.fail(std::string("/") + key, "expected an array, found " + SceneReader::type_of(v));
        return v;
    }

    int material(const json& obj, const std::string& p) const {
        const json& name = r_.require(obj, p, "material");
        if (!name.is_string())
            r_.fail(p + "/material",
                    "expected a material name, found " + SceneReader::type_of(name));
        const auto found = materials_.find(name.get<std::string>());
        if (found == materials_.end())
            r_.fail(p + "/material",
                    "unknown material " + name.dump() + " (not defined under \"materials\")");
        return found->second;
    }

    std::vector<Vec3> vertices(const json& obj, const std::string& p, size_t count) const {
        WrittenPoint unused;  // read_triangle reads the written vertices itself
        const json& v = r_.require(obj, p, "vertices");
        if (!v.is_array() || v.size() != count)
            r_.fail(p + "/vertices", "expected an array of " + std::to_string(count) +
                                         " points, found " + SceneReader::type_of(v));
        std::vector<Vec3> points;
        for (size_t k = 0; k < count; ++k)
            points.push_back(read_position(r_, v[k], p + "/vertices/" + std::to_string(k), unused));
        return points;
    }

private:
    const SceneReader& r_;
    const json& root_;
    const std::map<std::string, int> materials_;  // material name -> index
};

// The entries of a kind written as fields (file_fields.h): each field read as its role asks,
// the primitive built from the values rounded to `real`, the file's numbers kept for centring.
template <class K>
void read_fields_kind(const SceneReader& r, const PrimitiveReader& prims, Scene& scene) {
    constexpr int kValues = field_values<K>();
    const json& list = prims.list(K::kFileKey);
    std::vector<const char*> keys;
    for (const FileField& field : K::kFields) keys.push_back(field.key);
    keys.push_back("material");
    for (size_t i = 0; i < list.size(); ++i) {
        const std::string p = std::string("/") + K::kFileKey + "/" + std::to_string(i);
        r.check_keys(list[i], p, keys);
        double written[kValues];
        for_each_field<K>([&](const FileField& field, int at) {
            const std::string fp = p + "/" + field.key;
            const json& v = r.require(list[i], p, field.key);
            if (field.role == FieldRole::Point) {
                WrittenPoint point;
                read_position(r, v, fp, point);
                point.store(written + at);
            } else if (field.role == FieldRole::Length) {
                written[at] = r.written_number(v, fp, true);
                if (!(written[at] > 0.0))
                    r.fail(fp, std::string("expected a ") + field.key + " > 0");
            } else {  // a direction, normalised in double
                WrittenPoint d;
                read_position(r, v, fp, d);
                const double length = std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
                if (!(length > 0.0 && std::isfinite(length)))
                    r.fail(fp, "expected a direction (a nonzero, finite vector)");
                WrittenPoint{d.x / length, d.y / length, d.z / length}.store(written + at);
            }
        });
        real values[kValues];
        for (int k = 0; k < kValues; ++k) values[k] = static_cast<real>(written[k]);
        scene.of<K>().push_back(from_fields(KindTag<K>{}, values, prims.material(list[i], p)));
        std::vector<double>& kept = scene.written.fields.of<K>().values;
        kept.insert(kept.end(), written, written + kValues);
    }
}

// Triangles, then quads, each checked as the two triangles v0 v1 v2 and v0 v2 v3
// (classify_quads then makes most of them one primitive).
void read_triangles(const SceneReader& r, const PrimitiveReader& prims, Scene& scene) {
    const json& triangles = prims.list(kTriangleList.key);
    for (size_t i = 0; i < triangles.size(); ++i) {
        const std::string p = std::string("/") + kTriangleList.key + "/" + std::to_string(i);
        r.check_keys(triangles[i], p, {"vertices", "material"});
        const auto v = prims.vertices(triangles[i], p, kTriangleList.vertices);
        scene.of<Triangle>().push_back(
            read_triangle(triangles[i], v, 0, 1, 2, prims.material(triangles[i], p), scene));
    }
    const json& quads = prims.list(kQuadList.key);
    for (size_t i = 0; i < quads.size(); ++i) {
        const std::string p = std::string("/") + kQuadList.key + "/" + std::to_string(i);
        r.check_keys(quads[i], p, {"vertices", "material"});
        const auto v = prims.vertices(quads[i], p, kQuadList.vertices);
        const int m = prims.material(quads[i], p);
        scene.of<Triangle>().push_back(read_triangle(quads[i], v, 0, 1, 2, m, scene));
        scene.of<Triangle>().push_back(read_triangle(quads[i], v, 0, 2, 3, m, scene));
    }
}

void read_render_settings(const SceneReader& r, const json& root, RenderSettings& s) {
    if (!root.contains("render")) return;
    const json& rs = root["render"];
    r.check_keys(rs, "/render", {"width", "height", "spp", "bounces", "seed"});
    const auto read = [&](const char* key, long long lo, long long hi) {
        return r.integer(rs[key], std::string("/render/") + key, lo, hi);
    };
    if (rs.contains("width")) s.width = static_cast<int>(read("width", 1, kMaxImageSide));
    if (rs.contains("height")) s.height = static_cast<int>(read("height", 1, kMaxImageSide));
    if (rs.contains("spp")) s.spp = static_cast<int>(read("spp", 1, kMaxSpp));
    if (rs.contains("bounces")) s.bounces = static_cast<int>(read("bounces", 1, kMaxBounces));
    if (rs.contains("seed")) s.seed = static_cast<uint64_t>(read("seed", 0, kMaxSeed));
}

// What this build's precision cannot place (scene_limits.h) is refused; in the float build, a
// scene the double build places is refused as a PrecisionError, which a reference hands to
// its double build (double_twin.h). Why float cannot place a scene is kept for the double
// build's report.
void check_placement(const SceneReader& r, Scene& scene, size_t file_triangles) {
    const PlacementProblem in_float = !r.float_problem.empty()
                                          ? r.float_problem
                                          : placement_problem(scene, file_triangles, kFloatLimits);
    if (!in_float.empty()) scene.float_refusal = in_float.pointer + ": " + in_float.message;
    if (!build_limits().is_double && in_float.empty()) return;
    const PlacementProblem in_double = placement_problem(scene, file_triangles, kDoubleLimits);
    if (in_double.empty()) {
        if (!build_limits().is_double)
            r.fail_precision(in_float.pointer, in_float.message + "; " + kDoublePlacesIt);
        return;
    }
    // Neither places it: the float build names float's own limit where it has one.
    const PlacementProblem& own =
        build_limits().is_double || !r.float_problem.empty() ? in_double : in_float;
    r.fail(own.pointer, own.message);
}

// An edge as two points, the lesser first: the same key from either side.
using EdgeKey = std::array<real, 6>;
EdgeKey edge_key(Vec3 p, Vec3 q) {
    EdgeKey a{p.x, p.y, p.z, q.x, q.y, q.z}, b{q.x, q.y, q.z, p.x, p.y, p.z};
    return a < b ? a : b;
}

// What each quad of the file becomes (DESIGN.md, section 5), once every check has passed on it
// as two triangles (read_triangles): an axis-aligned rectangle, else one planar convex quad,
// else the two triangles it was read as. The kind is chosen on the points the renderer will
// use, the written ones moved to the scene's centre and rounded once (centre_scene), so the
// same file gives the same kinds wherever it is placed, and centring keeps them.
// A rectangle's test is watertight against rectangles and a convex quad's against quads and
// triangles, each with its own kind of edge function: so a rectangle that shares an edge with
// a triangle or a convex quad (the same two points) becomes a convex quad too, and so on
// along the rectangles that share its edges; no ray then slips between two kinds of test.
void classify_quads(Scene& scene, size_t file_triangles) {
    enum Kind { kRect, kQuad, kTriangles };
    const WrittenPoint centre = centring_centre(scene);
    const size_t count = (scene.of<Triangle>().size() - file_triangles) / 2;
    const std::vector<Triangle> halves(scene.of<Triangle>().begin() + file_triangles,
                                       scene.of<Triangle>().end());
    const std::vector<WrittenPoint> written(
        scene.written.triangle_vertices.begin() + 3 * file_triangles,
        scene.written.triangle_vertices.end());
    std::vector<std::array<Vec3, 4>> rendered(count);
    std::vector<Kind> kind(count);
    std::vector<int> axis(count, -1);
    std::vector<EdgeKey> shared;  // the edges of every triangle and convex quad
    const auto add_edges = [&](const Vec3* v, int n) {
        for (int k = 0; k < n; ++k) shared.push_back(edge_key(v[k], v[(k + 1) % n]));
    };
    for (size_t i = 0; i < file_triangles; ++i) {
        Vec3 v[3];
        for (int k = 0; k < 3; ++k)
            v[k] = moved_to_centre(scene.written.triangle_vertices[3 * i + k], centre);
        add_edges(v, 3);
    }
    for (size_t i = 0; i < count; ++i) {
        const int corner[4] = {0, 1, 2, 5};  // the halves hold v0 v1 v2 and v0 v2 v3
        Vec3 v[4];
        for (int k = 0; k < 4; ++k) v[k] = moved_to_centre(written[6 * i + corner[k]], centre);
        axis[i] = axis_rect_axis(v);
        kind[i] = axis[i] >= 0 ? kRect : (is_planar_convex_quad(v) ? kQuad : kTriangles);
        // Three points on a line as written: two triangles, of which the line is left out,
        // whatever rounding to `real` made of the corner (drop_line_triangles).
        if (on_a_line({written[6 * i], written[6 * i + 1], written[6 * i + 2]}) ||
            on_a_line({written[6 * i + 3], written[6 * i + 4], written[6 * i + 5]}))
            kind[i] = kTriangles;
        rendered[i] = {v[0], v[1], v[2], v[3]};
        if (kind[i] != kRect) add_edges(v, 4);  // two triangles: their outline is the quad's
    }
    std::map<EdgeKey, std::vector<size_t>> rect_edges;
    for (size_t i = 0; i < count; ++i) {
        for (int k = 0; kind[i] == kRect && k < 4; ++k)
            rect_edges[edge_key(rendered[i][k], rendered[i][(k + 1) % 4])].push_back(i);
    }
    while (!shared.empty()) {  // a worklist: each rectangle is demoted once
        const auto found = rect_edges.find(shared.back());
        shared.pop_back();
        if (found == rect_edges.end()) continue;
        for (size_t i : found->second) {
            if (kind[i] != kRect) continue;
            kind[i] = kQuad;
            add_edges(rendered[i].data(), 4);
        }
    }

    scene.of<Triangle>().resize(file_triangles);
    scene.written.triangle_vertices.resize(3 * file_triangles);
    for (size_t i = 0; i < count; ++i) {
        const Triangle& first = halves[2 * i];  // v0 v1 v2; the second is v0 v2 v3
        const Triangle& second = halves[2 * i + 1];
        const Vec3 loaded[4] = {first.v0, first.v1, first.v2, second.v2};
        const WrittenPoint w[4] = {written[6 * i], written[6 * i + 1], written[6 * i + 2],
                                   written[6 * i + 5]};
        if (kind[i] == kRect) {
            scene.of<AxisRect>().push_back(make_axis_rect(loaded, axis[i], first.material));
            scene.written.rect_vertices.insert(scene.written.rect_vertices.end(), w, w + 4);
        } else if (kind[i] == kQuad) {
            scene.of<ConvexQuad>().push_back(
                make_convex_quad(loaded[0], loaded[1], loaded[2], loaded[3], first.material));
            scene.written.quad_vertices.insert(scene.written.quad_vertices.end(), w, w + 4);
        } else {
            scene.of<Triangle>().push_back(first);
            scene.of<Triangle>().push_back(second);
            scene.written.triangle_vertices.insert(scene.written.triangle_vertices.end(),
                                                   written.begin() + 6 * i,
                                                   written.begin() + 6 * i + 6);
        }
    }
}

// The triangles whose written points lie on a line (scene_limits.h, on_a_line), which the
// loader leaves out in every build alike: counts them and names the first as the file writes
// it. A quad with such a half becomes two triangles (classify_quads), so every one of them
// is left out by drop_line_triangles.
void count_line_triangles(Scene& scene, size_t file_triangles) {
    const std::vector<WrittenPoint>& all = scene.written.triangle_vertices;
    for (size_t i = 0; 3 * i < all.size(); ++i) {
        if (!on_a_line({all[3 * i], all[3 * i + 1], all[3 * i + 2]})) continue;
        if (++scene.line_triangles == 1)
            scene.first_line_triangle = i < file_triangles
                                            ? "/triangles/" + std::to_string(i)
                                            : "/quads/" + std::to_string((i - file_triangles) / 2);
    }
}

void drop_line_triangles(Scene& scene) {
    std::vector<Triangle> kept;
    std::vector<WrittenPoint> kept_points;
    const std::vector<WrittenPoint>& all = scene.written.triangle_vertices;
    for (size_t i = 0; i < scene.of<Triangle>().size(); ++i) {
        if (on_a_line({all[3 * i], all[3 * i + 1], all[3 * i + 2]})) continue;
        kept.push_back(scene.of<Triangle>()[i]);
        kept_points.insert(kept_points.end(), all.begin() + 3 * i, all.begin() + 3 * i + 3);
    }
    scene.of<Triangle>() = std::move(kept);
    scene.written.triangle_vertices = std::move(kept_points);
}

}  // namespace

Scene parse_scene(const std::string& text, const std::string& name) {
    const JsonWithPositions parsed = parse_json_with_positions(text, name);
    const json& root = parsed.root;
    const SceneReader r(name, text, parsed.offsets);
    if (!parsed.duplicate_key_pointer.empty())
        r.fail_key(parsed.duplicate_key_pointer, "duplicate key \"" + parsed.duplicate_key + "\"");
    std::vector<const char*> keys = {"camera", "background", "light", "materials"};
    for_each_fields_kind([&](auto kind) { keys.push_back(decltype(kind)::type::kFileKey); });
    keys.insert(keys.end(), {kTriangleList.key, kQuadList.key, "render"});
    r.check_keys(root, "", keys);

    Scene scene;
    scene.name = name;
    scene.written.present = true;
    read_camera(r, root, scene);
    if (root.contains("background"))
        scene.background = r.non_negative_vec3(root["background"], "/background");
    read_light(r, root, scene);
    const PrimitiveReader prims(r, root, read_materials(r, root, scene));
    for_each_fields_kind(
        [&](auto kind) { read_fields_kind<typename decltype(kind)::type>(r, prims, scene); });
    read_triangles(r, prims, scene);
    read_render_settings(r, root, scene.render);
    const size_t file_triangles =
        root.contains(kTriangleList.key) ? root[kTriangleList.key].size() : 0;
    check_placement(r, scene, file_triangles);
    count_line_triangles(scene, file_triangles);
    classify_quads(scene, file_triangles);
    if (scene.line_triangles > 0) drop_line_triangles(scene);
    scene.t_junction_pieces = split_t_junctions(scene);
    return scene;
}

void check_render_limits(Scene& scene, int image_height, int bounces) {
    const PlacementProblem in_float = render_problem(scene, image_height, bounces, kFloatLimits);
    if (!in_float.empty() && scene.float_refusal.empty())
        scene.float_refusal = in_float.pointer + ": " + in_float.message;
    if (!build_limits().is_double && in_float.empty()) return;
    const PlacementProblem in_double = render_problem(scene, image_height, bounces, kDoubleLimits);
    const auto where = [&](const PlacementProblem& p) {
        return scene.name + ": " + p.pointer + ": ";
    };
    if (!in_double.empty()) throw InputError(where(in_double) + in_double.message);
    if (!build_limits().is_double)
        throw PrecisionError(where(in_float) + in_float.message + "; " + kDoublePlacesIt);
}

Scene load_scene(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError(path + ": cannot open scene file: " + std::strerror(errno));
    std::ostringstream ss;
    ss << in.rdbuf();
    if (in.bad()) throw InputError(path + ": cannot read scene file");
    return parse_scene(ss.str(), path);
}
