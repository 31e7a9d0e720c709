"""Scenes with a closed form: the sphere interior, millions of samples of it, the lit plane and
the glass pane. How often a correct renderer fails each:
- sphere interior: the estimator has zero variance there (every next-event estimate is the
  same), so only float rounding differs from the closed form: ~1e-5 relative, bound 3e-4.
- millions of samples: the same zero-variance scene at 2^22 and 2^12 spp; a double sum keeps
  the two means equal to float rounding (~1e-7), bound 1e-5; a float sum drifts by ~1e-2.
- lit plane: the only noise is where the pixel jitter lands; at 256 spp the per-pixel error
  is ~1e-3, bounds 3e-3 (mean) and 2e-2 (max) are far outside it.
- glass pane: the mean of 262,144 Bernoulli(~4-5%) paths has a relative standard error of
  ~1%; the 5% bound is five standard errors (two-sided rate ~6e-7) at each of 4 renders."""
from __future__ import annotations

import pathlib
import tempfile

import numpy as np

from grading.checks import draws, symptoms
from grading.checks.check_result import CheckResult, image_checked, worst_of
from grading.checks.graded_scenes import INTERIOR, drawn_interior
from labkit import scenes
from labkit.harness import run_lab


def render_interior(binary, runs: dict, interior: dict = INTERIOR) -> dict:
    """Renders the sphere interior once per entry of `runs` (key -> run_lab settings)."""
    with tempfile.TemporaryDirectory() as tmp:
        path = scenes.write_scene(pathlib.Path(tmp) / "scene.json",
                                  scenes.sphere_interior(**interior))
        return {label: run_lab(binary, path, **how).image for label, how in runs.items()}


def black_pixels(image: np.ndarray) -> str:
    """In a scene lit everywhere (the closed forms below), pixels exactly 0 in every channel
    were never written, or were read back before they were: on a GPU, a copy that did not
    wait for the kernel. Names that symptom, or says nothing."""
    black = int((image == 0).all(axis=2).sum())
    if not black:
        return ""
    why = ("pixels never written, or copied back before the kernel had written them (a "
           "missing synchronisation?)" if symptoms.gpu_lab() else
           "pixels never written (a loop that skips some?)")
    return (f"; {black} of {image.shape[0] * image.shape[1]} pixels are exactly black in a "
            f"scene lit everywhere: {why}")


@image_checked("analytic sphere interior")
def check_sphere_interior(binary, bounces=(1, 2, 4)) -> CheckResult:
    """Closed form: camera and light inside a diffuse sphere (labkit/scenes.py). The
    estimator has zero variance there, so a wrong render is identified, not guessed: the
    closed form of one bounce more or fewer, a factor of pi, a gamma curve
    (symptoms.identified)."""
    worst, symptom = 0.0, ""
    interior = drawn_interior()
    images = render_interior(binary, {b: dict(width=16, height=16, spp=4, bounces=b,
                                              seed=draws.seed("interior"))
                                      for b in bounces}, interior)
    failing: list[int] = []  # the bounce counts rendered wrong
    common: list[str] = []  # the causes that every one of those renders matches
    for b, image in images.items():
        want = scenes.sphere_interior_radiance(**interior, bounces=b)
        error = np.max(np.abs(image.astype(np.float64) / want - 1.0))
        worst = worst_of(worst, error)
        symptom = symptom or black_pixels(image)
        if not (error <= 3e-4):
            causes = symptoms.matching_causes(
                image, lambda k: scenes.sphere_interior_radiance(**interior, bounces=k), b)
            common = causes if not failing else [c for c in common if c in causes]
            failing.append(b)
    ok = worst <= 3e-4
    if len(common) == 1:
        # One cause explains every failing render: identified, it outranks the black pixels.
        symptoms.record(common[0])
        symptom = f"; {common[0]} (identified at bounces {failing})"
    return CheckResult("analytic sphere interior", ok,
                       f"largest relative error {worst:.2e} over bounces {list(bounces)}"
                       f" (allowed 3e-4)" + ("" if ok else symptom))


@image_checked("millions of samples")
def check_million_samples(binary, spp: int = 1 << 22) -> CheckResult:
    """Numerical stability at millions of samples: the sphere interior (zero variance, so
    every sample of a pixel has the same value up to rounding) at 2^22 spp against the same
    render at 2^12 spp, one bounce. A float running sum drifts by ~1% between the two; a sum
    in double keeps them equal to float rounding."""
    few = 1 << 12
    images = render_interior(binary, {n: dict(width=2, height=2, spp=n, bounces=1)
                                      for n in (spp, few)})
    many_image, few_image = images[spp], images[few]
    if not (np.all(few_image > 0) and np.all(np.isfinite(many_image))):
        return CheckResult("millions of samples", False,
                           "the lit sphere interior rendered black or non-finite pixels")
    drift = float(np.max(np.abs(many_image / few_image - 1.0)))
    return CheckResult("millions of samples", drift < 1e-5,
                       f"the mean at {spp} spp differs from the mean at {few} spp by up to "
                       f"{drift:.2e} (allowed 1e-5)")


@image_checked("analytic lit plane")
def check_lit_plane(binary) -> CheckResult:
    """Closed form: a diffuse floor lit by a point light, one bounce, per-pixel integral."""
    w = h = 24
    scene = scenes.lit_plane(albedo=draws.uniform("plane-albedo", 0.3, 0.8),
                             height=draws.uniform("plane-height", 0.5, 2.0),
                             intensity=draws.uniform("plane-intensity", 1.0, 4.0),
                             vfov=draws.uniform("plane-vfov", 60.0, 80.0))
    with tempfile.TemporaryDirectory() as tmp:
        path = scenes.write_scene(pathlib.Path(tmp) / "scene.json", scene)
        image = run_lab(binary, path, width=w, height=h, spp=256, bounces=1,
                        seed=draws.seed("plane")).image
    want = scenes.lit_plane_expected(scene, w, h)
    # The only noise is where the jitter lands inside a pixel: ~0.2% at 256 spp here.
    def right(gray):
        err = np.abs(gray / want - 1.0)
        return float(err.mean()) <= 3e-3 and float(err.max()) <= 2e-2, err
    ok, err = right(image.astype(np.float64).mean(axis=2))
    symptom = ""
    if not ok:
        # The light stands off the axes, so the image has no symmetry: a flipped or transposed
        # image that matches once turned back means the pixels went to the wrong places, not
        # the light to the wrong values (grading/checks/symptoms.py).
        symptom = black_pixels(image) or symptoms.named(image, want, closed_form=True)
    return CheckResult("analytic lit plane", ok,
                       f"relative error mean {err.mean():.2e}, max {err.max():.2e}"
                       f" (allowed 3e-3, 2e-2)" + symptom)


@image_checked("analytic glass pane (Fresnel)")
def check_glass_slab(binary, angles=None, ior: float | None = None) -> CheckResult:
    """Closed form: a glass pane's Fresnel reflectance, head-on and at an oblique angle
    (35-55 degrees, drawn from the grading secret, as is the index of refraction, 1.4-1.7),
    where the reflectance is that of the exact Fresnel equations and the refracted path
    follows Snell's law through the pane and back (labkit/scenes.py, glass_slab)."""
    angles = angles or (0.0, round(draws.uniform("pane-angle", 35.0, 55.0), 3))
    ior = ior or round(draws.uniform("pane-ior", 1.4, 1.7), 4)
    worst, where = 0.0, ""
    with tempfile.TemporaryDirectory() as tmp:
        for angle in angles:
            scene = scenes.glass_slab(ior=ior, albedo=draws.uniform("pane-albedo", 0.6, 0.9),
                                      intensity=draws.uniform("pane-intensity", 2.0, 6.0),
                                      angle_deg=angle)
            path = scenes.write_scene(pathlib.Path(tmp) / "scene.json", scene)
            for b in (2, 4):
                # 32x32 pixels x 256 paths, each reflecting with probability ~4-7%: the mean
                # has a relative standard error of about 1%, so 5% is a five-sigma bound.
                image = run_lab(binary, path, width=32, height=32, spp=256, bounces=b,
                                seed=draws.seed(f"pane-{angle}-{b}")).image
                want = scenes.glass_slab_radiance(scene, b, angle)
                err = abs(float(image.astype(np.float64).mean()) / want - 1.0)
                if not (err <= worst):
                    worst, where = err, f"at {angle:g} degrees, {b} interactions, ior {ior:g}"
    return CheckResult("analytic glass pane (Fresnel)", worst <= 0.05,
                       f"largest relative error of the mean {worst:.2%} {where} (allowed 5%)")
