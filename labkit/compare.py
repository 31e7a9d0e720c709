"""Statistically sound comparison of a Monte Carlo render against a golden reference.

Usage from the command line::

    python3 -m labkit.compare IMAGE.pfm --golden DIR --spp N [--alpha A] [--heatmap PNG]

DIR holds ``golden.pfm`` (the converged mean of ``golden_spp`` paths per pixel),
``variance.pfm`` (the variance of ONE path's radiance, per pixel and channel) and
``meta.json`` (``{"golden_spp": ..., ...}``).  Exit status: 0 pass, 1 fail, 2 bad input.

From Python::

    report = compare(image, test_spp, golden, variance, golden_spp)
    assert report.passed, report.table()

The test
========

Let I be the render (n = ``test_spp`` paths per pixel) and G the golden mean (N =
``golden_spp`` paths per pixel), and sigma^2 the per-path variance of a pixel channel.  If
the renderer is correct, I and G estimate the same expectation with independent samples, so
the difference d = I - G has mean 0 and variance

    s2 = sigma^2 / n + sigma^2 / N.

(The golden image's own noise is part of s2, so a golden made with few paths costs power
but does not cause false failures.)  Pixels use independent random numbers, so for any set
B of pixels Var[sum_B d] = sum_B s2, and

    z_B = sum_B d / sqrt(sum_B s2)

is approximately standard normal by the central limit theorem (it averages n*|B| path
samples).  We test, for every channel: every block of 8x8 and of 16x16 pixels (partial
blocks at the right and bottom edges included; several sizes, because a defect straddling
the corner of four 8x8 blocks is diluted in each of them but whole in a 16x16 block) and the
whole image (the global mean, which catches small uniform biases such as a wrong
normalisation constant that no single block could resolve).  ``n_tests`` counts them all.

Why the false-failure rate is at most alpha (Bonferroni)
--------------------------------------------------------
Each test rejects when |z| > c with c = Phi^-1(1 - alpha / (2 m)), m = ``n_tests`` (two-sided:
alpha/(2m) in each tail).  Under the null hypothesis (correct renderer) every single test
then rejects with probability alpha/m, and by the union bound

    P(any test rejects) <= sum over tests of P(test rejects) = m * alpha/m = alpha.

The union bound needs no independence: the tests overlap heavily (a 16x16 block contains
four 8x8 blocks, the global mean contains everything), and positive dependence only makes
the true family-wise rate *smaller* than alpha.  With the default alpha = 1e-4 a correct
renderer fails at most once in 10 000 runs, so a red test almost surely means a bug.

Zero-variance blocks (sum s2 == 0: e.g. a constant background that every path sees
identically) are deterministic: a correct render must match them exactly up to float
rounding, |sum d| <= zero_var_rtol * (1 + sum |G|) (1e-6 by default).  Anything else fails
with z = +-inf.  Likewise a block whose |sum d| is within that rounding tolerance is never
counted as a failure, whatever its variance.  These checks contribute no false failures;
they are still counted in m, which only raises c slightly.  Any NaN or Inf in the render
fails the comparison outright (``nan_count``/``inf_count`` count the pixels); those channel
values are left out of the statistics so the rest of the report stays meaningful.

Assumptions, and what happens when they are violated
----------------------------------------------------
1. Central limit theorem per block.  z sums n*|B| path samples; a path-radiance skewness g
   shrinks to g / sqrt(n*|B|).  The Bonferroni threshold sits far in the tail (c ~ 4.5-5.5),
   where heavy-tailed radiance (fireflies, caustics) converges slowest: for such scenes use
   more test spp or larger blocks, otherwise the real false-failure rate can exceed alpha.
2. Independent pixels.  True when every pixel draws its own random streams.  Samplers that
   correlate pixels (shared QMC sequences, blue-noise masks) change Var[sum d].  The R, G
   and B values of a pixel come from the same paths and are correlated; that is harmless,
   because every z test is per channel and the union bound needs no independence.  (Only
   ``bias_se``, which averages over channels, needs their covariance; it uses the
   Cauchy-Schwarz bound, i.e. it assumes fully correlated channels and is never too small.)
3. The variance is itself estimated.  If ``variance.pfm`` comes from K independent samples
   (K renders of the scene, or K = golden_spp when accumulated per path), each pixel's
   estimate has relative standard error ~ sqrt(2/(K-1)) (Gaussian data; heavier tails give
   more, sqrt((kurtosis-1)/K)).  The test only uses block sums of it, so over a block of P
   pixels the relative error of sum s2 is eps ~ sqrt(2/((K-1) P)): small.  Underestimating
   the variance inflates |z|; averaged over the estimation error the tail probability at c
   grows by about exp(c^4 eps^2 / 8) -- e.g. K=16, 8x8 blocks, c=5: x1.18; K=64: x1.04;
   per-path estimate with K=4096: x1.0006.  ``false_failure_rate()`` computes this bound.
   A pixel whose estimated variance is exactly 0 although its true variance is not (rare
   paths never seen in the K samples) turns a block deterministic; a render that does see
   such a path there fails with z = inf -- golden references need enough samples.

Small blocks and pooled variance
--------------------------------
A small image with small features (grading/checks/hidden.py's 32x32 scene, whose turned panel and
triangle cover a few pixels each) needs 4x4 blocks: a renderer that misses one of them moves
a few pixels far, which 8x8 blocks dilute (over 26 secrets with a lighter panel and a smaller
triangle, lab 01's closest hit without convex quads reached the 8x8/16x16 limit in 20, with
4x4 blocks in 25).  But 16 pixels is where assumptions 1 and 3 weaken together: a glass ball's
rare bright paths give skewed pixel means, and golden data from K = 32 renders miss them in
some pixels, so the estimated variance there is far too small (the reference's 4x4 max |z|
reached 5.07 over 200 secrets, against the limit 5.1).  ``pooled_variance=True`` raises each
pixel's s2, in the block and global tests only, to the mean of its 3x3 neighbourhood where
that is larger: a rare-path pixel borrows the variance its neighbours saw, which only ever
makes z smaller (the false-failure bound still holds) and costs a defect spanning several
pixels about a tenth of its z (over 167 secrets, the reference's max |z| was 4.53 raw, 4.05
pooled).  Measured on the hidden scene as it is (lab 01's reference, Intel Xeon; 4x4, 8x8 and
16x16 blocks, pooled, limit 5.1 at alpha 1e-4): the reference's max |z| over 200 secrets
4.41, all passing; over 61 secrets, a renderer without convex quads at least 8.85 and one
without triangles at least 11.3.  The grader compares at ``GRADING_ALPHA`` (limit about 5.5).

The grader's alpha
------------------
The grader draws its renders' seeds afresh each grade, so a tail the normal model
underestimates is met sooner or later: the showcase's glass makes block sums skewed
(assumption 1), and lab 01's reference at 64 spp failed its golden test (8x8 and 16x16
blocks, alpha 1e-4: limit 5.06) at 4 of 2,500 seeds (worst z +5.36; over pooled variance,
+5.13).  The grader therefore compares at ``GRADING_ALPHA`` = 1e-5 over pooled variance
(limit 5.49 there), where none of the 2,500 came within 0.36 of the limit.

Noise and structure: the per-pixel test
---------------------------------------
Block means see only averages: an image rendered with a quarter of the paths, or one blurred,
flattened into blocks or denoised, keeps the right block means.  So each pixel channel with
s2 > 0 also gives q = d^2 / s2, which for a correct render is approximately chi-square with
one degree of freedom (d/sqrt(s2) ~ N(0, 1) per pixel): its mean is 1 and its median
0.455.  Too much noise (fewer paths: q grows by the ratio of the path counts) raises the
mean; too little (an image smoothed across pixels) lowers the median, which, unlike the
mean, a few wrong pixels cannot hold up.  The mean is of min(q, ``CHI_CAP``): a pixel
whose rare paths the golden data never saw has an underestimated variance and a huge q,
which alone must not decide (chi-square(1) exceeds 16 with probability 6e-5, so the cap
costs a correct render nothing; four times too noisy still averages ~3.7).  The test fails
when that mean exceeds ``CHI_MEAN_MAX`` or the median falls below ``CHI_MEDIAN_MIN``.
Measured on lab 01's reference at 64 spp against the stored golden data (6 seeds each): mean
1.00-1.07 (cornell) and 0.95-1.10 (showcase), median 0.45-0.49; at 16 spp mean 4.0-4.2; blurred
over 3x3 pixels median 0.10-0.18; flattened into 8x8 blocks mean 36-149 (uncapped).  On the
hidden scene (grading/checks/hidden.py, with its glass and mirror balls, turned panel and triangle;
lab 01's reference on an Intel Xeon): capped mean 0.96-1.22, median 0.32-0.55 (200 secrets);
at 16 spp capped mean 2.5-4.0, blurred over 3x3 pixels 3.8-7.7, both failing in 20 of 20.
With a lighter panel and a smaller triangle (150 secrets) the uncapped mean reached 1.42 (up
to 38 pixel channels above the cap), and 1.51 in one grade, which failed the reference: a
few pixels beside the glass ball whose variance the golden renders underestimated.  Glass
makes a pixel's mean of 64 paths skewed, which lowers the median of a correct render: hence
the lower bound's margin.  For
chi-square(1) values the standard error of the mean over P values is sqrt(2/P) and of the
median ~0.5/(0.47 sqrt(P)), i.e. 0.02 and 0.01 for a 64x64 image and 0.03 and 0.02 for 32x32:
both bounds are more than 10 standard errors from 1 and 0.455, and a variance estimated from K
renders moves the mean only by (K-1)/(K-3) (1.07 for K = 32).  Images with fewer than
``CHI_MIN_VALUES`` pixel channels of non-zero variance skip this test.  Every statistic is
computed in float64 and compared as ``not (value <= bound)``, so a NaN fails.

Power: a bias delta per pixel over a block of P pixels is found once
delta > c * sqrt(mean s2 / P); the global test finds delta > c * sqrt(mean s2 / (H W)).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
from typing import NamedTuple, Sequence

import numpy as np

from . import heatmap
from .compare_report import (
    CHI_CAP,
    CHI_MEAN_MAX,
    CHI_MEDIAN_MIN,
    CHI_MIN_VALUES,
    GRADING_ALPHA,
    MAX_LISTED_FAILURES,
    BlockResult,
    Failure,
    Report,
)
from .compare_stats import (
    count_tests,
    critical_z,
    false_failure_rate,
    normal_quantile,
    normal_sf,
)
from .pfm import PFMError, read_pfm

# The comparison's whole interface, whichever of compare_stats and compare_report holds it.
__all__ = [
    "CHI_MEAN_MAX",
    "CHI_MEDIAN_MIN",
    "GRADING_ALPHA",
    "BlockResult",
    "count_tests",
    "Failure",
    "InputError",
    "Report",
    "compare",
    "compare_files",
    "critical_z",
    "false_failure_rate",
    "heatmap_png",
    "load_reference",
    "normal_quantile",
    "normal_sf",
    "main",
]



class InputError(ValueError):
    """Bad input to the comparison: missing or malformed files, mismatched sizes, a
    reference with NaN or negative variance, non-positive sample counts."""




# ---------------------------------------------------------------------------------------
# The comparison


def _as_image(name: str, a) -> np.ndarray:
    arr = np.asarray(a)
    if arr.ndim == 2:
        arr = arr[:, :, None]
    if arr.ndim != 3 or arr.shape[0] < 1 or arr.shape[1] < 1 or arr.shape[2] < 1:
        raise InputError(
            f"{name}: expected an image of shape (height, width, channels), got {arr.shape}"
        )
    if not (np.issubdtype(arr.dtype, np.floating) or np.issubdtype(arr.dtype, np.integer)):
        raise InputError(f"{name}: expected numbers, got dtype {arr.dtype}")
    return arr.astype(np.float64, copy=False)


def _positive(name: str, x) -> float:
    try:
        v = float(x)
    except (TypeError, ValueError):
        raise InputError(f"{name} must be a positive number, got {x!r}") from None
    if not (v > 0 and math.isfinite(v)) or isinstance(x, bool):
        raise InputError(f"{name} must be a positive number, got {x!r}")
    return v


def _shape_str(a: np.ndarray) -> str:
    return f"{a.shape[1]}x{a.shape[0]}" + (f"x{a.shape[2]}" if a.shape[2] != 3 else "")


def _check_inputs(image, golden, variance, test_spp, golden_spp, alpha, block_sizes):
    img = _as_image("image", image)
    gold = _as_image("golden", golden)
    var = _as_image("variance", variance)
    if img.shape != gold.shape:
        raise InputError(
            f"size mismatch: image is {_shape_str(img)} but golden is {_shape_str(gold)}"
        )
    if var.shape != gold.shape:
        raise InputError(
            f"size mismatch: variance is {_shape_str(var)} but golden is {_shape_str(gold)}"
        )
    if not np.all(np.isfinite(gold)):
        raise InputError("golden image contains NaN or Inf")
    if not np.all(np.isfinite(var)):
        raise InputError("variance image contains NaN or Inf")
    if np.any(var < 0):
        raise InputError("variance image contains negative values")
    n = _positive("test_spp", test_spp)
    big_n = _positive("golden_spp", golden_spp)
    try:
        alpha_ok = 0.0 < float(alpha) < 1.0
    except (TypeError, ValueError):
        alpha_ok = False
    if not alpha_ok:
        raise InputError(f"alpha must be in (0, 1), got {alpha!r}")
    sizes = []
    for b in block_sizes:
        if isinstance(b, bool) or not isinstance(b, (int, np.integer)) or b < 1:
            raise InputError(f"block sizes must be positive integers, got {b!r}")
        sizes.append(int(b))
    return img, gold, var, n, big_n, tuple(sizes)


def _block_sums(a: np.ndarray, b: int) -> np.ndarray:
    """Sums of `a` (H, W, C) over b x b blocks, partial edge blocks included: (by, bx, C)."""
    h, w, c = a.shape
    by, bx = -(-h // b), -(-w // b)
    if by * b != h or bx * b != w:
        padded = np.zeros((by * b, bx * b, c), dtype=a.dtype)
        padded[:h, :w] = a
        a = padded
    return a.reshape(by, b, bx, b, c).sum(axis=(1, 3))


def _z_scores(sum_d, sum_s2, sum_abs_g, rtol):
    """z = sum d / sqrt(sum s2), with the deterministic (zero-variance) and float-rounding
    rules of the module docstring."""
    sum_d = np.asarray(sum_d, dtype=np.float64)
    sum_s2 = np.asarray(sum_s2, dtype=np.float64)
    within_rounding = np.abs(sum_d) <= rtol * (1.0 + np.asarray(sum_abs_g))
    with np.errstate(divide="ignore", invalid="ignore"):
        z = sum_d / np.sqrt(sum_s2)
    z = np.where(sum_s2 > 0, z, np.copysign(np.inf, sum_d))
    return np.where(within_rounding, 0.0, z)


class _Stats(NamedTuple):
    img: np.ndarray
    gold: np.ndarray
    d: np.ndarray
    s2: np.ndarray
    finite: np.ndarray  # per channel value
    z_maps: dict
    global_z: np.ndarray
    n_tests: int
    critical: float


def _neighbourhood_floor(s2: np.ndarray) -> np.ndarray:
    """Each value raised to the mean of its 3x3 neighbourhood (edges repeated) where that is
    larger: the module docstring's pooled variance."""
    h, w = s2.shape[:2]
    padded = np.pad(s2, ((1, 1), (1, 1), (0, 0)), mode="edge")
    mean = sum(padded[dy:dy + h, dx:dx + w] for dy in range(3) for dx in range(3)) / 9.0
    return np.maximum(s2, mean)


def _statistics(image, test_spp, golden, variance, golden_spp, alpha, block_sizes,
                zero_var_rtol, pooled_variance=False) -> _Stats:
    img, gold, var, n, big_n, sizes = _check_inputs(
        image, golden, variance, test_spp, golden_spp, alpha, block_sizes)
    finite = np.isfinite(img)
    d = np.where(finite, img, 0.0) - np.where(finite, gold, 0.0)
    s2 = np.where(finite, var * (1.0 / n + 1.0 / big_n), 0.0)
    s2_tests = np.where(finite, _neighbourhood_floor(s2), 0.0) if pooled_variance else s2
    abs_g = np.abs(gold)
    z_maps = {}
    n_tests = 0
    for b in sizes:
        z = _z_scores(_block_sums(d, b), _block_sums(s2_tests, b), _block_sums(abs_g, b),
                      zero_var_rtol)
        z_maps[b] = z
        n_tests += z.size
    global_z = _z_scores(d.sum(axis=(0, 1)), s2_tests.sum(axis=(0, 1)), abs_g.sum(axis=(0, 1)),
                         zero_var_rtol)
    n_tests += global_z.size
    return _Stats(img, gold, d, s2, finite, z_maps, global_z, n_tests, critical_z(alpha, n_tests))


def compare(image, test_spp, golden, variance, golden_spp, alpha: float = 1e-4,
            block_sizes: Sequence[int] = (8, 16), heatmap_path: str | os.PathLike | None = None,
            zero_var_rtol: float = 1e-6, per_pixel: bool = True,
            pooled_variance: bool = False) -> Report:
    """Compares a render (`test_spp` paths per pixel) with the golden mean (`golden_spp`
    paths per pixel) given the per-path variance image.  Images are (H, W, 3) arrays, top
    row first.  The comparison passes when every z test stays within the Bonferroni limit
    and the render has no NaN/Inf; the family-wise false-failure rate is then <= alpha (see
    the module docstring).  When it fails and `heatmap_path` is given, a PNG heatmap of the
    per-block |z| (smallest block size) is written there.  `per_pixel=False` skips the
    per-pixel noise test (for an image averaged from a larger stratified render, whose pixels
    are smoother than `test_spp` independent paths give).  `pooled_variance=True` raises
    each pixel's variance to its neighbourhood's mean in the block tests (module docstring:
    small blocks over golden data estimated from few renders).  Raises InputError (a
    ValueError) for mismatched sizes or an invalid reference."""
    st = _statistics(image, test_spp, golden, variance, golden_spp, alpha, block_sizes,
                     zero_var_rtol, pooled_variance)
    img, gold, d, s2, finite = st.img, st.gold, st.d, st.s2, st.finite
    h, w, nch = img.shape
    crit = st.critical

    nan_px = np.isnan(img).any(axis=2)
    inf_px = np.isinf(img).any(axis=2)
    nonfinite_px = nan_px | inf_px
    first_nonfinite = None
    if nonfinite_px.any():
        y, x = np.argwhere(nonfinite_px)[0]
        first_nonfinite = (int(x), int(y))

    n_fin = int(finite.sum())
    if n_fin:
        dd = d[finite]
        rmse = float(np.sqrt(np.mean(dd * dd)))
        relmse = float(np.mean(dd * dd / (gold[finite] ** 2 + 1e-2)))
        bias = float(np.mean(dd))
        # The channels of a pixel come from the same paths and are correlated (unknown
        # covariance), so use the Cauchy-Schwarz bound Var(sum_c d_c) <= (sum_c sd_c)^2:
        # exact for fully correlated channels, never an underestimate.
        bias_se = float(np.sqrt(np.sum(np.sqrt(s2).sum(axis=2) ** 2)) / n_fin)
    else:
        rmse = relmse = bias = bias_se = float("nan")
    mean_golden = float(gold.mean())

    # Every test, worst first.
    worst_block = None
    max_abs_z = float(np.max(np.abs(st.global_z))) if st.global_z.size else 0.0
    candidates = []  # (|z|, Failure-args)
    for b, z in st.z_maps.items():
        absz = np.abs(z)
        k = int(np.argmax(absz))
        by, bx, c = np.unravel_index(k, z.shape)
        if worst_block is None or absz.flat[k] > abs(worst_block.z):
            worst_block = BlockResult(b, int(bx) * b, int(by) * b, int(c), float(z.flat[k]))
        max_abs_z = max(max_abs_z, float(absz.flat[k]))
        bad = np.argwhere(absz > crit)
        if len(bad):
            sum_d = _block_sums(d, b)
            sum_g = _block_sums(gold, b)
            count = _block_sums(finite.astype(np.float64), b)
            for by, bx, c in bad:
                npx = max(count[by, bx, c], 1.0)
                candidates.append(Failure(
                    b, int(bx) * b, int(by) * b, min(int(bx) * b + b, w) - 1,
                    min(int(by) * b + b, h) - 1, int(c), float(z[by, bx, c]),
                    float(sum_d[by, bx, c] / npx), float(sum_g[by, bx, c] / npx)))
    for c, zc in enumerate(st.global_z):
        if abs(zc) > crit:
            npx = max(int(finite[:, :, c].sum()), 1)
            candidates.append(Failure(0, 0, 0, w - 1, h - 1, c, float(zc),
                                      float(d[:, :, c].sum() / npx),
                                      float(gold[:, :, c][finite[:, :, c]].sum() / npx)))
    candidates.sort(key=lambda f: (-abs(f.z), f.block_size, f.y0, f.x0, f.channel))

    # The per-pixel test (module docstring), float64 throughout; NaN/Inf values are already
    # a failure and are left out here.
    usable = finite & (s2 > 0)
    chi_mean = chi_median = None
    if per_pixel and int(usable.sum()) >= CHI_MIN_VALUES:
        q = (d[usable] ** 2) / s2[usable]
        chi_mean, chi_median = float(np.mean(np.minimum(q, CHI_CAP))), float(np.median(q))

    passed = bool(not nonfinite_px.any() and not candidates)
    report = Report(
        passed=passed, rmse=rmse, relmse=relmse, bias=bias, bias_se=bias_se,
        max_abs_z=max_abs_z, critical_z=crit, n_tests=st.n_tests, worst_block=worst_block,
        nan_count=int(nan_px.sum()), inf_count=int(inf_px.sum()),
        width=w, height=h, test_spp=test_spp, golden_spp=golden_spp, alpha=alpha,
        block_sizes=tuple(st.z_maps), global_z=tuple(float(z) for z in st.global_z),
        mean_golden=mean_golden, n_failed=len(candidates),
        failures=candidates[:MAX_LISTED_FAILURES], first_nonfinite=first_nonfinite,
        z_maps=st.z_maps, chi_mean=chi_mean, chi_median=chi_median)
    if report.noise_problem():
        report.passed = passed = False
    if not passed and heatmap_path is not None and st.z_maps:
        b = min(st.z_maps)
        heatmap.write_heatmap(
            os.fspath(heatmap_path),
            st.z_maps[b],
            crit,
            b,
            h,
            w,
            _block_sums(nonfinite_px[:, :, None].astype(np.float64), b)[:, :, 0] > 0,
        )
        report.heatmap_path = os.fspath(heatmap_path)
    return report


def heatmap_png(path, image, golden, variance, test_spp, golden_spp, block: int = 8,
                alpha: float = 1e-4, block_sizes: Sequence[int] | None = None,
                zero_var_rtol: float = 1e-6) -> str:
    """Writes a PNG heatmap of the per-block |z| (max over channels) for `block`-sized
    blocks: blue at 0, white at the Bonferroni limit, red at twice the limit or more, black
    where a block holds a NaN/Inf pixel, the worst block outlined in green.  The limit is
    the one compare() uses with `alpha` and `block_sizes` (default: (8, 16) plus `block`).
    Returns the path."""
    if block_sizes is None:
        block_sizes = tuple(sorted({8, 16, int(block)}))
    elif block not in block_sizes:
        block_sizes = tuple(block_sizes) + (int(block),)
    st = _statistics(image, test_spp, golden, variance, golden_spp, alpha, block_sizes,
                     zero_var_rtol)
    h, w = st.img.shape[:2]
    nonfinite = (~np.isfinite(st.img)).any(axis=2)[:, :, None].astype(np.float64)
    heatmap.write_heatmap(os.fspath(path), st.z_maps[block], st.critical, block, h, w,
                          _block_sums(nonfinite, block)[:, :, 0] > 0)
    return os.fspath(path)


# ---------------------------------------------------------------------------------------
# Files and the command line


def load_reference(directory: str | os.PathLike):
    """Loads (golden, variance, golden_spp, meta) from a golden directory holding
    golden.pfm, variance.pfm and meta.json.  Raises InputError for anything missing or
    malformed."""
    directory = os.fspath(directory)
    if not os.path.isdir(directory):
        raise InputError(f"{directory}: golden directory not found")
    meta_path = os.path.join(directory, "meta.json")
    try:
        with open(meta_path, encoding="utf-8") as f:
            meta = json.load(f)
    except FileNotFoundError:
        raise InputError(f"{meta_path}: file not found") from None
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as e:
        raise InputError(f"{meta_path}: cannot read JSON: {e}") from None
    if not isinstance(meta, dict) or "golden_spp" not in meta:
        raise InputError(f"{meta_path}: expected an object with a \"golden_spp\" entry")
    golden_spp = meta["golden_spp"]
    if (
        isinstance(golden_spp, bool)
        or not isinstance(golden_spp, (int, float))
        or not golden_spp > 0
    ):
        raise InputError(f"{meta_path}: golden_spp must be a positive number, got {golden_spp!r}")
    golden = _read_image(os.path.join(directory, "golden.pfm"))
    variance = _read_image(os.path.join(directory, "variance.pfm"))
    if golden.shape != variance.shape:
        raise InputError(f"size mismatch: {directory}/golden.pfm is {_shape_str(golden)} but"
                         f" variance.pfm is {_shape_str(variance)}")
    return golden, variance, golden_spp, meta


def _read_image(path: str) -> np.ndarray:
    try:
        return read_pfm(path)
    except FileNotFoundError:
        raise InputError(f"{path}: file not found") from None
    except PFMError as e:
        raise InputError(str(e)) from None
    except OSError as e:
        raise InputError(f"{path}: cannot read: {e.strerror or e}") from None


def compare_files(image_path, golden_dir, test_spp, alpha: float = 1e-4,
                  block_sizes: Sequence[int] = (8, 16), heatmap_path=None) -> Report:
    """compare() on files: the render IMAGE.pfm against the golden directory."""
    golden, variance, golden_spp, _ = load_reference(golden_dir)
    image = _read_image(os.fspath(image_path))
    if image.shape != golden.shape:
        raise InputError(f"size mismatch: {os.fspath(image_path)} is {_shape_str(image)} but"
                         f" the golden image is {_shape_str(golden)}")
    return compare(image, test_spp, golden, variance, golden_spp, alpha=alpha,
                   block_sizes=block_sizes, heatmap_path=heatmap_path)


def _default_heatmap_path(image_path: str) -> str:
    root, ext = os.path.splitext(image_path)
    return (root if ext.lower() == ".pfm" else image_path) + ".heatmap.png"


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python3 -m labkit.compare",
        description="Compare a Monte Carlo render with a golden reference (exit 0 pass,"
                    " 1 fail, 2 bad input).")
    parser.add_argument("image", help="the render, a PFM file")
    parser.add_argument("--golden", required=True,
                        help="directory with golden.pfm, variance.pfm and meta.json")
    parser.add_argument("--spp", required=True, type=float,
                        help="paths per pixel the render was made with")
    parser.add_argument("--alpha", type=float, default=1e-4,
                        help="family-wise false-failure rate (default 1e-4)")
    parser.add_argument("--blocks", default="8,16",
                        help="comma-separated block sizes (default 8,16)")
    parser.add_argument("--heatmap", default=None,
                        help="where to write the heatmap PNG on failure"
                             " (default IMAGE.heatmap.png next to the image)")
    parser.add_argument("--no-heatmap", action="store_true", help="never write a heatmap")
    args = parser.parse_args(argv)
    try:
        try:
            blocks = tuple(int(s) for s in args.blocks.split(",") if s.strip())
        except ValueError:
            raise InputError(
                f"--blocks: expected comma-separated integers, got {args.blocks!r}"
            ) from None
        heatmap_path = (
            None if args.no_heatmap else (args.heatmap or _default_heatmap_path(args.image))
        )
        try:
            report = compare_files(args.image, args.golden, args.spp, alpha=args.alpha,
                                   block_sizes=blocks, heatmap_path=heatmap_path)
        except OSError as e:  # the heatmap could not be written: still give the verdict
            print(f"warning: cannot write the heatmap {heatmap_path}: {e}", file=sys.stderr)
            report = compare_files(args.image, args.golden, args.spp, alpha=args.alpha,
                                   block_sizes=blocks)
    except (InputError, PFMError) as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    except OSError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    print(report.table())
    return 0 if report.passed else 1


if __name__ == "__main__":
    sys.exit(main())
