// T-junctions made shared edges. Each flat primitive's test is watertight against its own kinds
// only across an edge both hold end to end (the same two points, DESIGN.md section 6): where a
// vertex of one primitive lies part-way along another's edge (a floor's corner on a wall's
// bottom edge, two collinear edges that partly overlap), a ray through that line can pass
// between them. The loader therefore splits, once the file's quads are classified, every
// primitive at each vertex of another that lies on its edge strictly between the ends, so
// every overlap of edges becomes edges shared end to end. An edge that runs inside another
// face (a ceiling's edge on a wall that rises past it) first cuts that face along its line,
// so that its ends lie on the cut and the splitting makes it shared end to end too.
#pragma once

#include <scene.h>

// Splits the loaded scene's triangles, convex quads and rectangles where other primitives'
// vertices lie on their edges, and returns how many primitives that added (0: the scene is
// left exactly as it was). Decided on the points the renderer uses (the written ones moved to
// the scene's centre and rounded once, as centre_scene does); a point lies on an edge when it
// is collinear within 8 ulps of its coordinates (exactly, for a rectangle's edge) and strictly
// between the ends. A triangle or convex quad with such points becomes a fan of triangles
// around its centroid (the same front side and material); a rectangle is cut across at each
// point of a triangle's or quad's into smaller rectangles (a rectangle's edge test depends on
// the edge's line only, so points of other rectangles need no cut). A rectangle that then
// shares an edge with a triangle or convex quad becomes a convex quad, as classify_quads does,
// and the search repeats until nothing changes. Each pass first cuts every face that an edge
// no two primitives share crosses inside, at an angle to the edge's own piece, along the
// edge's line (a rectangle only across one of its axes, so its parts stay rectangles). Every
// new point is written in double (Scene::written), so centring moves it as it moves the
// file's own. Finally, an edge that three primitives hold, two of them in one plane (a wall
// cut under a ceiling), is marked on those two (cut_edges, triangle.h's step_off_cut_edge),
// in every scene, split or not.
int split_t_junctions(Scene& scene);
