#include "scene_loader.h"

#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "errors.h"

using nlohmann::json;

namespace {

// One JSON pointer token (RFC 6901): '~' becomes "~0" and '/' becomes "~1".
std::string pointer_token(const std::string& key) {
    std::string out;
    for (char c : key) out += c == '~' ? "~0" : (c == '/' ? "~1" : std::string(1, c));
    return out;
}

// A char iterator that publishes how far the parser has read, so SAX events can be tied to
// a place in the text (nlohmann's SAX interface reports no positions of its own).
struct CountingIterator {
    using iterator_category = std::forward_iterator_tag;
    using value_type = char;
    using difference_type = std::ptrdiff_t;
    using pointer = const char*;
    using reference = const char&;

    const char* p;
    const char* begin;
    size_t* consumed;  // shared with the handler: characters read so far

    reference operator*() const { return *p; }
    CountingIterator& operator++() {
        ++p;
        *consumed = static_cast<size_t>(p - begin);
        return *this;
    }
    CountingIterator operator++(int) {
        CountingIterator old = *this;
        ++*this;
        return old;
    }
    bool operator==(const CountingIterator& o) const { return p == o.p; }
    bool operator!=(const CountingIterator& o) const { return p != o.p; }
};

// Builds the DOM with nlohmann's own SAX-to-DOM parser and records, for every value, the
// offset in the text where it starts, keyed by its JSON pointer.
class PositionRecorder : public nlohmann::json_sax<json> {
public:
    PositionRecorder(json& root, const std::string& text, const size_t* consumed)
        : dom_(root, false), text_(text), consumed_(consumed) {}

    std::map<std::string, size_t> offsets;  // JSON pointer -> offset of the value's first char
    std::string duplicate_key_pointer;      // first key that appeared twice in one object
    std::string duplicate_key;              // that key, unescaped
    size_t error_offset = 0;                // where the syntax error is
    std::string error_message;              // nlohmann's explanation

    bool null() override { return value_done(dom_.null()); }
    bool boolean(bool v) override { return value_done(dom_.boolean(v)); }
    bool number_integer(number_integer_t v) override { return value_done(dom_.number_integer(v)); }
    bool number_unsigned(number_unsigned_t v) override {
        return value_done(dom_.number_unsigned(v));
    }
    bool number_float(number_float_t v, const string_t& s) override {
        return value_done(dom_.number_float(v, s));
    }
    bool string(string_t& v) override { return value_done(dom_.string(v)); }
    bool binary(binary_t& v) override { return value_done(dom_.binary(v)); }

    bool start_object(std::size_t n) override {
        record_start('{');
        frames_.push_back({true, 0, "", {}});
        return dom_.start_object(n);
    }
    bool key(string_t& k) override {
        Frame& f = frames_.back();
        f.key = k;
        if (!f.keys.insert(k).second && duplicate_key_pointer.empty()) {
            duplicate_key_pointer = child_pointer();
            duplicate_key = k;
        }
        offsets[child_pointer() + "#key"] = token_start('"');
        return dom_.key(k);
    }
    bool end_object() override {
        frames_.pop_back();
        return container_done(dom_.end_object());
    }
    bool start_array(std::size_t n) override {
        record_start('[');
        frames_.push_back({false, 0, "", {}});
        return dom_.start_array(n);
    }
    bool end_array() override {
        frames_.pop_back();
        return container_done(dom_.end_array());
    }
    bool parse_error(std::size_t position, const std::string&,
                     const nlohmann::detail::exception& ex) override {
        error_offset = position == 0 ? 0 : position - 1;
        error_message = ex.what();
        // nlohmann points at the last character it read. When a whole token came where it
        // is not allowed ("unexpected string literal"), point at the token's first character;
        // a malformed token ("invalid literal") stays at the character that broke it.
        if (error_message.find("unexpected") != std::string::npos &&
            error_offset < text_.size()) {
            size_t i = error_offset;
            auto in_word = [&](size_t k) {
                return std::isalnum(static_cast<unsigned char>(text_[k])) ||
                       std::strchr("+-.", text_[k]) != nullptr;
            };
            if (text_[i] == '"') {
                while (i > 0 && !(text_[i - 1] == '"' && (i < 2 || text_[i - 2] != '\\'))) --i;
                if (i > 0) --i;
            } else if (in_word(i)) {
                while (i > 0 && in_word(i - 1)) --i;
            }
            error_offset = i;
        }
        return false;
    }

private:
    struct Frame {
        bool is_object;
        size_t index;               // next array index
        std::string key;            // current object key
        std::set<std::string> keys;  // keys seen, to catch duplicates
    };

    std::string pointer() const {
        std::string p;
        for (const std::string& token : path_) p += "/" + token;
        return p;
    }
    std::string child_pointer() const {
        const Frame& f = frames_.back();
        return pointer() + "/" + (f.is_object ? pointer_token(f.key) : std::to_string(f.index));
    }
    // Offset of the token the parser has just finished: scan back from what it has read to
    // the token's first character (the opening quote for strings).
    size_t token_start(char opening_quote_or_zero) const {
        size_t end = std::min(*consumed_, text_.size());
        if (opening_quote_or_zero == '"') {
            size_t i = end;
            while (i > 0 && text_[i - 1] != '"') --i;  // closing quote
            if (i > 0) --i;
            while (i > 0) {
                --i;
                if (text_[i] == '"' && (i == 0 || text_[i - 1] != '\\')) return i;
            }
            return 0;
        }
        size_t i = end;
        while (i > 0 && std::strchr(",]}: \t\r\n", text_[i - 1]) != nullptr) --i;
        while (i > 0 && std::strchr(",[{: \t\r\n", text_[i - 1]) == nullptr) --i;
        return i;
    }
    void record_start(char bracket) {
        size_t i = std::min(*consumed_, text_.size());
        while (i > 0 && text_[i - 1] != bracket) --i;
        offsets[frames_.empty() ? "" : child_pointer()] = i == 0 ? 0 : i - 1;
        if (!frames_.empty()) path_.push_back(current_token());
    }
    std::string current_token() const {
        const Frame& f = frames_.back();
        return f.is_object ? pointer_token(f.key) : std::to_string(f.index);
    }
    bool value_done(bool ok) {
        if (!frames_.empty()) {
            offsets[child_pointer()] = token_start(text_.empty() ? 0 : peek_is_string());
            if (!frames_.back().is_object) ++frames_.back().index;
        }
        return ok;
    }
    char peek_is_string() const {
        size_t i = std::min(*consumed_, text_.size());
        while (i > 0 && std::strchr(",]}: \t\r\n", text_[i - 1]) != nullptr) --i;
        return (i > 0 && text_[i - 1] == '"') ? '"' : 0;
    }
    bool container_done(bool ok) {
        if (!path_.empty()) path_.pop_back();
        if (!frames_.empty() && !frames_.back().is_object) ++frames_.back().index;
        return ok;
    }

    nlohmann::detail::json_sax_dom_parser<json> dom_;
    const std::string& text_;
    const size_t* consumed_;
    std::vector<Frame> frames_;
    std::vector<std::string> path_;  // pointer tokens of the open containers (not the root)
};

// Turns an offset into "line L, column C" (both from 1).
std::string line_column(const std::string& text, size_t offset) {
    size_t line = 1, column = 1;
    for (size_t i = 0; i < offset && i < text.size(); ++i) {
        if (text[i] == '\n') {
            ++line;
            column = 1;
        } else {
            ++column;
        }
    }
    return "line " + std::to_string(line) + ", column " + std::to_string(column);
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
                    std::initializer_list<const char*> allowed) const {
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

    [[noreturn]] void fail_key(const std::string& pointer, const std::string& what) const {
        auto it = offsets_.find(pointer + "#key");
        throw InputError(name_ + ":" +
                         line_column(text_, it == offsets_.end() ? 0 : it->second) + ": " + what);
    }

    const json& require(const json& obj, const std::string& pointer, const char* key) const {
        if (!obj.contains(key)) fail(pointer, std::string("missing required key \"") + key + "\"");
        return obj.at(key);
    }

    float number(const json& v, const std::string& pointer) const {
        if (!v.is_number()) fail(pointer, "expected a number, found " + type_of(v));
        const double d = v.get<double>();
        if (!std::isfinite(d) || std::fabs(d) > 3.0e38)
            fail(pointer, "expected a finite number within float range");
        return static_cast<float>(d);
    }

    Vec3 vec3(const json& v, const std::string& pointer) const {
        if (!v.is_array() || v.size() != 3)
            fail(pointer, "expected an array of 3 numbers, found " + type_of(v));
        return {number(v[0], pointer + "/0"), number(v[1], pointer + "/1"),
                number(v[2], pointer + "/2")};
    }

    Vec3 non_negative_vec3(const json& v, const std::string& pointer) const {
        const Vec3 r = vec3(v, pointer);
        if (r.x < 0 || r.y < 0 || r.z < 0) fail(pointer, "expected components >= 0");
        return r;
    }

    Vec3 albedo(const json& v, const std::string& pointer) const {
        const Vec3 r = non_negative_vec3(v, pointer);
        if (r.x > 1 || r.y > 1 || r.z > 1)
            fail(pointer, "expected an albedo with components in [0, 1] (energy conservation)");
        return r;
    }

    int integer(const json& v, const std::string& pointer, long lo, long hi) const {
        if (!v.is_number_integer())
            fail(pointer, "expected an integer, found " + type_of(v));
        const long long x = v.get<long long>();
        if (x < lo || x > hi)
            fail(pointer, "expected an integer in " + std::to_string(lo) + ".." +
                              std::to_string(hi) + ", found " + v.dump());
        return static_cast<int>(x);
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

}  // namespace

Scene parse_scene(const std::string& text, const std::string& name) {
    size_t consumed = 0;
    json root;
    PositionRecorder recorder(root, text, &consumed);
    CountingIterator first{text.data(), text.data(), &consumed};
    CountingIterator last{text.data() + text.size(), text.data(), &consumed};
    if (!json::sax_parse(first, last, &recorder)) {
        // nlohmann's message reads "[json.exception.parse_error.101] parse error at line L,
        // column C: syntax error while parsing ..."; keep the part after the position.
        std::string why = recorder.error_message;
        const size_t colon = why.find(": ");
        if (colon != std::string::npos) why = why.substr(colon + 2);
        throw InputError(name + ":" + line_column(text, recorder.error_offset) +
                         ": invalid JSON: " + why);
    }
    SceneReader r(name, text, recorder.offsets);
    if (!recorder.duplicate_key_pointer.empty()) {
        const std::string& p = recorder.duplicate_key_pointer;
        r.fail_key(p, "duplicate key \"" + recorder.duplicate_key + "\"");
    }

    Scene scene;
    scene.name = name;
    r.check_keys(root, "", {"camera", "background", "light", "materials", "spheres", "triangles",
                            "quads", "render"});

    const json& cam = r.require(root, "", "camera");
    r.check_keys(cam, "/camera", {"position", "look_at", "up", "vfov"});
    scene.camera.position = r.vec3(r.require(cam, "/camera", "position"), "/camera/position");
    scene.camera.look_at = r.vec3(r.require(cam, "/camera", "look_at"), "/camera/look_at");
    if (cam.contains("up")) scene.camera.up = r.vec3(cam["up"], "/camera/up");
    if (cam.contains("vfov")) {
        scene.camera.vfov_degrees = r.number(cam["vfov"], "/camera/vfov");
        if (!(scene.camera.vfov_degrees > 0.0f && scene.camera.vfov_degrees < 180.0f))
            r.fail("/camera/vfov", "expected a field of view in degrees, in (0, 180)");
    }
    const Vec3 forward = scene.camera.look_at - scene.camera.position;
    if (length_squared(forward) == 0.0f)
        r.fail("/camera/look_at", "expected a point different from the camera position");
    if (length_squared(cross(forward, scene.camera.up)) == 0.0f)
        r.fail("/camera/up", "expected an up vector not parallel to the viewing direction");

    if (root.contains("background"))
        scene.background = r.non_negative_vec3(root["background"], "/background");

    if (root.contains("light")) {
        const json& light = root["light"];
        r.check_keys(light, "/light", {"position", "intensity"});
        scene.has_light = true;
        scene.light.position = r.vec3(r.require(light, "/light", "position"), "/light/position");
        scene.light.intensity =
            r.non_negative_vec3(r.require(light, "/light", "intensity"), "/light/intensity");
    }

    const json& materials = r.require(root, "", "materials");
    if (!materials.is_object() || materials.empty())
        r.fail("/materials", "expected an object of named materials, found " +
                                 SceneReader::type_of(materials));
    std::map<std::string, int> material_index;
    for (auto it = materials.begin(); it != materials.end(); ++it) {
        const std::string p = "/materials/" + pointer_token(it.key());
        const json& m = it.value();
        if (!m.is_object()) r.fail(p, "expected an object, found " + SceneReader::type_of(m));
        const json& type = r.require(m, p, "type");
        Material mat{MaterialType::Diffuse, Vec3(0.0f), 1.0f};
        if (type == "diffuse" || type == "mirror") {
            r.check_keys(m, p, {"type", "albedo"});
            mat.type = type == "diffuse" ? MaterialType::Diffuse : MaterialType::Mirror;
            mat.albedo = r.albedo(r.require(m, p, "albedo"), p + "/albedo");
        } else if (type == "glass") {
            r.check_keys(m, p, {"type", "ior"});
            mat.type = MaterialType::Glass;
            mat.ior = r.number(r.require(m, p, "ior"), p + "/ior");
            if (!(mat.ior >= 1.0f && mat.ior <= 5.0f))
                r.fail(p + "/ior", "expected an index of refraction in [1, 5]");
        } else {
            r.fail(p + "/type", "unknown material type " + type.dump() +
                                    " (expected \"diffuse\", \"mirror\" or \"glass\")");
        }
        material_index[it.key()] = static_cast<int>(scene.materials.size());
        scene.materials.push_back(mat);
        scene.material_names.push_back(it.key());
    }

    auto material_of = [&](const json& obj, const std::string& p) {
        const json& name_value = r.require(obj, p, "material");
        if (!name_value.is_string())
            r.fail(p + "/material", "expected a material name, found " +
                                        SceneReader::type_of(name_value));
        const auto found = material_index.find(name_value.get<std::string>());
        if (found == material_index.end())
            r.fail(p + "/material", "unknown material " + name_value.dump() +
                                        " (not defined under \"materials\")");
        return found->second;
    };
    auto list = [&](const char* key) -> const json& {
        static const json empty = json::array();
        if (!root.contains(key)) return empty;
        const json& v = root[key];
        if (!v.is_array())
            r.fail(std::string("/") + key, "expected an array, found " + SceneReader::type_of(v));
        return v;
    };

    const json& spheres = list("spheres");
    for (size_t i = 0; i < spheres.size(); ++i) {
        const std::string p = "/spheres/" + std::to_string(i);
        r.check_keys(spheres[i], p, {"center", "radius", "material"});
        Sphere s{};
        s.center = r.vec3(r.require(spheres[i], p, "center"), p + "/center");
        s.radius = r.number(r.require(spheres[i], p, "radius"), p + "/radius");
        if (!(s.radius > 0.0f)) r.fail(p + "/radius", "expected a radius > 0");
        s.material = material_of(spheres[i], p);
        scene.spheres.push_back(s);
    }

    auto vertices = [&](const json& obj, const std::string& p, size_t count) {
        const json& v = r.require(obj, p, "vertices");
        if (!v.is_array() || v.size() != count)
            r.fail(p + "/vertices", "expected an array of " + std::to_string(count) +
                                        " points, found " + SceneReader::type_of(v));
        std::vector<Vec3> points;
        for (size_t k = 0; k < count; ++k)
            points.push_back(r.vec3(v[k], p + "/vertices/" + std::to_string(k)));
        return points;
    };
    const json& triangles = list("triangles");
    for (size_t i = 0; i < triangles.size(); ++i) {
        const std::string p = "/triangles/" + std::to_string(i);
        r.check_keys(triangles[i], p, {"vertices", "material"});
        const auto v = vertices(triangles[i], p, 3);
        scene.triangles.push_back(make_triangle(v[0], v[1], v[2], material_of(triangles[i], p)));
    }
    const json& quads = list("quads");
    for (size_t i = 0; i < quads.size(); ++i) {
        const std::string p = "/quads/" + std::to_string(i);
        r.check_keys(quads[i], p, {"vertices", "material"});
        const auto v = vertices(quads[i], p, 4);
        const int m = material_of(quads[i], p);
        scene.triangles.push_back(make_triangle(v[0], v[1], v[2], m));
        scene.triangles.push_back(make_triangle(v[0], v[2], v[3], m));
    }

    if (root.contains("render")) {
        const json& rs = root["render"];
        r.check_keys(rs, "/render", {"width", "height", "spp", "bounces", "seed"});
        if (rs.contains("width")) scene.render.width = r.integer(rs["width"], "/render/width", 1, kMaxImageSide);
        if (rs.contains("height")) scene.render.height = r.integer(rs["height"], "/render/height", 1, kMaxImageSide);
        if (rs.contains("spp")) scene.render.spp = r.integer(rs["spp"], "/render/spp", 1, kMaxSpp);
        if (rs.contains("bounces")) scene.render.bounces = r.integer(rs["bounces"], "/render/bounces", 1, kMaxBounces);
        if (rs.contains("seed")) scene.render.seed = static_cast<uint64_t>(r.integer(rs["seed"], "/render/seed", 0, 2147483647));
    }
    return scene;
}

Scene load_scene(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError(path + ": cannot open scene file: " + std::strerror(errno));
    std::ostringstream ss;
    ss << in.rdbuf();
    if (in.bad()) throw InputError(path + ": cannot read scene file");
    return parse_scene(ss.str(), path);
}
