// The primitive kinds: declared here once, as one list. Its order is the order in which the
// closest-hit and shadow loops visit the kinds (path_steps.h) and so the order in which equal
// distances are decided; a kind's position numbers it in a Hit and a packed hit. The scene's
// arrays, their upload, the sets a renderer is compiled for and the report's counters follow
// the list (DESIGN.md §6, "Only what the scene uses").
//
// A kind is a struct with a `material` index and
//   kName, kReportKey  what the scene report calls one, and its --json key;
//   kShearsRay         whether its test takes the ray's RayShear (triangle.h), which the loops
//                      build once per ray for every kind that does;
// and these functions of it (its hooks), which the loops of path_steps.h call by kind (with
// the shear after the ray where kShearsRay, as `intersect(ray, shear, k, t_max)`):
//   intersect<kConverged>(ray, k, t_max)  the distance in (0, t_max), else t_max;
//   occludes<kConverged>(ray, k, t_max)   whether it lies on the ray before t_max;
//   normal_at(k, p)        the unit geometric normal at the hit point p (outward, or front);
//   surface_extent(k)      its largest |coordinate|: what a hit's rounding error grows with;
//   step_off_edges(k, p, margin)  a specular path's step off its edges (zero without edges);
//   step_off_edges(k, p, margin, direction)  the same given the arriving ray's direction, for
//                          kinds with cut edges (triangle.h); the template below for the others.
#pragma once

#include <axis_rect.h>
#include <convex_quad.h>
#include <file_fields.h>
#include <kinds.h>
#include <sphere.h>
#include <triangle.h>

using AllPrimitives = Kinds<Sphere, Triangle, ConvexQuad, AxisRect>;

// A kind without cut edges (triangle.h's step_off_cut_edge) steps off its edges whatever the
// arriving ray's direction.
template <class K>
RT_HD inline Vec3 step_off_edges(const K& item, Vec3 p, real margin, Vec3) {
    return step_off_edges(item, p, margin);
}

// Calls f(KindTag<K>{}) for every kind of AllPrimitives written as fields (file_fields.h), in
// the list's order (host code: the loader, centring, limits).
template <class F>
void for_each_fields_kind(F&& f) {
    for_each_kind(AllPrimitives{}, [&](auto kind) {
        if constexpr (written_as_fields<typename decltype(kind)::type>) f(kind);
    });
}
