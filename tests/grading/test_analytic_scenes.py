"""The analytic scenes' closed forms (labkit/scenes.py): the glass pane wound as the core
reads glass, its Fresnel and Snell geometry, and the reference matching it head-on and at an
oblique angle, where an approximate reflectance would not."""
import math

import numpy as np
import pytest

from grading.checks import analytic
from labkit import scenes
from labkit.harness import build


def normal(quad):
    v0, v1, v2 = (np.array(v, dtype=float) for v in quad[:3])
    n = np.cross(v1 - v0, v2 - v0)
    return n / np.linalg.norm(n)


@pytest.mark.parametrize("angle", [0.0, 45.0])
def test_each_pane_face_points_out_of_the_glass(angle):
    """The core takes a glass triangle's medium to lie behind its front face (path_steps.h:
    `entering = dot(incoming, normal) < 0`), so each face's normal must point away from the
    other face."""
    scene = scenes.glass_slab(ior=1.5, albedo=0.8, intensity=4.0, angle_deg=angle)
    panes = [q["vertices"] for q in scene["quads"] if q["material"] == "glass"]
    assert len(panes) == 2
    z = [p[0][2] for p in panes]
    centre = sum(z) / 2
    for quad, face_z in zip(panes, z):
        outward = math.copysign(1.0, face_z - centre)
        assert normal(quad)[2] == pytest.approx(outward), (face_z, normal(quad))


def test_fresnel_known_values():
    assert scenes.fresnel(1.0, 1 / 1.5) == pytest.approx(0.04)
    # 45 degrees into n = 1.5: Rs = 0.0920, Rp = 0.0085.
    assert scenes.fresnel(math.cos(math.radians(45)), 1 / 1.5) == pytest.approx(0.05025, abs=2e-5)
    # Reciprocity: from inside at the refracted angle, the same reflectance.
    sin_t = math.sin(math.radians(45)) / 1.5
    assert scenes.fresnel(math.sqrt(1 - sin_t**2), 1.5) == pytest.approx(0.05025, abs=2e-5)
    assert scenes.fresnel(math.cos(math.radians(60)), 1.5) == 1.0  # beyond the critical angle


def test_oblique_pane_is_told_from_schlick():
    """At 45 degrees Schlick's approximation (0.0421) is 16% below Fresnel's 0.0503: the
    oblique view checks the reflectance, which head-on cannot (both give 0.04 there)."""
    scene = scenes.glass_slab(ior=1.5, albedo=0.8, intensity=4.0, angle_deg=45)
    exact = scenes.glass_slab_radiance(scene, 2, 45)
    schlick = 0.04 + 0.96 * (1 - math.cos(math.radians(45))) ** 5
    assert abs(schlick / scenes.fresnel(math.cos(math.radians(45)), 1 / 1.5) - 1) > 0.1
    assert exact > 0


def test_reference_matches_the_glass_pane_head_on_and_oblique():
    reference, = build("lab01-ref")
    result = analytic.check_glass_slab(reference)
    assert result.passed, result.detail
