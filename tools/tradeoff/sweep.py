"""Error against samples per pixel (and time) for one renderer on one scene.

Each point is one render at n spp from its own seed, compared by labkit/compare.py with a
converged reference of N >= 16 n paths from other seeds: RMSE, relMSE, bias +- its standard
error, NaN/Inf counts, whether the noise-aware z tests pass. The reference's own noise adds
mean(sigma^2)/N to the measured MSE; `mse` subtracts it, so that for an unbiased renderer
mse = mean(sigma^2)/n exactly in expectation and the log-log slope is -1/2 at every n
(tools/tradeoff/fit.py). Efficiency is 1 / (mse x seconds): the higher, the less time a
given error costs.

Time is the `seconds` of the binary's --json summary: render only, no scene loading or file
writing (GPU: kernel time by CUDA events). `wall` is the whole process as the harness saw it.
"""
from __future__ import annotations

import dataclasses
import math
import pathlib

from labkit.compare import compare
from labkit.harness import run_lab
from tools.tradeoff import fit as tradeoff_fit
from tools.tradeoff.reference import Reference
from tools.tradeoff.series import first_words

ROOT = pathlib.Path(__file__).resolve().parents[2]

SWEEP_SEED = 100  # + log2(spp): each point its own seed, none of the reference's


@dataclasses.dataclass
class Point:
    series: str
    scene: str
    spp: int
    seconds: float
    wall: float
    rmse: float
    relmse: float
    bias: float
    bias_se: float
    nan: int
    inf: int
    z_pass: bool       # labkit/compare.py's verdict against the reference
    mse: float         # RMSE^2 minus the reference's own noise (may be <= 0 when tiny)
    efficiency: float  # 1 / (mse * seconds)


@dataclasses.dataclass
class Sweep:
    series: str
    scene: str
    checked: bool
    points: list
    fit: tradeoff_fit.Fit | None = None
    plateau: float | None = None
    problem: str | None = None  # why there is no fit

    @property
    def failed(self) -> str | None:
        """Why this sweep fails its check, or None (only checked sweeps can fail)."""
        if not self.checked:
            return None
        if self.problem:
            return f"{self.series} on {self.scene}: {self.problem}"
        nonfinite = sum(p.nan + p.inf for p in self.points)
        if nonfinite:
            return f"{self.series} on {self.scene}: {nonfinite} NaN/Inf pixels"
        if not tradeoff_fit.slope_ok(self.fit) or self.plateau is not None:
            return f"{self.series} on {self.scene}: " + tradeoff_fit.describe(
                self.fit, self.plateau
            )
        return None


def spp_list(largest: int) -> list[int]:
    return [1 << k for k in range(largest.bit_length()) if 1 << k <= largest]


def render_point(series, scene_name: str, scene_path: pathlib.Path, ref: Reference, n: int, *,
                 width: int, height: int, bounces: int, log=print) -> Point:
    """One render of `series` (tradeoff_series.Series) at n spp, compared with `ref`."""
    if ref.spp < 16 * n:
        raise ValueError(f"the reference has {ref.spp} spp, fewer than 16 x {n}")
    run = run_lab(series.binary, scene_path, width=width, height=height, spp=n,
                  bounces=bounces, seed=SWEEP_SEED + n.bit_length(),
                  launcher=series.launcher, check=False)
    if run.returncode != 0 or run.image is None or run.json is None:
        raise RuntimeError(f"{series.name} on {scene_name} at {n} spp failed: "
                           f"{first_words(run.stderr)}")
    r = compare(run.image, n, ref.mean, ref.variance, ref.spp)
    mse = r.rmse ** 2 - ref.noise_mse()
    seconds = float(run.json["seconds"])
    eff = 1.0 / (mse * seconds) if mse > 0 and seconds > 0 else math.nan
    log(f"  {series.name:<20} {scene_name:<8} {n:>5} spp {seconds:>8.4f} s  RMSE {r.rmse:.5f}"
        f"  bias {r.bias:+.5f} +- {r.bias_se:.5f}{'' if r.passed else '  z-test FAIL'}")
    return Point(series.name, scene_name, n, seconds, run.wall_seconds, r.rmse, r.relmse,
                 r.bias, r.bias_se, r.nan_count, r.inf_count, r.passed, mse, eff)


def fitted(series, scene_name: str, points: list) -> Sweep:
    """The sweep of one renderer with its slope fit and plateau."""
    result = Sweep(series.name, scene_name, series.checked, points)
    usable = [p for p in points if p.mse > 0 and math.isfinite(p.mse)]
    if len(usable) < 2:
        result.problem = f"only {len(usable)} of {len(points)} points have a usable error"
        return result
    if len(usable) < 0.75 * len(points):  # a point or two below the reference's noise is fine
        result.problem = (f"{len(points) - len(usable)} of {len(points)} points have no usable "
                          "error (NaN, or below the reference's own noise)")
    x = [p.spp for p in usable]
    y = [math.sqrt(p.mse) for p in usable]
    result.fit = tradeoff_fit.fit_loglog(x, y)
    result.plateau = tradeoff_fit.find_plateau(x, y)
    return result


def sweep_all(series_list, scene_name: str, scene_path: pathlib.Path, ref: Reference, *,
              width: int, height: int, bounces: int, spps, log=print):
    """Every renderer at every spp, interleaved (each spp: every renderer in turn), so that a
    shared machine's load, which drifts over minutes, slows all of them alike rather than
    whichever ran during a busy spell. Returns (sweeps, {renderer name: why it failed})."""
    points = {s.name: [] for s in series_list}
    failed = {}
    for n in spps:
        for s in series_list:
            if s.name in failed:
                continue
            try:
                points[s.name].append(render_point(s, scene_name, scene_path, ref, n,
                                                   width=width, height=height,
                                                   bounces=bounces, log=log))
            except RuntimeError as e:  # one renderer failing must not hide the others' rows
                log(f"  {e}")
                failed[s.name] = str(e)
    sweeps = [fitted(s, scene_name, points[s.name]) for s in series_list if s.name not in failed]
    return sweeps, failed
