"""Correctness checks of a lab binary, shared by the pytest suites, the mutation tests and the
grader. Each returns a CheckResult: whether it passed and a line saying what it saw.

How often a correct renderer fails each check (its false-failure rate), and why:
- golden images: at most alpha = 1e-4 per comparison, by the Bonferroni bound over every
  block and global z-test (labkit/compare.py explains the model and its assumptions).
- sphere interior: the estimator has zero variance there (every next-event estimate is the
  same), so only float rounding differs from the closed form: ~1e-5 relative, bound 3e-4.
- millions of samples: the same zero-variance scene at 2^22 and 2^12 spp; a double sum keeps
  the two means equal to float rounding (~1e-7), bound 1e-5; a float sum drifts by ~1e-2.
- lit plane: the only noise is where the pixel jitter lands; at 256 spp the per-pixel error
  is ~1e-3, bounds 3e-3 (mean) and 2e-2 (max) are far outside it.
- glass pane: the mean of 262,144 Bernoulli(~4-5%) paths has a relative standard error of
  ~1%; the 5% bound is five standard errors (two-sided rate ~6e-7) at each of 4 renders.
- scale invariance: the scaled and unscaled renders use the same random numbers, so they
  differ only where rounding sends a path another way: measured 0.00% for the reference.
A renderer whose float roundings differ (SIMD, GPU) is another random draw of the same
estimator, so these rates apply to it too. Which bugs each check catches is shown by
tests/labs/test_lab01_mutants.py.
"""
from __future__ import annotations

import contextlib
import dataclasses
import functools
import os
import pathlib
import re
import tempfile
import time

import numpy as np

from grading import draws, hidden, report_html, symptoms
from labkit import scenes
from labkit.compare import GRADING_ALPHA, compare
from labkit.harness import GOLDEN, ROOT, ImageError, golden, rerun_command, run_lab

# The trusted renderer that makes golden data on the spot (the timed scene drawn for a grade).
LAB01_REFERENCE = ROOT / "lab01-ref"


@dataclasses.dataclass
class CheckResult:
    name: str
    passed: bool
    detail: str
    # The machine could not measure this (too busy, even after retries): marked for a
    # regrade. Its points stay out of the score; `provisional` (a fraction of the points) is
    # what the regrade may add, shown apart.
    regrade: bool = False
    # A timed check's fraction of its points (speed_credit); None: all or nothing by `passed`.
    credit: float | None = None
    provisional: float = 0.0

    def __str__(self) -> str:
        return f"{'PASS' if self.passed else 'FAIL'} {self.name}: {self.detail}"


def worst_of(*values: float) -> float:
    """The largest of `values`, NaN if any is NaN: `max(0.0, nan)` is 0.0, which would read
    a NaN error as no error. Compare its result as `not (worst <= bound)`."""
    values = [float(v) for v in values]
    return float("nan") if any(v != v for v in values) else max(values)


def image_checked(name: str):
    """A check whose renders raise ImageError (no image, wrong size, NaN/Inf pixels) fails
    with that message instead of raising: a NaN makes every comparison false, so no check may
    look at such an image, and the mutation tests still get a CheckResult from each check."""
    def wrap(check):
        @functools.wraps(check)
        def checked(*args, **kwargs) -> CheckResult:
            try:
                return check(*args, **kwargs)
            except ImageError as e:
                return CheckResult(name, False, str(e))
        return checked
    return wrap


# Test renders are small and quick; the golden comparison knows their noise level exactly.
GOLDEN_TEST_SPP = 64


@image_checked("golden image")
def check_golden(binary, scene: str, *, seed: int | None = None, spp: int = GOLDEN_TEST_SPP,
                 heatmap_dir: pathlib.Path | None = None, launcher=(), threads=None,
                 extra=()) -> CheckResult:
    """Noise-aware comparison with the converged golden image (labkit/compare.py), rendered
    at a seed drawn from the grading secret (grading/draws.py)."""
    g = golden(scene)
    seed = draws.seed(f"golden-{scene}") if seed is None else seed
    run = run_lab(binary, g.scene, width=g.meta["width"], height=g.meta["height"], spp=spp,
                  bounces=g.meta["bounces"], seed=seed, launcher=launcher, threads=threads,
                  extra=extra)
    copied = stored_golden_copied(run.image)
    if copied:
        return CheckResult(f"golden image '{scene}'", False,
                           f"the image is the stored golden image '{copied}' itself, bit for "
                           f"bit: a copy, not a render (a render at {spp} spp is noisy)")
    heatmap = heatmap_dir / f"{scene}-diff.png" if heatmap_dir else None
    report = compare(run.image, spp, g.mean, g.variance, g.meta["golden_spp"],
                     heatmap_path=heatmap, alpha=GRADING_ALPHA, pooled_variance=True)
    if heatmap_dir and run.image is not None:  # for the page (grading/report_html.py)
        report_html.write_images(heatmap_dir, scene, run.image, g.mean)
    hint = "" if report.passed else symptoms.named(run.image, g.mean)
    cause = "" if report.passed else lanes_not_lab01(binary, launcher=launcher, threads=threads)
    again = "" if report.passed else "; rerun: " + rerun_command(
        binary, g.scene, launcher, ["--scene", str(g.scene),
                                    *(["--threads", str(threads)] if threads else []),
                                    "--width", str(g.meta["width"]), "--height",
                                    str(g.meta["height"]), "--spp", str(spp), "--bounces",
                                    str(g.meta["bounces"]), "--seed", str(seed), *extra,
                                    "--pfm", "out.pfm"])
    return CheckResult(f"golden image '{scene}'", report.passed,
                       (f"{cause}; " if cause else "") + report.summary() + hint + again)


def lanes_not_lab01(binary, **how) -> str:
    """Lab 02's identified cause of a wrong image, "" elsewhere or where it does not apply:
    every lane of a packet computes lab 01's path with lab 01's roundings (handout 02), so a
    render whose bits differ from lab01-ref's on the public scene has lanes whose hit, miss
    or bounce is not their own: a mask. Told before the comparison's statistics, whose "too
    noisy" would otherwise point at a loop over paths lab 02 students never write."""
    if symptoms.current_lab() != "02":
        return ""
    settings = dict(width=32, height=32, spp=8, seed=draws.seed("lanes"))
    try:
        want = run_lab(LAB01_REFERENCE, **settings).image
        image = run_lab(binary, **settings, **how).image
    except Exception:  # the check itself reports a crash or a bad image
        return ""
    if image.shape != want.shape or image.tobytes() == want.tobytes():
        return ""
    pixels = int(np.count_nonzero(np.any(image != want, axis=2)))
    return (f"lanes: {pixels} of {want.shape[0] * want.shape[1]} pixels of the Cornell box "
            f"are not lab 01's bits, which every lane computes exactly: a lane mask keeps a "
            f"hit, a miss or a finished path for lanes it does not belong to (each intersect "
            f"returns t only where the ray crosses the surface in front of t_max and inside "
            f"it; a dead lane adds nothing)")


def stored_golden_copied(image: np.ndarray) -> str | None:
    """The name of a stored golden image (reference/golden/) that `image` is, bit for bit, or
    None. The golden images are public (they ship with the course), so a submission could
    carry one and print it; no render at a test's spp matches a converged image exactly."""
    for folder in sorted(p for p in GOLDEN.iterdir() if p.is_dir()):
        stored = golden(folder.name).mean
        if stored.shape == image.shape and np.array_equal(stored, image):
            return folder.name
    return None


# The sphere interior both checks below render: albedo, radius, light intensity.
INTERIOR = dict(albedo=0.6, radius=2.0, intensity=3.0)


def drawn_interior() -> dict:
    """The graded sphere interior's albedo, radius and intensity, drawn from the secret."""
    return dict(albedo=draws.uniform("interior-albedo", 0.3, 0.8),
                radius=draws.uniform("interior-radius", 0.5, 4.0),
                intensity=draws.uniform("interior-intensity", 0.5, 6.0))


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
        # the light to the wrong values (grading/symptoms.py).
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


SCALE_FACTORS = (1e-4, 1e-2, 1e3, 1e5)


@image_checked("scale invariance 1e-4..1e5")
def check_scale_invariance(binary, scene: str = "cornell", factors=SCALE_FACTORS) -> CheckResult:
    """A scene scaled by any factor from 1e-4 to 1e5 (intensity by the factor squared)
    renders the same: same seed, so the same random numbers and almost the same paths."""
    base_scene = scenes.load(scene)
    w = h = 48
    worst = (-1.0, -1.0, factors[0])
    with tempfile.TemporaryDirectory() as tmp:
        def render(s, name):
            path = scenes.write_scene(pathlib.Path(tmp) / name, s)
            return run_lab(binary, path, width=w, height=h, spp=16, bounces=4,
                           seed=draws.seed("scale")).image
        base = render(base_scene, "a.json")
        for f in factors:
            img = render(scenes.scaled(base_scene, f), f"b{factors.index(f)}.json")
            ours, plain = img.astype(np.float64), base.astype(np.float64)
            mean_err = abs(float(ours.mean()) / float(plain.mean()) - 1.0)
            rel = np.abs(ours - plain) / (np.abs(plain) + 1e-3)
            bad_fraction = float((~(rel <= 0.05)).mean())
            if not ((mean_err, bad_fraction) <= worst[:2]):  # a NaN counts as the worst
                worst = (mean_err, bad_fraction, f)
    mean_err, bad_fraction, factor = worst
    ok = mean_err <= 0.01 and bad_fraction <= 0.02
    return CheckResult("scale invariance 1e-4..1e5", ok,
                       f"worst factor {factor:g}: image mean off by {mean_err:.2%}, "
                       f"{bad_fraction:.2%} of pixel values off by > 5% (allowed 1%, 2%)")


@image_checked("reproducible")
def check_reproducible(binary, **kwargs) -> CheckResult:
    """Same seed, same bits; another seed, another image (of the drawn timed scene)."""
    seed = draws.seed("reproducible")
    with timed_scene() as scene:
        args = dict(scene=scene, width=32, height=32, spp=8, **kwargs)
        a = run_lab(binary, seed=seed, **args).image
        b = run_lab(binary, seed=seed, **args).image
        c = run_lab(binary, seed=seed + 1, **args).image
    same = a.tobytes() == b.tobytes()
    differs = a.tobytes() != c.tobytes()
    return CheckResult("reproducible", same and differs,
                       f"same seed identical: {same}; new seed changes image: {differs}")


def check_structure_of_arrays(binary) -> CheckResult:
    """Lab 07's lesson, which speed cannot grade: on the H200 lab 06's array of structures is
    within 10% of the structure of arrays (handouts/07-soa.md). The binary reports where its
    path pool puts the same field of two neighbouring queued paths (a probe that stores two
    paths with the submission's own code and searches the memory: common/wavefront/
    layout_probe.cuh); a structure of arrays puts them one 4-byte word apart."""
    json = run_lab(binary, width=4, height=4, spp=1).json or {}
    layout = json.get("layout") if isinstance(json.get("layout"), dict) else {}
    apart = layout.get("bytes_between_neighbours")
    if not isinstance(apart, int) or isinstance(apart, bool):
        return CheckResult("structure of arrays", False,
                           "the program does not report its pool's layout (--json has no layout)")
    if apart < 0:
        return CheckResult("structure of arrays", False,
                           "a queued path stored at places 0 and 1 was not found in the pool's "
                           "memory: the pool does not store what it is given")
    verdict = "a structure of arrays" if apart == 4 else "want 4: one array per field"
    return CheckResult("structure of arrays", apart == 4,
                       f"the same field of neighbouring paths lies {apart} bytes apart "
                       f"({verdict})")


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


def timed_settings(spp: int, scene: pathlib.Path, scale: int = 1) -> dict:
    """The timed render of `scene` (timed_scene()) at `scale` times the golden image's width
    and height, at a seed drawn from the secret."""
    g = golden(TIMED_SCENE)
    return dict(scene=scene, width=g.meta["width"] * scale, height=g.meta["height"] * scale,
                bounces=g.meta["bounces"], seed=draws.seed("timed"), spp=spp)


def timed_golden(scene: pathlib.Path, reference=LAB01_REFERENCE) -> tuple:
    """(mean, variance, golden_spp) of the drawn timed scene, rendered now by the trusted
    reference at the golden size (grading/hidden.py's make_golden)."""
    g = golden(TIMED_SCENE)
    made = hidden.make_golden(reference, scene, size=g.meta["width"], bounces=g.meta["bounces"])
    return made.mean, made.variance, made.golden_spp


def box_filtered(image: np.ndarray, scale: int) -> np.ndarray:
    """Each scale x scale block of pixels averaged into one pixel. A pixel's paths jitter
    uniformly over its area, so the average of a block rendered at n spp is an estimate of the
    large pixel's value from scale^2 n paths, stratified over its area: its variance is at most
    that of scale^2 n unstratified paths, and the golden comparison at that spp stays valid
    (conservative)."""
    h, w, c = image.shape
    blocks = image.reshape(h // scale, scale, w // scale, scale, c).astype(np.float64)
    return blocks.mean(axis=(1, 3)).astype(np.float32)


def wrong_timed_image(image, spp: int, scale: int = 1, reference: tuple | None = None
                      ) -> str | None:
    """Why a timed render is not a correct image of its scene, or None: speed is graded only
    for correct work, on the very runs that were timed. `reference` is the scene's (mean,
    variance, golden_spp) (timed_golden); by default the stored golden Cornell box's."""
    if reference is None:
        g = golden(TIMED_SCENE)
        reference = (g.mean, g.variance, g.meta["golden_spp"])
    report = compare(box_filtered(image, scale) if scale > 1 else image, spp * scale * scale,
                     *reference, per_pixel=scale == 1)
    return None if report.passed else f"the timed render is wrong ({report.summary()})"


# Speed earns partial credit: full points at or above the bar, falling linearly to none at
# ZERO_CREDIT_AT times the bar (grading/README.md). For a parallel lab on two cores (bar
# 1.46x) that is 1.10x, where a serial program is; the CPU-time evidence below stops a serial
# program from earning anything by noise.
ZERO_CREDIT_AT = 0.75


def speed_credit(measured: float, bar: float) -> float:
    """The fraction of a speed check's points for `measured` against `bar` (NaN earns 0)."""
    floor = ZERO_CREDIT_AT * bar
    if not (measured > floor):
        return 0.0
    return min(1.0, (measured - floor) / (bar - floor))


def credit_note(credit: float, bar: float) -> str:
    if credit >= 1.0:
        return ""
    return (f"; {credit:.0%} of the points (full at {bar:.2f}x, none at or below "
            f"{ZERO_CREDIT_AT * bar:.2f}x)")


def cores_used(run) -> float:
    """CPU time over wall time of a run's whole process tree, both measured by the grader."""
    if run.cpu_seconds is None or not run.wall_seconds > 0:
        return float("nan")
    return run.cpu_seconds / run.wall_seconds


def one_cpu() -> int:
    """The CPU lab 02's timed runs are confined to (its lesson is SIMD, not threads). The
    sandbox refuses widening the affinity again (sandbox.Limits.cpu), so threads share that
    CPU and earn nothing; their CPU time is not judged (a serial hand-in whose wrapper script
    does some of the work would look threaded by it)."""
    return min(os.sched_getaffinity(0))


# A program whose tree never used more CPU time than this many times its wall time did not
# run in parallel (a serial renderer measures 0.95-1.0 cores on a quiet machine; a correct
# parallel one on two cores ~1.9, ~1.3 beside a process burning one of them). On a machine
# others load, every thread gets a share of a core: there the parallel check compares the
# cores a program used with those the serial reference used in the same round.
SERIAL_CORES = 1.1


# The reference runs twice a round, before and after the program, and the speedup is over
# the best of all its runs: a load that slowed only some of them does not make the program
# look faster. How far its two series' bests lie apart (at least 1) says how much a ratio
# measured then may be off; where the credit differs between the speedup divided and
# multiplied by that, the rounds are measured again, up to `attempts` times, and failing
# that the lower credit counts and the rest is left to a regrade (grading/README.md has the
# measurement that called for it).


@image_checked("speedup")
def check_speedup(binary, baseline, min_speedup: float, *, threads=None, launcher=(),
                  repeat: int = 3, spp: int = 256, scale: int = 1, attempts: int = 3,
                  overhead_reference=None, one_core: bool = False) -> CheckResult:
    """Wall-clock time against a baseline binary (the lab-01 reference; a GPU lab's own
    reference), measured by the grader around each whole process (never the `seconds` a
    program reports about itself), interleaved, best of `repeat` rounds, the reference before
    and after the program in each: a ratio, so a busy machine slows both sides alike, and a
    ratio the reference's own two series disagree about is measured again or left to a
    regrade (see above). Every timed image must match the golden image, or there is no
    speed to grade. `scale` renders the golden view that many times larger (checked box-
    filtered down to the golden size); `overhead_reference` (a trusted binary) measures a
    start-up cost, rendering one pixel, that is subtracted from both sides (launch_overhead).
    `one_core` (lab 02): both sides run confined to one CPU, which they cannot widen (threads
    are not the lesson: they share that CPU and gain nothing). Both sides render the timed
    scene drawn for this grade (timed_scene), whose golden data the trusted lab-01 reference
    renders first. Points: speed_credit of the speedup."""
    name = f"speedup >= {min_speedup:g}x"
    pinned = one_cpu() if one_core else None
    overhead = launch_overhead(overhead_reference, launcher) if overhead_reference else 0.0
    note = (f", less {overhead:.3f} s of start-up measured on the reference rendering one pixel"
            if overhead else "")
    where = ", both on one CPU" if one_core else ""
    with timed_scene() as scene:
        settings = timed_settings(spp, scene, scale)
        reference = timed_golden(scene)

        def reference_run() -> float:
            run = run_lab(baseline, cpu=pinned, **settings)
            return max(run.wall_seconds - overhead, 1e-3)

        for attempt in range(1, attempts + 1):
            before, after, fast = [], [], []
            for _ in range(repeat):
                before.append(reference_run())
                run = run_lab(binary, threads=threads, launcher=launcher, cpu=pinned,
                              **settings)
                wrong = wrong_timed_image(run.image, spp, scale, reference)
                if wrong:
                    return CheckResult(name, False,
                                       f"{wrong}: speed is graded only for a correct image",
                                       credit=0.0)
                fast.append(max(run.wall_seconds - overhead, 1e-3))
                after.append(reference_run())
            base = min(before + after)
            speedup = base / min(fast)
            unsteady = max(min(before), min(after)) / base
            low = speed_credit(speedup / unsteady, min_speedup)
            high = speed_credit(speedup * unsteady, min_speedup)
            if low == high:
                break
            if attempt < attempts:
                time.sleep(2.0 * attempt)  # let the other load pass
    detail = (f"{speedup:.2f}x ({base:.3f} s -> {min(fast):.3f} s wall clock measured by the "
              f"grader{note}{where}, best of {repeat} rounds, the reference twice a round)")
    if low != high:
        return CheckResult(name, low > 0,
                           f"{detail}: the reference's best before and after the program lay "
                           f"{unsteady - 1:.1%} apart, too unsteady to tell {low:.0%} of the "
                           f"points from {high:.0%} in {attempts} attempts; {low:.0%} now, the "
                           f"rest marked for regrade", regrade=True, credit=low,
                           provisional=1.0 - low)
    return CheckResult(name, low > 0, detail + credit_note(low, min_speedup), credit=low)


def launch_overhead(reference, launcher, rounds: int = 3) -> float:
    """Seconds a launcher (mpirun) and MPI start-up add to a run, measured on a trusted
    reference binary rendering one pixel: subtracted from the candidate's wall-clock time so
    that a fixed start-up of ~0.5 s does not hide a parallel speedup."""
    return min(run_lab(reference, width=1, height=1, spp=1, launcher=launcher).wall_seconds
               for _ in range(rounds))


# On a machine giving fewer than BUSY cores' worth of throughput (a quiet two-core machine
# gives 1.9-2.0) a missed bar may be the machine's fault: under bursts of other load the
# reference measured 0.95x with 1.79x capacity measured in the same rounds, and ~1x under a
# steady load of 9 on two cores. Such a result is measured again and, failing that, marked
# for regrade, with only the points measured in the score. Whether the program runs in
# parallel at all is told apart from the load two ways. Thread by thread, at any load: a
# program one of whose threads did ONE_THREAD of its timed runs' CPU time is serial (a
# serial renderer's one thread does all of it; a parallel one's busiest thread about 1/T of
# it, however few cores it got). By CPU time over wall time: where the machine gave at least
# SERIAL_TELLABLE cores' worth, a parallel program uses more than SERIAL_CORES of them (CFS
# shares the CPUs by thread), a serial one cannot.
BUSY = 1.9
SERIAL_TELLABLE = 1.25
QUOTA_TOO_SMALL = 1.5  # cores' worth of CPU (count or cgroup quota) below which nothing is timed
ONE_THREAD = 0.9
# A speedup this many times the capacity measured in the same rounds is impossible: a
# program cannot get more from the cores than n copies of the serial reference do, beyond
# noise and a faster serial path. One that does read something it had kept (its own first
# render, another run's image) or slowed the reference: refused, never scored.
IMPOSSIBLE = 1.5


def busiest_thread_share(run) -> float:
    """The fraction of a run's CPU time that its busiest thread did (both measured by the
    grader from /proc, sandbox.TreeClock); NaN where nothing was measured."""
    return run.thread_share


def one_thread_did_it(shares: list[float]) -> bool:
    """Every timed run did at least ONE_THREAD of its work on one thread (none unmeasured)."""
    return bool(shares) and all(share >= ONE_THREAD for share in shares)


def serial_by_thread(shares: list[float], where: str, timed: str = "") -> CheckResult:
    """The verdict on a program whose one thread did the work; `timed`: what the timed runs
    measured, where they ran (the class page shows those numbers beside the verdict)."""
    return CheckResult("parallel speedup", False,
                       f"serial: in every timed run one thread did at least {ONE_THREAD:.0%} "
                       f"of the CPU time ({min(shares):.0%} at the least; measured by the "
                       f"grader, thread by thread, {where}); a parallel program shares its work "
                       f"among its threads" + (f" (timed: {timed})" if timed else ""),
                       credit=0.0)


@image_checked("parallel speedup")
def check_parallel_speedup(binary, baseline, *, threads=None, launcher=(),
                           fraction: float = 0.75, spp: int = 512, attempts: int = 3,
                           overhead_reference=None) -> CheckResult:
    """Speedup of a parallel lab over the serial baseline, in wall-clock time measured by the
    grader, against the machine's capacity measured alongside (labkit.harness.
    measure_parallel), on the timed scene drawn for this grade (timed_scene). Every timed
    image must be the baseline's, bit for bit (what labs 03 and 04 promise). It fails closed:
    - a program one of whose threads did ONE_THREAD of every timed run's CPU time is serial,
      at any load and capacity (even where nothing is timed): no points, not a regrade;
    - so is a program whose timed runs never used more than SERIAL_CORES cores' worth of CPU
      time (the grader's own measurement of the sandboxed tree) nor more than SERIAL_CORES
      times the serial reference's share in the same rounds, on a machine giving at least
      SERIAL_TELLABLE;
    - points follow speed_credit of the speedup against the bar; where the machine stays too
      busy to reach a verdict, the test is marked for regrade and only the points measured
      count: the rest is shown apart, never in the score."""
    with timed_scene() as scene:
        return _parallel_speedup(binary, baseline, timed_settings(spp, scene), threads=threads,
                                 launcher=launcher, fraction=fraction, attempts=attempts,
                                 overhead_reference=overhead_reference)


def _parallel_speedup(binary, baseline, settings: dict, *, threads, launcher, fraction: float,
                      attempts: int, overhead_reference) -> CheckResult:
    import threading

    from labkit.harness import cpu_capacity, measure_parallel
    capacity_here = cpu_capacity()
    if capacity_here < QUOTA_TOO_SMALL:
        # Nothing to time: no program can show a speedup here. One run shows whether the work
        # is one thread's (serial: final here too); else correctness is graded (the checks
        # gated on this one open) and the speed left to a regrade on a course machine.
        try:
            run = run_lab(binary, threads=threads, launcher=launcher, check=False, **settings)
        except OSError:  # the binary cannot even be staged: nothing to tell
            run = None
        # Only a run that rendered tells whose work a render is (a crash is one thread's too).
        shares = [busiest_thread_share(run)] if run and run.image is not None else []
        if one_thread_did_it(shares):
            return serial_by_thread(shares, f"on a machine giving {capacity_here:g} cores' worth")
        return CheckResult("parallel speedup", True,
                           f"not timed: this machine gives {capacity_here:g} cores' worth of CPU "
                           f"time (CPU count, cgroup cpu.max), too few to show a parallel "
                           f"speedup; correctness graded, speed marked for regrade on a machine "
                           f"with 2 or more", regrade=True, credit=0.0, provisional=1.0)
    want: list[bytes] = []
    wrong: list[str] = []
    used: list[float] = []       # cores' worth of CPU time of each of your timed runs
    shares: list[float] = []     # the share of each of your timed runs' busiest thread
    base_used: list[float] = []  # the same of the serial reference run alone, same rounds
    overhead = launch_overhead(overhead_reference, launcher) if overhead_reference else 0.0

    def base() -> float:
        run = run_lab(baseline, **settings)
        if not want:
            want.append(run.image.tobytes())
        if threading.current_thread() is threading.main_thread():  # alone, not the capacity's
            base_used.append(cores_used(run))
        return run.wall_seconds

    def yours() -> float:
        run = run_lab(binary, threads=threads, launcher=launcher, **settings)
        if want and run.image.tobytes() != want[0] and not wrong:
            wrong.append("the timed render differs from the serial reference's image (the bit "
                         "check says why)")
        used.append(cores_used(run))
        shares.append(busiest_thread_share(run))
        return max(run.wall_seconds - overhead, 1e-3)

    def copies(n: int) -> float:
        """n copies of the baseline at once as one process tree (one session, as a parallel
        program is: measure_parallel says why)."""
        run = run_lab(baseline, launcher=together_launcher(n), check=False, **settings)
        return run.wall_seconds

    def share() -> float:
        """Cores your runs used over the cores the serial reference used in the same rounds
        (the median over rounds): ~1 for a serial program whatever the load, NaN unknown."""
        ratios = sorted(y / b for y, b in zip(used, base_used) if b > 0)
        return ratios[len(ratios) // 2] if ratios else float("nan")

    def parallel() -> bool:
        """Shown to run on more than one core: a run used more than SERIAL_CORES cores' worth
        of CPU time (one thread cannot use more than one core, whatever the load), or the runs
        got more than SERIAL_CORES times the serial reference's share of a busy machine."""
        return max(used, default=0.0) > SERIAL_CORES or share() > SERIAL_CORES

    def threaded() -> bool:
        """Evidence enough to grade correctness while the speed waits for a regrade: shown
        parallel, or the work shared among threads (which a busy machine may have run on one
        core's worth; a regrade on a quiet machine tells)."""
        return parallel() or (bool(shares) and max(shares) < ONE_THREAD)

    note = f" (launch overhead {overhead:.3f} s subtracted)" if overhead else ""
    best = None  # (credit, timing) of the attempt closest to the bar
    capacity = 0.0
    for attempt in range(1, attempts + 1):
        timing = measure_parallel(base, {"yours": yours}, together=copies)
        capacity = max(capacity, timing.capacity)
        if wrong:
            return CheckResult("parallel speedup", False,
                               f"{wrong[0]}: speed is graded only for a correct image", credit=0.0)
        if timing.speedup("yours") > IMPOSSIBLE * timing.capacity:
            return CheckResult("parallel speedup", False,
                               f"impossible: {timing.describe('yours')}; more than "
                               f"{IMPOSSIBLE:g} times the capacity no program can get from the "
                               f"machine, so not a speedup: refused, no points", credit=0.0)
        if one_thread_did_it(shares):
            return serial_by_thread(shares, f"{max(used):.2f} cores' worth at most, on a "
                                            f"machine giving {capacity:.2f}",
                                    f"{timing.describe('yours')}{note}")
        if not parallel() and capacity >= SERIAL_TELLABLE:
            return CheckResult("parallel speedup", False,
                               f"serial: the timed runs used at most {max(used):.2f} cores' "
                               f"worth of CPU time, {share():.2f}x the serial reference's share "
                               f"(measured by the grader), on a machine giving {capacity:.2f} "
                               f"cores' worth; a parallel program uses more than "
                               f"{SERIAL_CORES:g} ({timing.describe('yours')}{note})", credit=0.0)
        if timing.capacity >= 1.5:
            credit = speed_credit(timing.speedup("yours"), timing.required(fraction))
            if best is None or credit > best[0]:
                best = (credit, timing)
            if credit >= 1 or timing.capacity >= BUSY:
                break  # reached the bar, or measured on a machine quiet enough to judge
        if attempt < attempts:
            time.sleep(2.0 * attempt)  # let the other load pass
    if best is None:
        return CheckResult("parallel speedup", threaded(),
                           f"not measurable: the machine gave only {capacity:.2f} cores' worth "
                           f"of throughput in {attempts} attempts (the timed runs used "
                           f"{share():.2f}x the serial reference's CPU share, their busiest "
                           f"thread {max(shares, default=float('nan')):.0%} of their CPU time); "
                           f"no points now, marked for regrade",
                           regrade=True, credit=0.0, provisional=1.0)
    credit, timing = best
    bar = timing.required(fraction)
    detail = timing.describe("yours") + note + credit_note(credit, bar)
    if credit < 1 and timing.capacity < BUSY:
        return CheckResult("parallel speedup", credit > 0 or threaded(),
                           f"short of the bar on a machine too busy to judge ({detail}); "
                           f"marked for regrade", regrade=True, credit=credit,
                           provisional=1.0 - credit)
    return CheckResult("parallel speedup", credit > 0, detail, credit=credit)


def together_launcher(n: int) -> list[str]:
    """A launcher running its command n times at once and waiting for all of them."""
    return ["/bin/sh", "-c", f'i=0; while [ $i -lt {n} ]; do "$@" & i=$((i + 1)); done; wait',
            "copies"]


@image_checked("bit-identical to lab 01")
def check_bitwise_equal(binary, baseline, *, runs=None) -> CheckResult:
    """The image is the baseline's, bit for bit, for every way of running it (thread counts,
    rank counts), on the timed scene drawn for this grade: what a counter-based RNG and a
    race-free parallel loop guarantee. `runs`
    maps a label to run_lab keyword arguments; default: 1, 2, 3 and 7 threads. On a mismatch
    it says which of the two causes it is (why_different)."""
    runs = runs or {f"{t} threads": {"threads": t} for t in (1, 2, 3, 7)}
    with timed_scene() as scene:  # the scene drawn for this grade: nobody's stored image
        settings = dict(scene=scene, width=48, height=40, spp=8, seed=draws.seed("bitwise"))
        want = run_lab(baseline, **settings).image
        images = {label: run_lab(binary, **settings, **how).image for label, how in runs.items()}
        differing = [label for label, image in images.items()
                     if image.tobytes() != want.tobytes()]
        if not differing:
            return CheckResult("bit-identical to lab 01", True,
                               "identical for " + ", ".join(runs))
        return CheckResult("bit-identical to lab 01", False,
                           f"differs for {', '.join(differing)}; "
                           + why_different(binary, settings, runs, images, differing, want))


def row_ranges(rows: list[int]) -> str:
    """[0, 1, 2, 7, 9, 10] -> "0-2, 7, 9-10"."""
    spans: list[list[int]] = []
    for r in rows:
        if spans and r == spans[-1][1] + 1:
            spans[-1][1] = r
        else:
            spans.append([r, r])
    return ", ".join(f"{a}-{b}" if b > a else f"{a}" for a, b in spans)


def rows_differing(a: np.ndarray, b: np.ndarray) -> list[int]:
    return [int(y) for y in np.nonzero(np.any((a != b).reshape(a.shape[0], -1), axis=1))[0]]


def why_different(binary, settings: dict, runs: dict, images: dict, differing: list[str],
                  want: np.ndarray | None = None) -> str:
    """Tells the causes of other bits apart. Identified first: rows exactly black where lab
    01's image (`want`) is not, rows never rendered or never gathered (lab 04's skeleton),
    which would otherwise read as a work split below. Then, by rendering twice more each way
    that differed, the most threads or ranks first: renders that change from run to run at one
    count (a data race, a generator shared by threads), or the same image every time that
    depends on the count (random numbers drawn by thread, rank or chunk instead of by pixel:
    how the work is split). A race need not show in every run, so every differing count is
    tried before an image is called deterministic."""
    if want is not None:
        for label in differing:
            black = symptoms.black_rows(images[label], want)
            if black:
                return f"at {label}, {black}"
    for label in reversed(differing):
        first = images[label]
        again = [run_lab(binary, **settings, **runs[label]).image for _ in range(2)]
        rows = sorted({y for image in again for y in rows_differing(first, image)})
        if rows:
            return (f"nondeterministic: a data race or shared generator: renders at {label} "
                    f"differ from each other in {len(rows)} of {first.shape[0]} rows (rows "
                    f"{row_ranges(rows)}); each pixel's random numbers must depend on the "
                    f"pixel alone, and each pixel be written by one thread")
    same = [label for label in runs if label not in differing]
    if not same:  # even the first way (1 thread, 1 rank) is not lab 01's image
        return (f"deterministic but different from lab 01 even at {differing[0]}: the same "
                f"image run after run at each count, but not lab 01's: are the random numbers "
                f"drawn by pixel and sample as lab 01 draws them?")
    return (f"deterministic but different: work split: the same image run after run at each "
            f"count, but {', '.join(differing)} give other bits than lab 01 ({', '.join(same)} "
            f"match): the random numbers depend on how the rows are split (drawn by thread, "
            f"rank or chunk, not by pixel?)")


def mpirun(ranks: int, distribution: str | None = None, *env: str) -> list[str]:
    """The launcher for MPI labs, RT_MPI_DISTRIBUTION set for every rank when `distribution`
    is given and each NAME=VALUE of `env` too (the sandbox passes none of the grader's
    environment on). Not -q: it would hide OpenMPI's own error text (MPI_ERR_TRUNCATE, a
    rank that died), the cause a student needs; a run that succeeds prints no banner."""
    cmd = ["mpirun", "--oversubscribe", "--bind-to", "none", "-np", str(ranks)]
    for setting in ([f"RT_MPI_DISTRIBUTION={distribution}"] if distribution else []) + list(env):
        cmd += ["-x", setting]
    return cmd


DISTRIBUTIONS = ("block", "interleaved", "dynamic")


def report_rows(stderr: str) -> dict[int, set[int]]:
    """RT_MPI_REPORT's lines ("rank 1: ... : rows 1,4,7-9"): {rank: the rows it rendered}."""
    rows: dict[int, set[int]] = {}
    for rank, ranges in re.findall(r"^rank (\d+): .*: rows (\S+)$", stderr, re.M):
        rows[int(rank)] = set()
        for part in ranges.split(","):
            first, _, last = part.partition("-")
            if first.isdigit() and (not last or last.isdigit()):
                rows[int(rank)].update(range(int(first), int(last or first) + 1))
    return rows


def check_distributions(binary, ranks: int = 3, width: int = 16, height: int = 12) -> CheckResult:
    """Lab 04's tasks 2 and 3, which the image cannot show (every distribution renders lab
    01's bits, blocks included): the rows each rank rendered, as RT_MPI_REPORT lists them,
    for `ranks` ranks: interleaved is every `ranks`-th row from the rank's own; dynamic is
    not the fixed bands of block. Half the points each."""
    bands = {r: set(range(height * r // ranks, height * (r + 1) // ranks)) for r in range(ranks)}
    verdicts = []
    for distribution in ("interleaved", "dynamic"):
        run = run_lab(binary, width=width, height=height, spp=2,
                      launcher=mpirun(ranks, distribution, "RT_MPI_REPORT=1"))
        rows = report_rows(run.stderr)
        if sorted(rows) != list(range(ranks)) or set().union(*rows.values()) != set(range(height)):
            verdicts.append((False, f"{distribution}: RT_MPI_REPORT=1 does not list every "
                                    f"row once among ranks 0-{ranks - 1}"))
        elif distribution == "interleaved":
            want = {r: set(range(r, height, ranks)) for r in range(ranks)}
            verdicts.append((rows == want, f"interleaved: rank 1 rendered rows "
                                           f"{row_ranges(sorted(rows[1]))}" + (
                "" if rows == want else f", not {row_ranges(sorted(want[1]))} (rank r renders "
                                        f"rows r, r + {ranks}, ...: task 2 undone?)")))
        else:
            verdicts.append((rows != bands, "dynamic: " + (
                "rows handed out as ranks finish" if rows != bands else
                "the rows were split into block's fixed bands (task 3, the master and its "
                "workers, undone?)")))
    passed = sum(ok for ok, _ in verdicts)
    detail = f"{ranks} ranks, {width}x{height}: " + "; ".join(text for _, text in verdicts)
    return CheckResult("rows per distribution", passed == len(verdicts), detail,
                       credit=passed / len(verdicts))


# ---- scenes far from the origin, and primitives far larger than the view -----------------
# Both render with the same random numbers as their plain versions; what could differ is only
# float rounding, which a renderer must keep from showing (ray offsets that grow with the
# primitive, light measured from the surface point, not the offset origin).

# In units of the scene's size: the interior's radius, the camera's height.
TRANSLATIONS = (1e2, 1e4)


def _direction(distance: float) -> list[float]:
    """An offset of about `distance` off every axis, so no coordinate stays small."""
    return [distance, -0.7 * distance, 0.3 * distance]


def render_floor(binary, scene: dict, width: int = 32, height: int = 32, spp: int = 64):
    """floor_view (labkit/scenes.py) rendered with one bounce, with its relative error per
    pixel where it is smooth: the lower half of the image, the floor within ~4 units of the
    camera, where every subsample sees the floor (the upper half reaches the horizon, where a
    finite floor ends and a pixel spans a huge range of distances)."""
    with tempfile.TemporaryDirectory() as tmp:
        path = scenes.write_scene(pathlib.Path(tmp) / "floor.json", scene)
        image = run_lab(binary, path, width=width, height=height, spp=spp, bounces=1).image
    want, full = scenes.floor_view_expected(scene, width, height)
    full[: height // 2] = False
    return np.abs(image.mean(axis=2)[full] / want[full] - 1.0)


def check_translation_invariance(binary) -> CheckResult:
    """A scene moved far from the origin, by up to 1e4 times its size, renders as before: the
    zero-variance sphere interior (closed form, 2 bounces) and a lit floor (closed form per
    pixel). The shared driver renders scenes centred on their geometry, which makes this hold
    for any renderer built on it; a renderer that loads scenes itself must do the same or
    keep its offsets and light sampling independent of |position| (before either, the sphere
    interior moved by 1e4 radii rendered 39% too bright)."""
    worst_interior, worst_floor = 0.0, 0.0
    radius = INTERIOR["radius"]
    want = scenes.sphere_interior_radiance(**INTERIOR, bounces=2)
    with tempfile.TemporaryDirectory() as tmp:
        for t in TRANSLATIONS:
            scene = scenes.translated(scenes.sphere_interior(**INTERIOR), _direction(t * radius))
            path = scenes.write_scene(pathlib.Path(tmp) / "interior.json", scene)
            image = run_lab(binary, path, width=16, height=16, spp=4, bounces=2).image
            worst_interior = max(worst_interior, float(np.max(np.abs(image / want - 1.0))))
    for t in TRANSLATIONS:
        err = render_floor(binary, scenes.translated(scenes.floor_view(1e3), _direction(t)))
        worst_floor = max(worst_floor, float(err.mean()))
    # Rounding at 2e4 from the origin moves the interior's wall points by ~1e-3 of its radius:
    # measured 5e-4 for the reference. The floor's noise is the jitter's, ~5e-3 at 64 spp.
    ok = worst_interior < 2e-3 and worst_floor < 1.5e-2
    return CheckResult("translation invariance", ok,
                       f"moved by up to 1e4x its size: sphere interior off by up to "
                       f"{worst_interior:.2e} (allowed 2e-3), lit floor by {worst_floor:.2e} "
                       f"on average (allowed 1.5e-2)")


LARGE_FLOORS = (1e1, 1e3, 1e5)  # floor half-sizes, in units of the camera's height


def check_large_primitives(binary) -> CheckResult:
    """A floor far larger than the view renders as a small one: a quad of half-size 10 to
    1e5 (a rectangle), the same floor as two triangles and a sphere of radius 1e3 to 1e5, seen
    from 1 unit above. An offset that scales only with the hit point and not with the
    primitive's coordinates lets shadow rays hit the floor they leave: two triangles of
    half-size 1e5 rendered 38% too dark. (A rectangle's test subtracts no far coordinate.)"""
    worst = (0.0, "")
    cases = ([("quad", h) for h in LARGE_FLOORS] + [("triangles", h) for h in LARGE_FLOORS[1:]]
             + [("sphere", h) for h in LARGE_FLOORS[1:]])
    for kind, half in cases:
        err = float(render_floor(binary, scenes.floor_view(half, kind=kind)).mean())
        if err >= worst[0]:
            worst = (err, f"{kind} {half:g}")
    # The jitter's noise is ~5e-3 at 64 spp; a sphere of radius 1e5 adds ~3e-3 of float
    # rounding in its hit points (measured).
    return CheckResult("large primitives", worst[0] < 1.5e-2,
                       f"worst: {worst[1]}, mean relative error {worst[0]:.2e} (allowed 1.5e-2)")
