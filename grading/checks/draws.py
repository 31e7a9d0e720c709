"""What a grade draws from its secret: the seeds of the timed and tested renders and the
analytic scenes' parameters, so that no image the grader asks for can be rendered at home and
printed. The same secret draws the same values (a regrade with GRADING_SECRET sees the same
renders); without a grade in progress (the labs' own tests) the draws come from a fixed
course secret and stay the same from run to run."""
from __future__ import annotations

import contextlib
import hashlib

COURSE_SECRET = "parallel-ray-tracer-labs"
_secret = [COURSE_SECRET]


@contextlib.contextmanager
def secret(value: str):
    """Every draw inside the block comes from `value`."""
    _secret.append(value)
    try:
        yield
    finally:
        _secret.pop()


def _unit(label: str) -> int:
    digest = hashlib.sha256(f"{_secret[-1]}\0{label}".encode()).digest()
    return int.from_bytes(digest[:8], "little")


def uniform(label: str, low: float, high: float) -> float:
    """A number in [low, high) drawn for `label`."""
    return low + (high - low) * (_unit(label) / 2**64)


def seed(label: str) -> int:
    """A render seed for `label`, in 1..2^31-1 (any value the command line accepts)."""
    return 1 + _unit(label) % (2**31 - 2)


def box_variation(scene: dict, label: str) -> dict:
    """A Cornell-like box (`scene`: camera, point light, diffuse materials, spheres resting on
    the floor y = 0) varied by draws for `label`: the camera moved and turned a little, the
    light moved and its colour and strength changed, every diffuse albedo changed and each
    sphere moved across the floor, resized and given another albedo. What a path costs stays
    as it was (the same primitives and materials, the same bounce count asked), so a timed
    render of the variation takes the time of the scene it varies; its image is nobody's
    stored image."""
    import copy

    s = copy.deepcopy(scene)
    s.pop("render", None)  # the graded renders give every setting on the command line

    def jitter(values, name, spread, low=None, high=None):
        out = [v + uniform(f"{label}-{name}-{i}", -spread, spread) for i, v in enumerate(values)]
        if low is not None:
            out = [min(max(v, low), high) for v in out]
        return out

    cam = s["camera"]
    cam["position"] = jitter(cam["position"], "camera", 0.06)
    cam["look_at"] = jitter(cam["look_at"], "look-at", 0.06)
    cam["vfov"] = cam.get("vfov", 55.0) * uniform(f"{label}-vfov", 0.94, 1.06)
    light = s["light"]
    light["position"] = jitter(light["position"], "light", 0.15, 0.1, 0.95)
    light["intensity"] = [c * uniform(f"{label}-intensity-{i}", 0.6, 1.6)
                          for i, c in enumerate(light["intensity"])]
    for name, material in sorted(s["materials"].items()):
        if material.get("type") == "diffuse":
            material["albedo"] = [min(max(a * uniform(f"{label}-{name}-{i}", 0.7, 1.3), 0.02),
                                      0.9) for i, a in enumerate(material["albedo"])]
    for k, sphere in enumerate(s.get("spheres", [])):
        r = sphere["radius"] * uniform(f"{label}-radius-{k}", 0.85, 1.15)
        x, _, z = sphere["center"]
        sphere["radius"] = r
        sphere["center"] = [min(max(x + uniform(f"{label}-x-{k}", -0.12, 0.12), r), 1 - r), r,
                            min(max(z + uniform(f"{label}-z-{k}", -0.12, 0.12), r - 1), -r)]
    return s
