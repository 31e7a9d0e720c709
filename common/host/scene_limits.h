// What a precision can place: the scene loader's refusals, made on the file's numbers in
// double, once the scene is centred on its geometry (scene_centring.h), for float and for
// double alike. Every scene the loader accepts renders, and nothing in it vanishes silently;
// where a scene sits never matters, only its sizes against each other and the range of the
// type. The bounds, in float (double's follow the same reasoning with double's range and
// spacing):
//  - Coordinates and radii up to 1e9 in magnitude once centred (double: 1e30): the tests
//    multiply two coordinate differences (the edge functions, triangle.h; a sphere's squared
//    lengths), far below FLT_MAX (3.4e38) there. The bound dates from when the triangle's
//    distance multiplied three (it overflowed past ~1e12 and triangles vanished); it keeps
//    that margin.
//  - Sizes (a radius, a triangle's longest edge) from 1e-9 (double: 1e-30): their squares and
//    cubes stay far above FLT_MIN (1.2e-38); a scene of size ~1e-13 underflowed and vanished.
//  - A size at least 4 ray offsets of the primitive's extent (its largest |coordinate| once
//    centred): 2^-18 in float, 2^-47 in double (ray offsets are 8 ulps, kRelativeOffset in
//    ray.h), so such a primitive is at least a few offsets across.
//  - A size at least 128 ray offsets (2^-13 in float, 2^-42 in double) of the scene's reach:
//    its primitives' extent, or the camera's or the light's distance from its centre where
//    larger (the first hit's offset grows with the distance the ray travelled, ray.h). A ray
//    that crossed the scene leaves a surface by an offset of 2^-20 of that distance, so a
//    detail within a few dozen offsets of it is not placed, or not lit, where it is (a small
//    sphere on a large floor, a small scene seen from far away). The limit sits where float
//    was measured right, with a margin (DESIGN.md section 5, docs/precision.md); below it the
//    references render in double, and no warning is left between the limit and that.
//  - A view whose pixels span at least 256 ulps of a unit direction (2^-15 rad in float,
//    2^-44 in double): the camera's rays are rounded to the type, and a narrower view repeats
//    the same ray across neighbouring pixels. Judged with the image's height, once the
//    settings are known (render_problem).
//  - A light whose brightest path stays within the type's range: its intensity times the
//    largest falloff 1/(pi d^2) it gives (d from the light to the nearest primitive's
//    bounding box, at least one ray offset of the scene's reach) times the bounces (each adds
//    at most one light sample), plus the background. The light sample saturates at the
//    type's largest value (path_tracer.h) so no NaN arises, but the pixel would be wrong.
//  - A triangle with an area as written must keep one when its centred vertices are rounded
//    to the type (else its normal is zero and it is never hit).
//  - A triangle whose written points lie on a line, to within the rounding of the file's
//    numbers to double (on_a_line), has no area at any precision: the loader leaves it out in
//    every build and the driver says so in one line; it is judged by no other limit.
//    (Rounded to float, a triangle nearly collinear as written either collapsed, and the
//    references switched to double while lab 02 refused it, or kept a sliver of area with a
//    normal made of rounding; neither is the file's intent.)
#pragma once

#include <string>

#include <scene.h>

struct PrecisionLimits {
    const char* name;             // "float" or "double", as --json says it
    double max_coordinate;        // |coordinate| and radius, once centred
    const char* max_coordinate_text;
    double min_size;              // a radius or a longest edge
    const char* min_size_text;
    double relative_offset;       // ray.h's kRelativeOffset in this type: 8 ulps
    const char* relative_offset_text;
    bool is_double;

    const char* scene_relative_text;  // min_scene_relative_size() as a power of two
    double max_value;                 // the type's largest finite value
    const char* max_value_text;

    double min_relative_size() const { return 4 * relative_offset; }  // to the primitive's extent
    double min_scene_relative_size() const { return 128 * relative_offset; }  // to its reach
    // The least angle one pixel of the view spans, in radians: 256 ulps of a unit direction.
    double min_pixel_angle() const { return 256 * relative_offset / 8; }
};

// The end of a PrecisionError's line: what to do about it.
extern const char* const kDoublePlacesIt;

// Whether a triangle's points, as the file writes them, lie on a line to within the rounding
// of the file's decimals to double: its height over its longest edge is at most 8 ulps of its
// largest |coordinate| (each written coordinate is off by up to half an ulp, which moves the
// height by about 3 ulps; the cross product's own rounding adds about as much).
bool on_a_line(const WrittenPoint (&v)[3]);

extern const PrecisionLimits kFloatLimits;
extern const PrecisionLimits kDoubleLimits;
const PrecisionLimits& build_limits();  // the one this build renders with (real.h)

// The first thing of a scene that `limits` cannot place, with the JSON pointer of the value at
// fault, or an empty problem. `scene` is as parse_scene reads it before it classifies quads:
// the file's triangles (the first `file_triangles`), then the two halves of each quad, every
// point also in scene.written.
struct PlacementProblem {
    std::string pointer;
    std::string message;
    bool empty() const { return message.empty(); }
};
PlacementProblem placement_problem(const Scene& scene, size_t file_triangles,
                                   const PrecisionLimits& limits);

// What `limits` cannot render once the image's settings are known: a view narrower per pixel
// than the type's directions resolve, a light whose brightest path passes the type's range.
// `scene` as loaded (centred or not).
PlacementProblem render_problem(const Scene& scene, int image_height, int bounces,
                                const PrecisionLimits& limits);
