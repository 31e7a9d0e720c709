// What a scene file's primitive lists and material types hold, as the renderer reads them:
// the kinds written as fields (core/file_fields.h), the two lists of vertices declared below
// and the material kinds (core/material.h). `--scene-schema` prints it (cli.cpp), so that
// labkit/scene_schema.py moves and scales scenes, and writes DESIGN.md's table of the scene
// file's keys, from the kinds' own declarations rather than a copy of them.
#pragma once

#include <string>

// A list of primitives written as their vertices. The loader reads a triangle as one Triangle
// and a quad as two, which classify_quads then makes a rectangle, a convex quad or two
// triangles (scene_loader.cpp), so neither list is one kind of AllPrimitives.
struct VertexList {
    const char* key;  // the list's key in a scene file
    int vertices;     // how many points an entry's "vertices" holds
};
constexpr VertexList kTriangleList{"triangles", 3};
constexpr VertexList kQuadList{"quads", 4};

// The schema as one line of JSON, every list in the order the loader reads it:
//   {"primitives": [{"key": "spheres", "fields": [{"key": "center", "role": "point"},
//                                                  {"key": "radius", "role": "length"}]},
//                   {"key": "triangles", "fields": [{"key": "vertices", "role": "points",
//                                                    "count": 3}]}, ...],
//    "materials": [{"type": "diffuse", "fields": [{"key": "albedo", "role": "albedo"}]}, ...,
//                  {"type": "glass", "fields": [{"key": "ior", "role": "number", "min": 1.0,
//                                                "max": 5.0, "what": "an index of refraction"}]}]}
// A role is "point", "length" (> 0) or "direction" (FieldRole), "points" (a list of `count`
// points), "albedo" (RGB, each in [0, 1]) or "number" (in [min, max]). Every primitive entry
// also names its "material", and every material has its "type".
std::string scene_schema_json();
