"""The numerical-stability suite at the extremes, measured in float and in double: each case
of the render-level suite (the checks of grading/checks/ and tests/labs/test_extremes.py),
run with lab01-ref's renderer in float and with lab01-ref-double, with its property, its
tolerance and what each build measured; printed as the Markdown table of docs/extremes.md.

    python3 -m tools.extremes_report > table.md      (about a minute; builds what is missing)

The same cases are tests (tests/labs/test_extremes.py, for both builds); this prints numbers.
"""
from __future__ import annotations

import pathlib
import re
import sys
import tempfile

from grading.checks import analytic, invariance
from labkit import scenes
from labkit.harness import build, run_lab
from labkit.variants import build_sources, lab_sources

ROOT = pathlib.Path(__file__).resolve().parent.parent

# lab01-ref renders in double what float cannot place (common/host/double_twin.h): the float
# column is its renderer built without the double build it carries (make variant), so that
# it shows what float does alone.
BUILDS = {"float": (), "double": "lab01-ref-double",
          "float, -ffast-math": ("VARIANT_FLAGS_01-serial=-ffast-math",)}
SCALES = [10.0**k for k in range(-14, 15, 2)]


def from_check(check):
    """A case from a grader check: (passed, the numbers it reported)."""
    def run(binary):
        result = check(binary)
        return result.passed, result.detail
    return run


def every_scale(binary):
    """The Cornell box scaled by 1e-14 .. 1e14: which scales render as the unscaled box (mean
    within 1%) and which the loader refuses, in one line each."""
    base_scene = scenes.load("cornell")
    renders, refused, wrong = [], [], []
    with tempfile.TemporaryDirectory() as tmp:
        def render(scene, name):
            path = scenes.write_scene(pathlib.Path(tmp) / name, scene)
            return run_lab(binary, path, width=32, height=32, spp=8, bounces=4, seed=3, check=False)
        base = render(base_scene, "base.json").image
        for factor in SCALES:
            run = render(scenes.scaled(base_scene, factor), f"s{factor:g}.json")
            if run.returncode != 0:
                refused.append(factor)
            elif abs(float(run.image.mean()) / float(base.mean()) - 1.0) < 0.01:
                renders.append(factor)
            else:
                wrong.append(factor)
    span = lambda xs: f"{min(xs):g} .. {max(xs):g}" if xs else "none"  # noqa: E731
    return not wrong, (f"renders {span(renders)}; refused with one line: "
                       f"{', '.join(f'{f:g}' for f in refused) or 'none'}"
                       + (f"; WRONG: {', '.join(f'{f:g}' for f in wrong)}" if wrong else ""))


def nonfinite(binary):
    """NaN or Inf in the image: the Cornell box and the showcase at 64x64, 64 spp."""
    count = 0
    for scene in ("cornell", "showcase"):
        image = run_lab(binary, ROOT / "common" / "scenes" / f"{scene}.json", width=64,
                        height=64, spp=64).image
        count += int((~(image == image)).sum() + (abs(image) == float("inf")).sum())
    return count == 0, f"{count} non-finite values"


# case, property, tolerance, measurement
CASES = [
    ("camera inside a sphere", "the zero-variance sphere interior equals its closed form at 1, 2 "
     "and 4 bounces", "relative error < 3e-4", from_check(analytic.check_sphere_interior)),
    ("millions of samples", "the mean at 2^22 spp equals the mean at 2^12 spp (zero variance)",
     "< 1e-5", from_check(analytic.check_million_samples)),
    ("light near a surface, per pixel", "a lit floor equals the per-pixel integral of its closed "
     "form", "mean 3e-3, max 2e-2", from_check(analytic.check_lit_plane)),
    ("glass pane", "Fresnel reflectance at normal incidence through a pane", "mean within 5%",
     from_check(analytic.check_glass_slab)),
    ("scale", "the Cornell box scaled 1e-4 .. 1e5 renders as at scale 1",
     "the scale check's", from_check(invariance.check_scale_invariance)),
    ("far from the origin", "sphere interior and lit floor moved 1e4 times their size",
     "2e-3; 1.5e-2 mean", from_check(invariance.check_translation_invariance)),
    ("huge next to small", "floors (quad, sphere) of half-size up to 1e5 seen from 1 unit",
     "mean 1.5e-2", from_check(invariance.check_large_primitives)),
    ("the loader's range", "every scale 1e-14 .. 1e14 renders as scale 1, or is refused in one "
     "line; none renders wrong", "mean within 1%", every_scale),
    ("NaN and Inf", "never reach the image", "0", nonfinite),
]


def float_build(make_args):
    """lab01-ref's renderer in float alone (make variant), with `make_args`: -ffast-math as
    make tradeoff builds it (do the NaN guards and the closed forms survive the flag?)."""
    work = ROOT / "build" / "extremes" / ("fast-math" if make_args else "float")
    return build_sources("01-serial", work, lab_sources("01-serial"), make_args=make_args)


def main() -> int:
    binaries = {name: build(target)[0] if isinstance(target, str) else float_build(target)
                for name, target in BUILDS.items()}
    print("| case | property | tolerance | float (lab01-ref's renderer) | double "
          "(lab01-ref-double) | float, `-ffast-math` |")
    print("|---|---|---|---|---|---|")
    for case, prop, tolerance, measure in CASES:
        cells = []
        for name in BUILDS:
            passed, detail = measure(binaries[name])
            detail = re.sub(r"\s+", " ", detail).replace("|", "/")
            cells.append(f"{'pass' if passed else '**FAIL**'}: {detail}")
        print(f"| {case} | {prop} | {tolerance} | {' | '.join(cells)} |", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
