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

}  // namespace

SceneUse scene_use(const Scene& scene) {
    SceneUse use;
    use.spheres = static_cast<int>(scene.spheres.size());
    use.triangles = static_cast<int>(scene.triangles.size());
    use.quads = static_cast<int>(scene.quads.size());
    use.rects = static_cast<int>(scene.rects.size());
    use.split_pieces = scene.t_junction_pieces;
    for (const Material& m : scene.materials) {
        use.diffuse += m.type == material_type<Diffuse>;
        use.mirrors += m.type == material_type<Mirror>;
        use.glass += m.type == material_type<Glass>;
    }
    use.light = scene.has_light;
    use.background = !is_black(scene.background);
    double smallest = INFINITY;
    for (const Sphere& s : scene.spheres) {
        smallest = std::min(smallest, static_cast<double>(s.radius));
        use.extent = std::max(use.extent, static_cast<double>(sphere_extent(s)));
    }
    for (const Triangle& t : scene.triangles) {
        const double edge = longest_edge(t);
        if (edge > 0) smallest = std::min(smallest, edge);  // a zero-area triangle shows nothing
        use.extent = std::max(use.extent, static_cast<double>(t.extent));
    }
    for (const ConvexQuad& q : scene.quads) {
        smallest = std::min(smallest, longest_edge(q));
        use.extent = std::max(use.extent, static_cast<double>(q.extent));
    }
    for (const AxisRect& r : scene.rects) {
        smallest = std::min(smallest, longest_edge(r));
        use.extent = std::max(use.extent, static_cast<double>(r.extent));
    }
    use.smallest = std::isfinite(smallest) ? smallest : 0.0;
    return use;
}

std::string describe(const SceneUse& use) {
    std::string materials;
    const auto add = [&](int n, const char* kind) {
        if (n) materials += (materials.empty() ? "" : ", ") + std::to_string(n) + " " + kind;
    };
    add(use.diffuse, "diffuse");
    add(use.mirrors, "mirror");
    add(use.glass, "glass");
    // The kinds the scene has, by count: "1 sphere, 5 rectangles".
    std::string primitives;
    const auto count = [&](int n, const char* one, const char* many) {
        if (n) primitives += (primitives.empty() ? "" : ", ") + plural(n, one, many);
    };
    count(use.spheres, "sphere", "spheres");
    count(use.triangles, "triangle", "triangles");
    count(use.quads, "convex quad", "convex quads");
    count(use.rects, "rectangle", "rectangles");
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

std::string scale_warning(const SceneUse& use) {
    if (use.smallest <= 0 || use.smallest >= use.extent * kResolvedDetail) return "";
    return "warning: the scene's smallest detail (" + number(use.smallest) + ") is below 1/" +
           number(1.0 / kResolvedDetail) + " of its extent (" + number(use.extent) +
           "): rays that cross the scene leave surfaces by offsets close to that size, so it "
           "will render with visible error; make the detail larger or the scene smaller";
}

std::string to_json(const SceneUse& use) {
    return "{\"spheres\": " + std::to_string(use.spheres) +
           ", \"triangles\": " + std::to_string(use.triangles) +
           ", \"quads\": " + std::to_string(use.quads) +
           ", \"rects\": " + std::to_string(use.rects) +
           ", \"diffuse\": " + std::to_string(use.diffuse) +
           ", \"mirrors\": " + std::to_string(use.mirrors) +
           ", \"glass\": " + std::to_string(use.glass) +
           ", \"light\": " + (use.light ? "true" : "false") +
           ", \"background\": " + (use.background ? "true" : "false") +
           ", \"smallest\": " + number(use.smallest) + ", \"extent\": " + number(use.extent) +
           ", \"warning\": " + (scale_warning(use).empty() ? "false" : "true") + "}";
}
