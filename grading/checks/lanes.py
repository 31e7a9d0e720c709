"""Lab 02's identified cause of a wrong image: lanes whose bits are not lab 01's, named by the
primitive kind whose test keeps them."""
from __future__ import annotations

import pathlib
import tempfile

import numpy as np

from grading.checks import draws, symptoms
from grading.checks.check_result import LAB01_REFERENCE
from labkit import scenes
from labkit.harness import run_lab


def kind_scenes() -> dict[str, dict]:
    """The Cornell box taken apart, one scene per primitive kind lab 02 tests in lanes, each
    holding that kind alone, so that a mask wrong in one kind's test shows in its scene only:
    the ball (a sphere), the walls as they are (axis-aligned rectangles), the walls turned off
    the axes (planar convex quads) and the walls cut in two (triangles). Every other wall and
    half is written in the opposite order, so that a test that keeps one winding only shows."""
    box = scenes.load("cornell")
    box["quads"] = [dict(q, vertices=q["vertices"][::-1]) if i % 2 else q
                    for i, q in enumerate(box["quads"])]
    ball = dict(box, quads=[])
    walls = {k: v for k, v in box.items() if k != "spheres"}
    turn = 0.3  # radians about the diagonal: no wall stays parallel to an axis
    axis = np.array([1.0, 1.0, 0.0]) / np.sqrt(2.0)
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    rotation = np.eye(3) + np.sin(turn) * k + (1 - np.cos(turn)) * (k @ k)
    halves = [dict(vertices=[q["vertices"][a], q["vertices"][b], q["vertices"][c]],
                   material=q["material"])
              for q in box["quads"] for a, b, c in ((0, 1, 2), (0, 3, 2))]
    triangles = dict({k: v for k, v in walls.items() if k != "quads"}, triangles=halves)
    return {"spheres": ball, "axis-aligned rectangles": walls,
            "convex quads": scenes.transformed(walls, rotation), "triangles": triangles}


def lanes_not_lab01(binary, **how) -> str:
    """Lab 02's identified cause of a wrong image, "" elsewhere or where it does not apply:
    every lane of a packet computes lab 01's path with lab 01's roundings (handout 02), so a
    render whose bits differ from lab01-ref's has lanes whose hit, miss or bounce is not their
    own: a mask. Each kind is rendered alone, so the cause names the kind whose test is wrong.
    Told before the comparison's statistics, whose "too noisy" would otherwise point at a loop
    over paths lab 02 students never write."""
    if not symptoms.packet_lab():
        return ""
    settings = dict(width=24, height=24, spp=4, seed=draws.seed("lanes"))
    differing = []
    for kind, scene in kind_scenes().items():
        with tempfile.TemporaryDirectory() as tmp:
            path = scenes.write_scene(pathlib.Path(tmp) / "scene.json", scene)
            try:
                want = run_lab(LAB01_REFERENCE, path, **settings).image
                image = run_lab(binary, path, **settings, **how).image
            except Exception:  # the check itself reports a crash or a bad image
                return ""
        if image.shape == want.shape and image.tobytes() != want.tobytes():
            pixels = int(np.count_nonzero(np.any(image != want, axis=2)))
            differing.append(f"{kind} ({pixels} of {want.shape[0] * want.shape[1]} pixels)")
    if not differing:
        return ""
    return (f"lanes: a scene of {' and of '.join(differing)} alone is not lab 01's bits, which "
            f"every lane computes exactly: a lane mask in that kind's test keeps a hit, a miss "
            f"or a finished path for lanes it does not belong to (each intersect returns t only "
            f"where the ray crosses the surface in front of t_max and inside it, and a dead "
            f"lane adds nothing)")
