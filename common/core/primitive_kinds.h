// The primitive kinds: declared here once, as one list. Its order is the order in which the
// closest-hit and shadow loops visit the kinds (path_tracer.h) and so the order in which equal
// distances are decided; a kind's position numbers it in a Hit and a packed hit. The scene's
// arrays, their upload, the sets a renderer is compiled for and the report's counters follow
// the list (DESIGN.md §6, "Only what the scene uses").
#pragma once

#include <axis_rect.h>
#include <convex_quad.h>
#include <kinds.h>
#include <sphere.h>
#include <triangle.h>

using AllPrimitives = Kinds<Sphere, Triangle, ConvexQuad, AxisRect>;
