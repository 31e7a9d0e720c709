"""Correctness checks of a lab binary, shared by the pytest suites, the mutation tests and the
grader. Each returns a CheckResult: whether it passed and a line saying what it saw.

How often a correct renderer fails each check (its false-failure rate), and why:
- golden images: at most alpha = 1e-4 per comparison, by the Bonferroni bound over every
  block and global z-test (grading/compare.py explains the model and its assumptions).
- sphere interior: the estimator has zero variance there (every next-event estimate is the
  same), so only float rounding differs from the closed form: ~1e-5 relative, bound 3e-4.
- millions of samples: the same zero-variance scene at 2^22 and 2^12 spp; a double sum keeps
  the two means equal to float rounding (~1e-7), bound 1e-5; a float sum drifts by ~1e-2.
- lit plane: the only noise is where the pixel jitter lands; at 256 spp the per-pixel error
  is ~1e-3, bounds 3e-3 (mean) and 2e-2 (max) are far outside it.
- glass pane: the mean of 262,144 Bernoulli(~4%) paths has a relative standard error of
  ~1%; the 5% bound is five standard errors (two-sided rate ~6e-7).
- scale invariance: the scaled and unscaled renders use the same random numbers, so they
  differ only where rounding sends a path another way: measured 0.00% for the reference.
A renderer whose float roundings differ (SIMD, GPU) is another random draw of the same
estimator, so these rates apply to it too. Which bugs each check catches is shown by
tests/labs/test_lab01_mutants.py.
"""
from __future__ import annotations

import dataclasses
import pathlib
import tempfile

import numpy as np

from grading import scenes
from grading.compare import compare
from grading.harness import golden, run_lab


@dataclasses.dataclass
class CheckResult:
    name: str
    passed: bool
    detail: str

    def __str__(self) -> str:
        return f"{'PASS' if self.passed else 'FAIL'} {self.name}: {self.detail}"


# Test renders are small and quick; the golden comparison knows their noise level exactly.
GOLDEN_TEST_SPP = 64


def check_golden(binary, scene: str, *, seed: int = 7, spp: int = GOLDEN_TEST_SPP,
                 heatmap_dir: pathlib.Path | None = None, launcher=(), threads=None,
                 extra=()) -> CheckResult:
    """Noise-aware comparison with the converged golden image (grading/compare.py)."""
    g = golden(scene)
    run = run_lab(binary, g.scene, width=g.meta["width"], height=g.meta["height"], spp=spp,
                  bounces=g.meta["bounces"], seed=seed, launcher=launcher, threads=threads,
                  extra=extra)
    heatmap = heatmap_dir / f"{scene}-diff.png" if heatmap_dir else None
    report = compare(run.image, spp, g.mean, g.variance, g.meta["golden_spp"],
                     heatmap_path=heatmap)
    return CheckResult(f"golden image '{scene}'", report.passed, report.summary())


# The sphere interior both checks below render: albedo, radius, light intensity.
INTERIOR = dict(albedo=0.6, radius=2.0, intensity=3.0)


def render_interior(binary, runs: dict) -> dict:
    """Renders the sphere interior once per entry of `runs` (key -> run_lab settings)."""
    with tempfile.TemporaryDirectory() as tmp:
        path = scenes.write_scene(pathlib.Path(tmp) / "interior.json",
                                  scenes.sphere_interior(**INTERIOR))
        return {label: run_lab(binary, path, **how).image for label, how in runs.items()}


def check_sphere_interior(binary, bounces=(1, 2, 4)) -> CheckResult:
    """Closed form: camera and light inside a diffuse sphere (grading/scenes.py)."""
    worst = 0.0
    images = render_interior(binary, {b: dict(width=16, height=16, spp=4, bounces=b)
                                      for b in bounces})
    for b, image in images.items():
        want = scenes.sphere_interior_radiance(**INTERIOR, bounces=b)
        worst = max(worst, float(np.max(np.abs(image / want - 1.0))))
    ok = worst < 3e-4
    return CheckResult("analytic sphere interior", ok,
                       f"largest relative error {worst:.2e} over bounces {list(bounces)}"
                       f" (allowed 3e-4)")


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


def check_lit_plane(binary) -> CheckResult:
    """Closed form: a diffuse floor lit by a point light, one bounce, per-pixel integral."""
    w = h = 24
    scene = scenes.lit_plane(albedo=0.5, height=1.0, intensity=2.0, vfov=70)
    with tempfile.TemporaryDirectory() as tmp:
        path = scenes.write_scene(pathlib.Path(tmp) / "plane.json", scene)
        image = run_lab(binary, path, width=w, height=h, spp=256, bounces=1).image
    want = scenes.lit_plane_expected(scene, w, h)
    err = np.abs(image.mean(axis=2) / want - 1.0)
    # The only noise is where the jitter lands inside a pixel: ~0.2% at 256 spp here.
    ok = float(err.mean()) < 3e-3 and float(err.max()) < 2e-2
    return CheckResult("analytic lit plane", ok,
                       f"relative error mean {err.mean():.2e}, max {err.max():.2e}"
                       f" (allowed 3e-3, 2e-2)")


def check_glass_slab(binary) -> CheckResult:
    """Closed form: Fresnel reflectance of a glass pane at normal incidence."""
    scene = scenes.glass_slab(ior=1.5, albedo=0.8, intensity=4.0)
    worst = 0.0
    with tempfile.TemporaryDirectory() as tmp:
        path = scenes.write_scene(pathlib.Path(tmp) / "slab.json", scene)
        for b in (2, 4):
            # 32x32 pixels x 256 paths, each reflecting with probability ~4%: the mean has a
            # relative standard error of about 1%, so 5% is a five-sigma bound.
            image = run_lab(binary, path, width=32, height=32, spp=256, bounces=b, seed=5).image
            want = scenes.glass_slab_radiance(scene, b)
            worst = max(worst, abs(float(image.mean()) / want - 1.0))
    return CheckResult("analytic glass pane (Fresnel)", worst < 0.05,
                       f"largest relative error of the mean {worst:.2%} (allowed 5%)")


SCALE_FACTORS = (1e-4, 1e-2, 1e3, 1e5)


def check_scale_invariance(binary, scene: str = "cornell", factors=SCALE_FACTORS) -> CheckResult:
    """A scene scaled by any factor from 1e-4 to 1e5 (intensity by the factor squared)
    renders the same: same seed, so the same random numbers and almost the same paths."""
    base_scene = scenes.load(scene)
    w = h = 48
    worst = (-1.0, -1.0, factors[0])
    with tempfile.TemporaryDirectory() as tmp:
        def render(s, name):
            path = scenes.write_scene(pathlib.Path(tmp) / name, s)
            return run_lab(binary, path, width=w, height=h, spp=16, bounces=4, seed=3).image
        base = render(base_scene, "base.json")
        for f in factors:
            img = render(scenes.scaled(base_scene, f), f"scaled-{f:g}.json")
            mean_err = abs(float(img.mean()) / float(base.mean()) - 1.0)
            rel = np.abs(img - base) / (np.abs(base) + 1e-3)
            bad_fraction = float((rel > 0.05).mean())
            if (mean_err, bad_fraction) > worst[:2]:
                worst = (mean_err, bad_fraction, f)
    mean_err, bad_fraction, factor = worst
    ok = mean_err < 0.01 and bad_fraction < 0.02
    return CheckResult("scale invariance 1e-4..1e5", ok,
                       f"worst factor {factor:g}: image mean off by {mean_err:.2%}, "
                       f"{bad_fraction:.2%} of pixel values off by > 5% (allowed 1%, 2%)")


def check_reproducible(binary, **kwargs) -> CheckResult:
    """Same seed, same bits; another seed, another image."""
    args = dict(width=32, height=32, spp=8, **kwargs)
    a = run_lab(binary, seed=11, **args).image
    b = run_lab(binary, seed=11, **args).image
    c = run_lab(binary, seed=12, **args).image
    same = a.tobytes() == b.tobytes()
    differs = a.tobytes() != c.tobytes()
    return CheckResult("reproducible", same and differs,
                       f"same seed identical: {same}; new seed changes image: {differs}")


def check_speedup(binary, baseline, min_speedup: float, *, threads=None, launcher=(),
                  repeat: int = 3) -> CheckResult:
    """Render time against a baseline binary (the lab-01 reference), interleaved in one run,
    best of `repeat`: a ratio, so a busy machine slows both sides alike."""
    from grading.harness import interleaved_speedup, render_seconds
    scene = dict(width=120, height=120, spp=32, bounces=4, seed=1)
    speedup, base, fast = interleaved_speedup(
        lambda: render_seconds(baseline, **scene),
        lambda: render_seconds(binary, threads=threads, launcher=launcher, **scene), n=repeat)
    return CheckResult(f"speedup >= {min_speedup:g}x", speedup >= min_speedup,
                       f"{speedup:.2f}x ({base:.3f} s -> {fast:.3f} s, best of {repeat})")


def check_parallel_speedup(binary, baseline, *, threads=None, launcher=(),
                           fraction: float = 0.75) -> CheckResult:
    """Speedup of a parallel lab over the serial baseline, against the machine's capacity
    measured alongside (grading.harness.measure_parallel)."""
    from grading.harness import measure_parallel, render_seconds
    scene = dict(width=256, height=256, spp=32, seed=1)
    timing = measure_parallel(
        lambda: render_seconds(baseline, **scene),
        {"yours": lambda: render_seconds(binary, threads=threads, launcher=launcher, **scene)})
    if timing.capacity < 1.5:
        return CheckResult("parallel speedup", False,
                           f"not measurable: the machine gave only {timing.capacity:.2f} cores' "
                           f"worth of throughput; run again when it is less busy")
    return CheckResult("parallel speedup", timing.speedup("yours") >= timing.required(fraction),
                       timing.describe("yours"))


def check_bitwise_equal(binary, baseline, *, runs=None) -> CheckResult:
    """The image is the baseline's, bit for bit, for every way of running it (thread counts,
    rank counts): what a counter-based RNG and a race-free parallel loop guarantee. `runs`
    maps a label to run_lab keyword arguments; default: 1, 2, 3 and 7 threads."""
    runs = runs or {f"{t} threads": {"threads": t} for t in (1, 2, 3, 7)}
    settings = dict(width=48, height=40, spp=8, seed=3)
    want = run_lab(baseline, **settings).image.tobytes()
    differing = [label for label, how in runs.items()
                 if run_lab(binary, **settings, **how).image.tobytes() != want]
    return CheckResult("bit-identical to lab 01", not differing,
                       "identical for " + ", ".join(runs) if not differing
                       else "differs for " + ", ".join(differing))


def mpirun(ranks: int) -> list[str]:
    """The launcher for MPI labs; -q keeps mpirun's banners out of stderr."""
    return ["mpirun", "-q", "--oversubscribe", "--bind-to", "none", "-np", str(ranks)]


def correctness_checks(binary) -> list[CheckResult]:
    """Every check a lab's rendering must pass, in the order a student should read them."""
    return [
        check_sphere_interior(binary),
        check_lit_plane(binary),
        check_glass_slab(binary),
        check_golden(binary, "cornell"),
        check_golden(binary, "showcase"),
        check_scale_invariance(binary),
        check_reproducible(binary),
    ]
