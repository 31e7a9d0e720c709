// Renders work in coordinates centred on the scene's geometry ("camera-relative rendering" in
// game engines): the loaded scene is moved so the centre of its primitives' bounding box is the
// origin, camera and light with it. The image does not change (every distance and direction
// is the same), but float coordinates near the origin are fine-grained, so a scene far from
// the world origin renders as it would there: rounding and ray offsets scale with the scene,
// not with where it sits. Without this, the Cornell box moved 5000 of its sizes away lost its
// corners (offsets of ~20 float ulps of 5000 reach 1% of the box).
#pragma once

#include <scene.h>

//
// The move is made in double on the points as the file writes them (Scene::written), and
// every moved point is rounded once, after the move: rounding first, then moving, kept each
// point's error of ulp(its distance from the origin), which a scene of size 1 moved 1e4 away
// showed (a look_at 1e-3 from the camera, a lamp 1e-2 above a floor).

// The translation that centre_scene applies: minus the centre of the primitives' bounding
// box, computed in double (and rounded here, for reports); zero for a scene without
// primitives.
Vec3 centring_offset(const Scene& scene);

// That centre in double, unrounded, and a point as centre_scene moves it there: p - centre in
// double, rounded once (the loader classifies quads on the points they will render with).
WrittenPoint centring_centre(const Scene& scene);
Vec3 moved_to_centre(const WrittenPoint& p, const WrittenPoint& centre);

// The scene moved by centring_offset (primitives rebuilt, so normals and extents are the
// moved primitives' own, each of its kind); its written coordinates move with it.
Scene centre_scene(Scene scene);
