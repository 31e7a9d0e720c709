"""The scenes `make tradeoff` renders besides the Cornell baseline.

- extreme: tiny next to huge. A diffuse floor of half-size 1e5 (labkit/scenes.py floor_view,
  the one check_large_primitives uses) with a ball of radius 0.25 on it, seen from 1 unit
  above. Hit points on the floor carry the rounding of coordinates 1e5 away (~6e-3), so a
  fixed world-space epsilon far below that lets shadow rays hit the floor they leave, while
  the ball needs offsets far smaller than the floor's: the case where the ray-offset strategy
  matters. Moving a scene far from the origin tests nothing here: the shared driver renders
  every scene centred on its geometry (DESIGN.md section 6).
- bias: the inside of a diffuse sphere lit from off-centre (tools/tradeoff/bias.py has its
  closed form).
"""
from __future__ import annotations

import pathlib

from labkit import scenes

ROOT = pathlib.Path(__file__).resolve().parents[2]

EXTREME_FLOOR_HALF_SIZE = 1e5
EXTREME_BALL = dict(center=[-0.4, 0.25, -2.5], radius=0.25)


def extreme() -> dict:
    scene = scenes.floor_view(EXTREME_FLOOR_HALF_SIZE)
    scene["materials"]["ball"] = {"type": "diffuse", "albedo": [0.7, 0.3, 0.2]}
    scene["spheres"] = [{**EXTREME_BALL, "material": "ball"}]
    return scene


# The sphere interior of the bias sweep: albedo, radius, intensity, and a light well off the
# centre (0.54 R), so that wall points see very different direct light and the indirect
# bounces are a real Monte Carlo estimate (with the light at the centre, as in
# grading/checks/analytic.py, every path returns the same value and there is nothing to estimate).
INTERIOR = dict(albedo=0.8, radius=2.0, intensity=3.0, light=(0.8, 0.6, 0.4))


def off_centre_interior(albedo: float, radius: float, intensity: float, light) -> dict:
    scene = scenes.sphere_interior(albedo=albedo, radius=radius, intensity=intensity)
    scene["light"]["position"] = list(light)
    return scene


def write(folder: pathlib.Path, name: str, scene: dict) -> pathlib.Path:
    folder.mkdir(parents=True, exist_ok=True)
    return scenes.write_scene(folder / f"{name}.json", scene)
