"""The convergence checks of `make tradeoff`: a log-log slope fit and plateau detection.

An unbiased Monte Carlo estimator averaging n independent samples has MSE = sigma^2 / n
exactly (not only asymptotically), so log RMSE against log spp is a line of slope -1/2 at
every n. A biased one converges to MSE = bias^2: the error flattens into a plateau. Pure
functions of numbers, so the tests can feed them made-up series that must fail.
"""
from __future__ import annotations

import dataclasses
import math
from typing import Sequence

# What `make tradeoff` requires of an unbiased renderer: slope -1/2 +- 0.05. The fitted
# slope's own standard error on the default sweeps is ~0.005 (reported with it), so a
# correct renderer lands well inside the band and a bias or correlated samples fall outside.
WANT_SLOPE = -0.5
SLOPE_TOLERANCE = 0.05
# A window of points whose local slope is flatter than this (half the expected fall) is a
# plateau: the error has stopped following 1/sqrt(spp).
PLATEAU_SLOPE = -0.25
PLATEAU_WINDOW = 3


@dataclasses.dataclass(frozen=True)
class Fit:
    slope: float
    intercept: float  # natural log of the error at x = 1
    slope_se: float   # ordinary least-squares standard error (0 with two points)
    points: int


def fit_loglog(x: Sequence[float], y: Sequence[float]) -> Fit:
    """Least-squares line through (ln x, ln y). Needs at least two points with distinct x,
    all positive; raises ValueError otherwise (the caller says which series)."""
    if len(x) != len(y):
        raise ValueError(f"{len(x)} x values but {len(y)} y values")
    if len(x) < 2:
        raise ValueError(f"a slope needs at least 2 points, got {len(x)}")
    if any(not (v > 0 and math.isfinite(v)) for v in (*x, *y)):
        raise ValueError("a log-log fit needs positive, finite values")
    lx = [math.log(v) for v in x]
    ly = [math.log(v) for v in y]
    n = len(lx)
    mx, my = sum(lx) / n, sum(ly) / n
    sxx = sum((a - mx) ** 2 for a in lx)
    if sxx == 0:
        raise ValueError("a slope needs at least two distinct x values")
    slope = sum((a - mx) * (b - my) for a, b in zip(lx, ly)) / sxx
    intercept = my - slope * mx
    if n > 2:
        residual = sum((b - intercept - slope * a) ** 2 for a, b in zip(lx, ly))
        slope_se = math.sqrt(residual / (n - 2) / sxx)
    else:
        slope_se = 0.0
    return Fit(slope, intercept, slope_se, n)


def slope_ok(fit: Fit, want: float = WANT_SLOPE, tolerance: float = SLOPE_TOLERANCE) -> bool:
    return abs(fit.slope - want) <= tolerance


def find_plateau(x: Sequence[float], y: Sequence[float], window: int = PLATEAU_WINDOW,
                 flat: float = PLATEAU_SLOPE) -> float | None:
    """The x from which the error stops falling, or None: the start of the earliest window of
    `window` consecutive points such that it and every later window have a local log-log
    slope flatter than `flat`. Only the tail counts, so one noisy dip early on is no plateau."""
    if len(x) < window:
        return None
    start = None
    for i in range(len(x) - window + 1):
        local = fit_loglog(x[i:i + window], y[i:i + window]).slope
        if local > flat:
            if start is None:
                start = x[i]
        else:
            start = None
    return start


def describe(fit: Fit, plateau: float | None) -> str:
    """e.g. 'slope -0.502 +- 0.004 (want -0.5 +- 0.05); plateau from 512 spp'."""
    text = (f"slope {fit.slope:+.3f} +- {fit.slope_se:.3f} over {fit.points} points "
            f"(want {WANT_SLOPE:+.1f} +- {SLOPE_TOLERANCE:g})")
    if plateau is not None:
        text += f"; plateau from {plateau:g} spp"
    return text
