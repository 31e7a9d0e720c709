#include <scene_report.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace {

std::string number(double x) {
    char text[32];
    std::snprintf(text, sizeof text, "%.3g", x);
    return text;
}

std::string plural(int n, const char* one, const char* many) {
    return std::to_string(n) + " " + (n == 1 ? one : many);
}

double longest_edge(const Triangle& t) {
    return std::max({static_cast<double>(length(t.v1 - t.v0)),
                     static_cast<double>(length(t.v2 - t.v1)),
                     static_cast<double>(length(t.v0 - t.v2))});
}

double longest_edge(const ConvexQuad& q) {
    return std::max(
        {static_cast<double>(length(q.v1 - q.v0)), static_cast<double>(length(q.v2 - q.v1)),
         static_cast<double>(length(q.v3 - q.v2)), static_cast<double>(length(q.v0 - q.v3))});
}

double longest_edge(const AxisRect& r) {
    return std::max(double(r.hi_u) - r.lo_u, double(r.hi_v) - r.lo_v);
}

// A primitive's size as a detail (0: it shows nothing): a kind written as fields
// (file_fields.h), its smallest length (a sphere's radius); any other, its longest edge.
template <class K>
double detail_size(const K& primitive) {
    if constexpr (written_as_fields<K>) {
        real values[field_values<K>()];
        fields_of(primitive, values);
        double smallest = INFINITY;
        for_each_field<K>([&](const FileField& field, int at) {
            if (field.role == FieldRole::Length) smallest = std::min(smallest, double(values[at]));
        });
        return std::isfinite(smallest) ? smallest : 0.0;
    } else {
        return longest_edge(primitive);
    }
}

}  // namespace

SceneUse scene_use(const Scene& scene) {
    SceneUse use;
    use.split_pieces = scene.t_junction_pieces;
    use.line_triangles = scene.line_triangles;
    use.first_line_triangle = scene.first_line_triangle;
    for (const Material& m : scene.materials) ++use.materials[static_cast<int>(m.type)];
    use.light = scene.has_light;
    use.background = !is_black(scene.background);
    double smallest = INFINITY;
    for_each_kind(AllPrimitives{}, [&](auto kind) {
        using K = typename decltype(kind)::type;
        use.primitives[kind_index<AllPrimitives, K>] = static_cast<int>(scene.of<K>().size());
        for (const K& p : scene.of<K>()) {
            const double size = detail_size(p);
            if (size > 0) smallest = std::min(smallest, size);  // zero area shows nothing
            use.extent = std::max(use.extent, double(surface_extent(p)));
        }
    });
    use.smallest = std::isfinite(smallest) ? smallest : 0.0;
    return use;
}

std::string describe(const SceneUse& use) {
    std::string materials;
    const auto add = [&](int n, const char* kind) {
        if (n) materials += (materials.empty() ? "" : ", ") + std::to_string(n) + " " + kind;
    };
    for_each_kind(AllMaterials{}, [&](auto kind) {
        using K = typename decltype(kind)::type;
        add(use.materials_of<K>(), K::kName);
    });
    // The kinds the scene has, by count: "1 sphere, 5 rectangles".
    std::string primitives;
    const auto count = [&](int n, const char* one, const char* many) {
        if (n) primitives += (primitives.empty() ? "" : ", ") + plural(n, one, many);
    };
    for_each_kind(AllPrimitives{}, [&](auto kind) {
        using K = typename decltype(kind)::type;
        count(use.primitives_of<K>(), K::kName, (std::string(K::kName) + "s").c_str());
    });
    if (use.split_pieces > 0)
        primitives += " (splitting at T-junctions added " + std::to_string(use.split_pieces) + ")";
    std::string line =
        "scene: " + (primitives.empty() ? std::string("no primitives") : primitives) +
        "; materials: " + (materials.empty() ? "none" : materials) + "; " +
        (use.light ? "a point light" : "no light") + "; " +
        (use.background ? "a background" : "a black background");
    if (use.smallest > 0) {
        line += "; sizes from " + number(use.smallest) + " within coordinates up to " +
                number(use.extent) + " (1 : " + number(use.extent / use.smallest) + ")";
    }
    return line;
}

std::string lines_left_out(const SceneUse& use) {
    if (use.line_triangles == 0) return "";
    return "note: " + plural(use.line_triangles, "triangle", "triangles") +
           " of the file left out, " + (use.line_triangles == 1 ? "its" : "their") +
           " points on a line (no area at any precision; the first: " + use.first_line_triangle +
           ")";
}

std::string to_json(const SceneUse& use) {
    // Each kind's count under its key, and the keys of each family in its list's order (what
    // a scene must hold to use every kind: the hidden scene's test reads them).
    std::string counts, primitive_keys, material_keys;
    const auto add = [&](std::string& keys, const char* key, int n) {
        counts += "\"" + std::string(key) + "\": " + std::to_string(n) + ", ";
        keys += (keys.empty() ? "\"" : ", \"") + std::string(key) + "\"";
    };
    for_each_kind(AllPrimitives{}, [&](auto kind) {
        using K = typename decltype(kind)::type;
        add(primitive_keys, K::kReportKey, use.primitives_of<K>());
    });
    for_each_kind(AllMaterials{}, [&](auto kind) {
        using K = typename decltype(kind)::type;
        add(material_keys, K::kReportKey, use.materials_of<K>());
    });
    return "{" + counts + "\"primitive_kinds\": [" + primitive_keys + "], \"material_kinds\": [" +
           material_keys + "], \"light\": " + (use.light ? "true" : "false") +
           ", \"background\": " + (use.background ? "true" : "false") +
           ", \"smallest\": " + number(use.smallest) + ", \"extent\": " + number(use.extent) +
           ", \"lines_left_out\": " + std::to_string(use.line_triangles) + "}";
}
