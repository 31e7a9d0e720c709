"""Converged references for `make tradeoff`: the mean of many paths per pixel, with each
pixel's per-path variance, from seeds no sweep uses.

Rendered as `chunks` independent renders (seeds REFERENCE_SEED, +1, ...): their mean is the
reference and the spread of the chunk means gives the per-path variance (variance of a chunk
mean x paths per chunk), which labkit/compare.py needs for its z tests and bias standard
error, and which the sweep uses to take the reference's own noise out of the MSE.
Renders are cached under build/tradeoff/cache, keyed by the binary's and the scene's bytes
and the settings, so a second run of the tool does not render them again.
"""
from __future__ import annotations

import dataclasses
import hashlib
import json
import pathlib

import numpy as np

from labkit.harness import golden, run_lab

ROOT = pathlib.Path(__file__).resolve().parents[2]

CACHE = ROOT / "build" / "tradeoff" / "cache"
# Sweeps use seeds below 1e5; tools/make_golden.py uses 1 000 000 and up.
REFERENCE_SEED = 2_000_000


@dataclasses.dataclass
class Reference:
    mean: np.ndarray      # (H, W, 3) float64
    variance: np.ndarray  # (H, W, 3) per-path variance
    spp: int              # paths per pixel in `mean`
    made_by: str          # which binary, how many renders, which seeds

    def noise_mse(self) -> float:
        """The reference's own contribution to a measured MSE: mean sigma^2 / N."""
        return float(self.variance.mean()) / self.spp


def from_golden(name: str) -> Reference:
    """The golden data in reference/golden/<name> (tools/make_golden.py)."""
    g = golden(name)
    return Reference(g.mean.astype(np.float64), g.variance.astype(np.float64),
                     int(g.meta["golden_spp"]),
                     f"reference/golden/{name} ({g.meta['golden_spp']} spp, "
                     f"{g.meta['made_by']}, seeds from {g.meta['seeds'][0]})")


def _key(binary: pathlib.Path, scene: pathlib.Path, settings: dict) -> str:
    h = hashlib.sha256()
    h.update(pathlib.Path(binary).read_bytes())
    h.update(pathlib.Path(scene).read_bytes())
    h.update(json.dumps(settings, sort_keys=True).encode())
    return h.hexdigest()[:24]


def render(binary: pathlib.Path, scene: pathlib.Path, *, width: int, height: int,
           bounces: int, spp: int, chunks: int = 16, launcher=(), threads=None,
           log=print) -> Reference:
    """A converged reference of `spp` paths per pixel made of `chunks` renders."""
    if spp % chunks or chunks < 2:
        raise ValueError(f"reference: {spp} spp do not split into {chunks} >= 2 equal renders")
    per = spp // chunks
    settings = dict(width=width, height=height, bounces=bounces, spp=per, chunks=chunks,
                    seed=REFERENCE_SEED)
    made_by = (f"{pathlib.Path(binary).name}, {chunks} renders x {per} spp, seeds "
               f"{REFERENCE_SEED}..{REFERENCE_SEED + chunks - 1}")
    cached = CACHE / f"{_key(binary, scene, settings)}.npz"
    if cached.exists():
        data = np.load(cached)
        return Reference(data["mean"], data["variance"], spp, made_by + " (cached)")
    log(f"  reference: {made_by}, {width}x{height}, {bounces} bounces ...")
    images = np.stack([
        run_lab(binary, scene, width=width, height=height, spp=per, bounces=bounces,
                seed=REFERENCE_SEED + k, launcher=launcher, threads=threads).image
        .astype(np.float64) for k in range(chunks)])
    mean = images.mean(axis=0)
    variance = images.var(axis=0, ddof=1) * per
    CACHE.mkdir(parents=True, exist_ok=True)
    np.savez(cached, mean=mean, variance=variance)
    return Reference(mean, variance, spp, made_by)
