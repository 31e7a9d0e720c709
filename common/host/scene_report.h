// What a scene uses, told to the person who renders it: the primitives of each kind (a quad of
// the file counts as a rectangle, a planar convex quad or two triangles: scene_loader.cpp), the
// material kinds, the light, the background, the range of sizes against the scene's extent,
// and the triangles of the file left out because their points lie on a line. A detail too
// small for the scene's reach is no warning here: the loader refuses it where float renders it
// wrong, with a margin (scene_limits.h), and the references render it in double.
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

SceneUse scene_use(const Scene& scene);
std::string describe(const SceneUse& use);  // one line
std::string lines_left_out(const SceneUse& use);  // one line saying so, or ""
std::string to_json(const SceneUse& use);  // an object for --json
