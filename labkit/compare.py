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
A small image with small features (grading/hidden.py's 32x32 scene, whose turned panel and
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
hidden scene (grading/hidden.py, with its glass and mirror balls, turned panel and triangle;
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
from dataclasses import dataclass, field
from typing import NamedTuple, Sequence

import numpy as np

from . import heatmap
from .pfm import PFMError, read_pfm

__all__ = [
    "BlockResult",
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

CHANNEL_NAMES = ("R", "G", "B")
# The grader's family-wise false-failure bound (module docstring, "The grader's alpha").
GRADING_ALPHA = 1e-5
# The per-pixel test (module docstring): a correct render gives a mean d^2/s2 of about 1 and
# a median of about 0.455.
CHI_MEAN_MAX = 1.5
CHI_MEDIAN_MIN = 0.25
CHI_CAP = 16.0  # each value's cap in the mean: one underestimated variance must not decide
CHI_MIN_VALUES = 256
MAX_LISTED_FAILURES = 20


class InputError(ValueError):
    """Bad input to the comparison: missing or malformed files, mismatched sizes, a
    reference with NaN or negative variance, non-positive sample counts."""


# ---------------------------------------------------------------------------------------
# Normal distribution


def normal_sf(z: float) -> float:
    """P(Z > z) for a standard normal Z (accurate far into the tail)."""
    return 0.5 * math.erfc(z / math.sqrt(2.0))


def normal_quantile(p: float) -> float:
    """Phi^-1(p): the z with P(Z <= z) = p, for 0 < p < 1.

    Acklam's rational approximation (relative error 1.15e-9) refined by one Halley step on
    math.erfc, which brings it to about machine precision even for p ~ 1e-300."""
    if not 0.0 < p < 1.0:
        raise ValueError(f"normal_quantile needs 0 < p < 1, got {p!r}")
    a = (-3.969683028665376e01, 2.209460984245205e02, -2.759285104469687e02,
         1.383577518672690e02, -3.066479806614716e01, 2.506628277459239e00)
    b = (-5.447609879822406e01, 1.615858368580409e02, -1.556989798598866e02,
         6.680131188771972e01, -1.328068155288572e01)
    c = (-7.784894002430293e-03, -3.223964580411365e-01, -2.400758277161838e00,
         -2.549732539343734e00, 4.374664141464968e00, 2.938163982698783e00)
    d = (7.784695709041462e-03, 3.224671290700398e-01, 2.445134137142996e00,
         3.754408661907416e00)
    p_low = 0.02425
    if p < p_low:
        q = math.sqrt(-2.0 * math.log(p))
        x = (((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) / (
            (((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1.0)
    elif p <= 1.0 - p_low:
        q = p - 0.5
        r = q * q
        x = (((((a[0] * r + a[1]) * r + a[2]) * r + a[3]) * r + a[4]) * r + a[5]) * q / (
            ((((b[0] * r + b[1]) * r + b[2]) * r + b[3]) * r + b[4]) * r + 1.0)
    else:
        q = math.sqrt(-2.0 * math.log1p(-p))
        x = -(((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) / (
            (((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1.0)
    # One Halley step.  Work in the smaller tail so erfc keeps full relative precision.
    if x > 0:
        e = normal_sf(x) - (1.0 - p)  # upper tail: sf(x) should equal 1-p
        e = -e
    else:
        e = normal_sf(-x) - p  # lower tail: cdf(x) = sf(-x)
    u = e * math.sqrt(2.0 * math.pi) * math.exp(0.5 * x * x)
    return x - u / (1.0 + 0.5 * x * u)


def critical_z(alpha: float, n_tests: int) -> float:
    """The two-sided Bonferroni threshold: |z| > critical_z(alpha, m) has probability
    alpha/m for one standard-normal z, so at most alpha for any family of m tests."""
    if not 0.0 < alpha < 1.0:
        raise ValueError(f"alpha must be in (0, 1), got {alpha!r}")
    if n_tests < 1:
        raise ValueError(f"n_tests must be >= 1, got {n_tests!r}")
    return -normal_quantile(alpha / (2.0 * n_tests))


def count_tests(height: int, width: int, channels: int = 3,
                block_sizes: Sequence[int] = (8, 16)) -> int:
    """How many z tests compare() performs on an image of this size."""
    n = channels  # the global mean, one per channel
    for b in block_sizes:
        n += channels * (-(-height // b)) * (-(-width // b))
    return n


def false_failure_rate(alpha: float = 1e-4, n_tests: int | None = None,
                       variance_samples: int | None = None, block_pixels: int = 64,
                       height: int | None = None, width: int | None = None,
                       block_sizes: Sequence[int] = (8, 16)) -> float:
    """Approximate upper bound on the family-wise false-failure rate of compare().

    With an exactly known variance it is alpha (Bonferroni; see the module docstring).  If
    the variance image was estimated from `variance_samples` = K independent samples, the
    smallest blocks (`block_pixels` = P pixels) have relative variance error
    eps^2 = 2/((K-1) P), which inflates the tail probability at the critical z = c by about
    exp(c^4 eps^2 / 8).  The bound returned is alpha times that factor (the factor of the
    smallest blocks, which is the largest).  Give `n_tests`, or `height` and `width`."""
    if n_tests is None:
        if height is None or width is None:
            raise ValueError("give n_tests, or height and width")
        n_tests = count_tests(height, width, 3, block_sizes)
    if variance_samples is None:
        return alpha
    if variance_samples < 2:
        raise ValueError("variance_samples must be >= 2")
    c = critical_z(alpha, n_tests)
    eps2 = 2.0 / ((variance_samples - 1) * block_pixels)
    return min(1.0, alpha * math.exp(c ** 4 * eps2 / 8.0))


# ---------------------------------------------------------------------------------------
# Report


class BlockResult(NamedTuple):
    """One block test: block size, its top-left pixel (x0, y0; y counts from the top row),
    channel index (0 R, 1 G, 2 B) and z."""

    block_size: int
    x0: int
    y0: int
    channel: int
    z: float


@dataclass(frozen=True)
class Failure:
    """One failing test.  block_size 0 means the global (whole-image) test.  Pixel ranges
    are inclusive; y counts from the top row."""

    block_size: int
    x0: int
    y0: int
    x1: int
    y1: int
    channel: int
    z: float
    mean_diff: float    # mean of render - golden over the block
    mean_golden: float  # mean golden value over the block

    def where(self) -> str:
        if self.block_size == 0:
            return "whole image"
        return (f"{self.block_size}x{self.block_size} block x {self.x0}..{self.x1},"
                f" y {self.y0}..{self.y1}")

    def relative_diff(self) -> float | None:
        if self.mean_golden == 0 or not math.isfinite(self.mean_diff):
            return None
        return self.mean_diff / abs(self.mean_golden)


@dataclass
class Report:
    passed: bool
    rmse: float
    relmse: float
    bias: float
    bias_se: float
    max_abs_z: float
    critical_z: float
    n_tests: int
    worst_block: BlockResult | None
    nan_count: int
    inf_count: int
    # context for the student-facing text
    width: int = 0
    height: int = 0
    test_spp: float = 0
    golden_spp: float = 0
    alpha: float = 0.0
    block_sizes: tuple = ()
    global_z: tuple = ()
    mean_golden: float = 0.0
    n_failed: int = 0
    failures: list = field(default_factory=list)  # the worst MAX_LISTED_FAILURES Failures
    first_nonfinite: tuple | None = None          # (x, y) of the first NaN/Inf pixel
    heatmap_path: str | None = None
    z_maps: dict = field(default_factory=dict, repr=False)  # block size -> (by, bx, C) z
    chi_mean: float | None = None    # mean of min(d^2/s2, CHI_CAP) over channels with s2 > 0
    chi_median: float | None = None  # its median (None: too few values, test skipped)

    def noise_problem(self) -> str | None:
        """Why the per-pixel noise is not a correct render's, or None."""
        if self.chi_mean is None:
            return None
        if not (self.chi_median >= CHI_MEDIAN_MIN):
            return (f"too smooth: the median per-pixel d^2/sigma^2 is {self.chi_median:.3f} "
                    f"(a render gives ~0.455, allowed >= {CHI_MEDIAN_MIN:g}): an image blurred, "
                    f"flattened or denoised, not a render at the asked paths")
        if not (self.chi_mean <= CHI_MEAN_MAX):
            return (f"too noisy: per-pixel d^2/sigma^2 averages {self.chi_mean:.2f} (a render "
                    f"with the asked paths gives ~1, allowed <= {CHI_MEAN_MAX:g}): fewer paths "
                    f"than asked, or pixels wrong in ways block means hide")
        return None

    def summary(self) -> str:
        """One line: verdict, worst test, and the headline numbers."""
        verdict = "PASS" if self.passed else "FAIL"
        parts = [verdict + ":"]
        if self.nan_count or self.inf_count:
            parts.append(f"{self.nan_count} NaN and {self.inf_count} Inf pixels;")
        if self.passed:
            parts.append(
                f"max |z| {self.max_abs_z:.2f} <= {self.critical_z:.2f} over {self.n_tests} tests;"
            )
        elif self.n_failed:
            worst = self.failures[0]
            rel = worst.relative_diff()
            rel_s = f", {rel * 100:+.1f}%" if rel is not None else ""
            channel = CHANNEL_NAMES[worst.channel] if worst.channel < 3 else worst.channel
            parts.append(
                f"{self.n_failed} of {self.n_tests} tests beyond |z| {self.critical_z:.2f};"
                f" worst {worst.where()} {channel}"
                f" z={_fmt_z(worst.z)}{rel_s};"
            )
        parts.append(f"RMSE {self.rmse:.4g}, relMSE {self.relmse:.4g},"
                     f" bias {self.bias:+.3g} +- {self.bias_se:.2g}")
        noise = self.noise_problem()
        if noise:
            parts.append(f"; {noise}")
        elif self.chi_mean is not None:
            parts.append(f"; per-pixel d^2/sigma^2 mean {self.chi_mean:.2f}, median "
                         f"{self.chi_median:.3f}")
        return " ".join(parts)

    def table(self) -> str:
        """A multi-line report a student can read: what failed, where, how badly."""
        L = []
        L.append(f"Image comparison: {'PASS' if self.passed else 'FAIL'}")
        L.append(f"  image {self.width}x{self.height}, render {_fmt_num(self.test_spp)} spp vs"
                 f" golden {_fmt_num(self.golden_spp)} spp")
        sizes = ", ".join(f"{b}x{b}" for b in self.block_sizes) or "none"
        L.append(f"  {self.n_tests} z-tests (blocks {sizes}, global mean; R G B);"
                 f" alpha {self.alpha:g} -> fail if |z| > {self.critical_z:.3f}")
        nonfinite = f"  NaN pixels {self.nan_count}, Inf pixels {self.inf_count}"
        if self.first_nonfinite is not None:
            nonfinite += (f"   <- FAIL: first at x={self.first_nonfinite[0]},"
                          f" y={self.first_nonfinite[1]} (y from the top row)")
        L.append(nonfinite)
        L.append(f"  RMSE   {self.rmse:.6g}")
        L.append(f"  relMSE {self.relmse:.6g}")
        bias_line = (
            f"  bias   {self.bias:+.6g} +- {self.bias_se:.3g} (render - golden, mean over pixels)"
        )
        if self.mean_golden > 0:
            bias_line += f" = {self.bias / self.mean_golden * 100:+.2f}% of the mean golden value"
        L.append(bias_line)
        if self.chi_mean is not None:
            L.append(
                f"  per-pixel d^2/sigma^2: mean {self.chi_mean:.3f} (allowed <= {CHI_MEAN_MAX:g}),"
                f" median {self.chi_median:.3f} (allowed >= {CHI_MEDIAN_MIN:g})"
                + ("" if self.noise_problem() is None else "   <- FAIL")
            )
        gz = "  ".join(
            f"{CHANNEL_NAMES[c] if c < 3 else c} {_fmt_z(z)}" for c, z in enumerate(self.global_z)
        )
        L.append(f"  global mean z: {gz}")
        if self.worst_block is not None:
            w = self.worst_block
            channel = CHANNEL_NAMES[w.channel] if w.channel < 3 else w.channel
            L.append(
                f"  worst block: {w.block_size}x{w.block_size} at x={w.x0}, y={w.y0},"
                f" channel {channel}, z {_fmt_z(w.z)}"
                f" (limit +-{self.critical_z:.2f})"
            )
        if self.n_failed:
            shown = len(self.failures)
            L.append(f"  failing tests: {self.n_failed}"
                     + (f" (the worst {shown} listed)" if shown < self.n_failed else ""))
            L.append(f"    {'where':<40} {'ch':>2} {'z':>9} {'mean diff':>11} {'relative':>9}")
            for f in self.failures:
                rel = f.relative_diff()
                rel_s = f"{rel * 100:+8.1f}%" if rel is not None else f"{'-':>9}"
                ch = CHANNEL_NAMES[f.channel] if f.channel < 3 else str(f.channel)
                L.append(
                    f"    {f.where():<40} {ch:>2} {_fmt_z(f.z):>9} {f.mean_diff:>+11.4g} {rel_s}"
                )
        if not self.passed:
            L.extend("  " + h for h in self._hints())
        if self.heatmap_path:
            L.append(f"  heatmap of per-block |z| (blue 0, white at the limit, red >= 2x the limit;"
                     f" black NaN/Inf; green box worst block): {self.heatmap_path}")
        return "\n".join(L)

    def _hints(self) -> list[str]:
        hints = []
        if self.nan_count or self.inf_count:
            hints.append("hint: NaN/Inf usually come from 0/0 or x/0: a zero pdf, normalising a"
                         " zero-length vector, or sqrt/log of a negative number.")
        global_fail = [f for f in self.failures if f.block_size == 0]
        if global_fail:
            direction = "bright" if global_fail[0].z > 0 else "dark"
            hints.append(f"hint: the whole image is too {direction} on average: look for a global"
                         " factor (normalisation, pdf, missing or doubled light, gamma/clamping).")
        elif self.failures:
            direction = "bright" if self.failures[0].z > 0 else "dark"
            hints.append(f"hint: the error is local (worst region too {direction}): look at what"
                         " the scene shows there (a light, a material, an edge, a shadow).")
        if any(math.isinf(f.z) for f in self.failures):
            hints.append("hint: z = inf means the golden image is noise-free there (zero variance),"
                         " so the render must match it exactly.")
        return hints


def _fmt_z(z: float) -> str:
    if math.isinf(z):
        return "+inf" if z > 0 else "-inf"
    return f"{z:+.2f}"


def _fmt_num(x: float) -> str:
    return str(int(x)) if float(x).is_integer() else f"{x:g}"


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
