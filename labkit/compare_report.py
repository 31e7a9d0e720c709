"""What an image comparison found, in words and numbers: every block and failure, the
summary line the grader prints, the hints that point at a cause."""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import NamedTuple

CHANNEL_NAMES = ("R", "G", "B")
# The grader's family-wise false-failure bound (labkit/compare.py's docstring, "The
# grader's alpha").
GRADING_ALPHA = 1e-5
# The per-pixel test (labkit/compare.py's docstring): a correct render gives a mean d^2/s2
# of about 1 and a median of about 0.455.
CHI_MEAN_MAX = 1.5
CHI_MEDIAN_MIN = 0.25
CHI_CAP = 16.0  # each value's cap in the mean: one underestimated variance must not decide
CHI_MIN_VALUES = 256
MAX_LISTED_FAILURES = 20


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
