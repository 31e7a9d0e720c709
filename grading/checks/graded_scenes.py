"""The scenes the checks render that are made in code for a grade: the timed scene (the golden
Cornell box varied by the grading secret) and the sphere interior the closed-form checks see.
The scenes themselves and their closed forms are labkit/scenes.py; what is drawn, and from
which secret, is draws.py; the hidden scene is hidden.py's."""
from __future__ import annotations

import contextlib
import pathlib
import tempfile

from grading.checks import draws
from labkit import scenes

# The timed renders: a variation of the golden 'cornell' scene drawn from the grading secret
# (draws.box_variation: the same cost, nobody's stored image), at the golden size, with enough
# paths that process start-up is a few percent of the time. Its golden data are rendered on the
# spot by the trusted reference where a timed image is compared with them (check_speedup);
# labs 03 and 04 compare their timed images with lab 01's bits instead.
TIMED_SCENE = "cornell"


def drawn_timed_scene() -> dict:
    """The timed scene of this grade: the golden Cornell box varied by the secret."""
    return draws.box_variation(scenes.load(TIMED_SCENE), "timed")


@contextlib.contextmanager
def timed_scene():
    """The drawn timed scene in a temporary file (neutral name, removed after): its path."""
    with tempfile.TemporaryDirectory() as tmp:
        yield scenes.write_scene(pathlib.Path(tmp) / "scene.json", drawn_timed_scene())


# The sphere interior the closed-form checks (analytic.py) and the translation check
# (invariance.py) render: albedo, radius, light intensity.
INTERIOR = dict(albedo=0.6, radius=2.0, intensity=3.0)


def drawn_interior() -> dict:
    """The graded sphere interior's albedo, radius and intensity, drawn from the secret."""
    return dict(albedo=draws.uniform("interior-albedo", 0.3, 0.8),
                radius=draws.uniform("interior-radius", 0.5, 4.0),
                intensity=draws.uniform("interior-intensity", 0.5, 6.0))
