"""Bias against bounces, measured and checked against a closed form.

The scene: camera at the centre of a diffuse sphere (albedo rho, radius R), a point light of
intensity I inside it, off the centre (tools/tradeoff/scenes.py). Two facts about a sphere's
inside make the answer exact wherever the light is:
- Every bit of the light's flux lands on the wall, so the wall's mean irradiance is
  4 pi I / (4 pi R^2) and its mean directly lit radiance is <L1> = rho I / (pi R^2).
- A cosine-distributed ray leaving any wall point lands at a point *uniformly* distributed
  over the wall (cos_x cos_y / (pi r^2) = 1 / (4 pi R^2) on a sphere, r = 2 R cos).
So, with next-event estimation at every interaction, interaction k >= 2 of a path adds
rho^(k-1) <L1> in expectation, whatever the wall point the camera sees. A render with B
bounces (B interactions) misses, in every pixel,

    L_inf - L_B = <L1> (rho^B + rho^(B+1) + ...) = <L1> rho^B / (1 - rho),

the "energy missing after B bounces" that falls as rho^B. We measure it against a reference
with B_ref bounces and 16x the paths, from other seeds: the expected difference is
<L1> (rho^B_ref - rho^B) / (1 - rho) in every pixel, exactly (no integral over pixels).

The pixels are independent and share that expectation, so the mean of the per-pixel
differences estimates it with standard error sd(differences) / sqrt(pixels). The check
passes when every |measured - closed form| <= c * SE + ROUNDING * L_ref, c being the
two-sided Bonferroni limit for ALPHA over all bounce counts (so a correct renderer fails at
most once in 1/ALPHA runs; 3 SE each over 16 bounce counts would fail ~4% of correct runs).
"""
from __future__ import annotations

import dataclasses
import math
import pathlib

import numpy as np

from labkit.compare import critical_z
from labkit.harness import run_lab
from tools.tradeoff import reference as tradeoff_reference
from tools.tradeoff.series import first_words

ROOT = pathlib.Path(__file__).resolve().parents[2]

ALPHA = 1e-4
# Float rounding of a path's value: the zero-variance interior of grading/checks/analytic.py differs
# from its closed form by ~1e-5 relative; 1e-4 of the converged radiance leaves a margin.
ROUNDING = 1e-4
SWEEP_SEED = 3000  # + bounces: every bounce count its own seed, none the reference's


def mean_direct(albedo: float, radius: float, intensity: float) -> float:
    """<L1>: the wall's mean directly lit radiance."""
    return albedo * intensity / (math.pi * radius ** 2)


def closed_form(bounces: int, ref_bounces: int, albedo: float, radius: float,
                intensity: float) -> float:
    """Expected E[render with `bounces`] - E[render with `ref_bounces`], every pixel."""
    return (mean_direct(albedo, radius, intensity)
            * (albedo ** ref_bounces - albedo ** bounces) / (1.0 - albedo))


@dataclasses.dataclass
class BiasPoint:
    series: str
    bounces: int
    spp: int
    bias: float         # measured mean of render - reference
    se: float           # its standard error
    closed: float       # the closed form
    allowed: float      # c * se + ROUNDING * converged radiance
    seconds: float      # the render's own `seconds`
    nonfinite: int      # NaN/Inf channel values in the render

    @property
    def ok(self) -> bool:
        return self.nonfinite == 0 and abs(self.bias - self.closed) <= self.allowed

    @property
    def z(self) -> float:
        return (self.bias - self.closed) / self.se if self.se > 0 else math.inf


def sweep(series: str, binary, reference_binary, scene_path: pathlib.Path, interior: dict, *,
          bounces, size: int, spp: int, ref_bounces: int, ref_threads=None,
          launcher=(), threads=None, log=print) -> list[BiasPoint]:
    """Renders the interior at each bounce count (size x size pixels, `spp` each) with
    `binary`, and once with `ref_bounces` and 16 x spp with `reference_binary`."""
    ref = tradeoff_reference.render(reference_binary, scene_path, width=size, height=size,
                                    bounces=ref_bounces, spp=16 * spp, threads=ref_threads,
                                    log=log)
    ref_grey = ref.mean.mean(axis=2)  # albedo and light are grey: R = G = B
    c = critical_z(ALPHA, len(bounces))
    params = {k: interior[k] for k in ("albedo", "radius", "intensity")}
    points = []
    for b in bounces:
        run = run_lab(binary, scene_path, width=size, height=size, spp=spp, bounces=b,
                      seed=SWEEP_SEED + b, launcher=launcher, threads=threads, check=False)
        if run.image is None or run.returncode != 0:
            raise RuntimeError(f"{series} at {b} bounces did not render: "
                               f"{first_words(run.stderr)}")
        image = run.image.astype(np.float64)
        finite = np.isfinite(image).all(axis=2)
        d = image.mean(axis=2)[finite] - ref_grey[finite]
        se = float(d.std(ddof=1) / math.sqrt(d.size)) if d.size > 1 else math.inf
        # The reference's own variance is inside sd(d): d = render - reference per pixel.
        points.append(BiasPoint(
            series, b, spp, float(d.mean()) if d.size else math.nan, se,
            closed_form(b, ref_bounces, **params),
            c * se + ROUNDING * float(ref_grey.mean()),
            float(run.json["seconds"]) if run.json else math.nan,
            int((~np.isfinite(image)).sum())))
        log(f"  {series:<24} {b:>2} bounces: bias {points[-1].bias:+.5f} +- {se:.5f}, "
            f"closed form {points[-1].closed:+.5f} ({points[-1].z:+.1f} SE)")
    return points


def failures(points: list[BiasPoint]) -> list[str]:
    """One phrase per bounce count that misses the closed form."""
    out = []
    for p in points:
        if p.ok:
            continue
        why = (f"{p.nonfinite} NaN/Inf values" if p.nonfinite else
               f"bias {p.bias:+.5f} vs closed form {p.closed:+.5f} "
               f"({p.z:+.1f} SE, allowed {p.allowed:.5f})")
        out.append(f"{p.series} at {p.bounces} bounces: {why}")
    return out
