// What a scene uses, told to the person who renders it: the primitives of each kind (a quad of
// the file counts as a rectangle, a planar convex quad or two triangles: scene_loader.cpp), the material
// kinds, the light, the background, and the range of sizes against the scene's extent; and a
// warning, with what to do, when a detail is smaller than the renderer can resolve at the
// scene's extent. (The loader refuses what cannot render at all: scene_limits.h. This is the
// softer case: every primitive is fine on its own, but rays that cross a large scene leave
// surfaces by offsets that grow with the distance travelled, ray.h, and a detail near the
// size of those offsets is rendered with visible error.)
#pragma once

#include <string>

#include <ray.h>
#include <scene.h>

struct SceneUse {
    int primitives[AllPrimitives::kCount] = {};  // per kind, in the list's order
    int split_pieces = 0;  // of those, how many more the splitting at T-junctions made
    int materials[AllMaterials::kCount] = {};  // the material table's entries by kind
    bool light = false;
    bool background = false;  // a background that is not black
    double smallest = 0;  // the smallest radius or longest edge (0: no primitive)
    double extent = 0;  // the largest |coordinate| of any primitive, after centring
    int line_triangles = 0;  // triangles of the file left out: their points lie on a line
    std::string first_line_triangle;  // where the first is written ("/triangles/3")

    template <class K>
    int primitives_of() const {
        return primitives[kind_index<AllPrimitives, K>];
    }
    template <class K>
    int materials_of() const {
        return materials[kind_index<AllMaterials, K>];
    }
};

// A detail is resolved while it spans at least 16 ray offsets of a ray that crossed the scene
// (offsets are kRelativeOffset of the distance scale, ray.h: 2^-20 in float, 2^-49 in
// double; a crossing ray's is about 4 extents): smallest >= extent * 2^-14 in float.
constexpr double kResolvedDetail = 64.0 * kRelativeOffset;

SceneUse scene_use(const Scene& scene);
std::string describe(const SceneUse& use);  // one line
std::string scale_warning(const SceneUse& use);  // one line with what to do, or ""
std::string lines_left_out(const SceneUse& use);  // one line saying so, or ""
std::string to_json(const SceneUse& use);  // an object for --json
