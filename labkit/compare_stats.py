"""The normal distribution and the Bonferroni limit the image comparison tests at
(labkit/compare.py's docstring says why), and the false-failure bound of an estimated
variance."""
from __future__ import annotations

import math
from typing import Sequence


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
