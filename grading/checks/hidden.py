"""A hidden scene: the golden scenes' images are in the repository, so a submission could
recognise a golden render and print the stored image. A hidden scene is made at grading time
from a secret (a random one per grade unless the instructor fixes it to regrade), its golden
data rendered there and then by the trusted lab-01 reference, so there is nothing to copy.

The scene is the Cornell box with its light moved and dimmed or brightened, its camera nudged,
its colours changed and a glass and a mirror ball added, all drawn from the secret. Its golden
data follow tools/make_golden.py (K renders with distinct seeds: their mean, and their spread
times n as the variance of one path), only smaller, so that it takes about a second on two
cores; with K = 32 estimated variances, labkit/compare.py's false-failure bound grows by about
1.1x.
"""
from __future__ import annotations

import concurrent.futures
import dataclasses
import hashlib
import os
import pathlib
import secrets
import tempfile

import numpy as np

from grading.checks import symptoms
from grading.checks.check_result import CheckResult, image_checked
from grading.checks.lanes import lanes_not_lab01
from labkit import scenes
from labkit.compare import GRADING_ALPHA, compare
from labkit.harness import RunPolicy, available_cores, policy, run_lab

SIZE = 32          # pixels a side
BOUNCES = 4
RENDERS = 32       # K
SPP_PER_RENDER = 64  # n
TEST_SPP = 64
# 4x4 blocks as well: the panel and the triangle cover a few pixels each, which 8x8 blocks
# dilute; pooled variance keeps small blocks over 32 renders' golden data honest
# (labkit/compare.py, "Small blocks and pooled variance").
BLOCK_SIZES = (4, 8, 16)
# A failed render is rendered once more with another seed, and the scene fails only when both
# do. The glass ball's caustics (light seen through glass from a diffuse wall, which no light
# sample reaches) put a rare bright path in some 4x4 block now and then, further in the tail
# than the normal model and 32 golden renders allow, so that a correct hand-in can fail
# (grading/README.md). A second failure of the same size is that chance squared; a wrong
# renderer is as wrong under any seed, and a right image must still be rendered to pass.
TEST_SEEDS = (7, 8)


def new_secret() -> str:
    return secrets.token_hex(16)


def hidden_scene(secret: str) -> dict:
    """The Cornell box varied by `secret`: the same secret, the same scene."""
    rng = np.random.default_rng(
        int.from_bytes(hashlib.sha256(secret.encode()).digest()[:8], "little")
    )
    s = scenes.load("cornell")
    s.pop("render", None)
    light = s["light"]
    light["position"] = [float(np.clip(c + rng.uniform(-0.25, 0.25), 0.1, 0.95))
                         for c in light["position"]]
    light["intensity"] = [c * float(rng.uniform(0.6, 1.6)) for c in light["intensity"]]
    cam = s["camera"]
    cam["position"] = [c + float(rng.uniform(-0.08, 0.08)) for c in cam["position"]]
    cam["vfov"] = float(cam["vfov"] * rng.uniform(0.9, 1.1))
    for m in s["materials"].values():
        if m.get("type") == "diffuse":
            m["albedo"] = [
                float(np.clip(a * rng.uniform(0.6, 1.4), 0.02, 0.9)) for a in m["albedo"]
            ]
    # A glass ball and a mirror ball at drawn places, sizes and (for glass) index: a renderer
    # without glass or mirrors cannot pass here by printing the stored showcase image.
    s["materials"]["clear"] = {"type": "glass", "ior": float(rng.uniform(1.3, 1.8))}
    s["materials"]["polished"] = {"type": "mirror",
                                  "albedo": [float(rng.uniform(0.6, 0.95))] * 3}
    glass_r, mirror_r = float(rng.uniform(0.1, 0.16)), float(rng.uniform(0.08, 0.13))
    s["spheres"] = s.get("spheres", []) + [
        {"center": [float(rng.uniform(0.17, 0.3)), glass_r, float(rng.uniform(-0.7, -0.5))],
         "radius": glass_r, "material": "clear"},
        {"center": [float(rng.uniform(0.7, 0.85)), mirror_r, float(rng.uniform(-0.75, -0.6))],
         "radius": mirror_r, "material": "polished"}]
    # A panel turned at a drawn angle to the walls (a convex quad, not a rectangle) and a
    # tilted triangle: every primitive kind is traced here, so a renderer that skips one of
    # them fails (the Cornell box alone holds only a sphere and rectangles).
    # Much darker than the walls behind them (0.15 to 0.45 of the white walls' albedo,
    # channel by channel): a renderer that misses the panel or the triangle shows the bright
    # back wall there. Drawn freely, the panel's colour could match the wall's, and a missing
    # panel then changed too little to see.
    s["materials"]["panel"] = {"type": "diffuse", "albedo": [
        float(a * rng.uniform(0.15, 0.45)) for a in s["materials"]["white"]["albedo"]]}
    angle = float(rng.uniform(np.radians(25), np.radians(65)))
    # Above the box's ball, left of the triangle, in front of the back wall: in view.
    cx, cz, half, height = float(rng.uniform(0.3, 0.4)), float(rng.uniform(-0.9, -0.85)), \
        0.1, float(rng.uniform(0.28, 0.38))
    dx, dz = half * np.cos(angle), half * np.sin(angle)
    s["quads"] = s.get("quads", []) + [{"vertices": [
        [cx - dx, 0.45, cz - dz], [cx + dx, 0.45, cz + dz],
        [cx + dx, 0.45 + height, cz + dz], [cx - dx, 0.45 + height, cz - dz]],
        "material": "panel"}]
    s["triangles"] = s.get("triangles", []) + [{"vertices": [
        [0.52 + float(rng.uniform(-0.03, 0.03)), 0.38, -0.6],
        [0.75, 0.53 + float(rng.uniform(-0.03, 0.03)), -0.67],
        [0.6, 0.75, -0.52 + float(rng.uniform(-0.03, 0.03))]], "material": "panel"}]
    return s


@dataclasses.dataclass
class HiddenGolden:
    scene: pathlib.Path
    mean: np.ndarray
    variance: np.ndarray
    golden_spp: int


def make_golden(reference, scene_path: pathlib.Path, size: int = SIZE,
                bounces: int = BOUNCES) -> HiddenGolden:
    """Golden data of a scene made at grading time (the hidden scene; the timed renders' drawn
    scene, at its size) from the trusted reference (outside the sandbox)."""
    seeds = range(2_000_000, 2_000_000 + RENDERS)
    with policy(RunPolicy(trusted=True)), \
            concurrent.futures.ThreadPoolExecutor(max(1, available_cores())) as pool:
        images = list(pool.map(
            lambda seed: run_lab(reference, scene_path, width=size, height=size, bounces=bounces,
                                 spp=SPP_PER_RENDER, seed=seed, threads=1).image, seeds))
    stack = np.stack([i.astype(np.float64) for i in images])
    return HiddenGolden(scene_path, stack.mean(axis=0).astype(np.float32),
                        (stack.var(axis=0, ddof=1) * SPP_PER_RENDER).astype(np.float32),
                        RENDERS * SPP_PER_RENDER)


def check_hidden(binary, reference, secret: str, *, launcher=(), threads=None,
                 heatmap_dir: pathlib.Path | None = None):
    """The submission's render of the hidden scene against golden data made just now."""
    @image_checked("hidden scene")
    def run() -> CheckResult:
        with tempfile.TemporaryDirectory() as tmp:
            path = scenes.write_scene(pathlib.Path(tmp) / "scene.json", hidden_scene(secret))
            g = make_golden(reference, path)
            heatmap = heatmap_dir / "hidden-diff.png" if heatmap_dir else None
            for seed in TEST_SEEDS:
                image = run_lab(binary, path, width=SIZE, height=SIZE, bounces=BOUNCES,
                                spp=TEST_SPP, seed=seed, launcher=launcher, threads=threads).image
                report = compare(image, TEST_SPP, g.mean, g.variance, g.golden_spp,
                                 heatmap_path=heatmap, block_sizes=BLOCK_SIZES,
                                 pooled_variance=True, alpha=GRADING_ALPHA)
                if report.passed:
                    break
        hint = "" if report.passed else symptoms.named(image, g.mean)
        cause = "" if report.passed else lanes_not_lab01(binary, launcher=launcher,
                                                         threads=threads)
        return CheckResult("hidden scene", report.passed,
                           (f"{cause}; " if cause else "") + report.summary() + hint)
    return run()


def secret_from_environment() -> str:
    """GRADING_SECRET fixes the hidden scene (to regrade a batch alike); else a new one."""
    return os.environ.get("GRADING_SECRET") or new_secret()
