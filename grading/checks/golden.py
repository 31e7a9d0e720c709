"""The golden images: a render compared, noise-aware, with the stored converged image of its
scene (labkit/compare.py), and a printed copy of a stored image named as one.

False failures: at most alpha per comparison, by the Bonferroni bound over every block and
global z-test (labkit/compare.py explains the model and its assumptions)."""
from __future__ import annotations

import pathlib

import numpy as np

from grading.checks import draws, symptoms
from grading.checks.check_result import CheckResult, image_checked
from grading.checks.lanes import lanes_not_lab01
from labkit.compare import GRADING_ALPHA, compare
from labkit.harness import GOLDEN, golden, rerun_command, run_lab

# Test renders are small and quick; the golden comparison knows their noise level exactly.
GOLDEN_TEST_SPP = 64


@image_checked("golden image")
def check_golden(binary, scene: str, *, seed: int | None = None, spp: int = GOLDEN_TEST_SPP,
                 heatmap_dir: pathlib.Path | None = None, launcher=(), threads=None,
                 extra=()) -> CheckResult:
    """Noise-aware comparison with the converged golden image (labkit/compare.py), rendered
    at a seed drawn from the grading secret (grading/checks/draws.py)."""
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
                       (f"{cause}; " if cause else "") + report.summary() + hint + again,
                       images={scene: (run.image, g.mean)})


def stored_golden_copied(image: np.ndarray) -> str | None:
    """The name of a stored golden image (reference/golden/) that `image` is, bit for bit, or
    None. The golden images are public (they ship with the course), so a submission could
    carry one and print it; no render at a test's spp matches a converged image exactly."""
    for folder in sorted(p for p in GOLDEN.iterdir() if p.is_dir()):
        stored = golden(folder.name).mean
        if stored.shape == image.shape and np.array_equal(stored, image):
            return folder.name
    return None
