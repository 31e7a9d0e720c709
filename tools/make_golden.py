"""Regenerate the golden data in reference/golden/: for each scene, a converged mean image
and the per-pixel variance of one path, both from the lab-01 reference.

The variance comes from K independent renders of n spp each (distinct seeds): the spread of
their means, times n, estimates the variance of a single path at every pixel. The mean of
all K*n paths is the golden image. Tests then know, per pixel, how noisy a render of any spp
should be (see labkit/compare.py).

    make golden          all scenes (a few minutes on two cores)
    python3 -m tools.make_golden --scene cornell
"""
import argparse
import concurrent.futures
import datetime
import json
import os
import pathlib
import platform
import sys
import tempfile

import numpy as np

from grading.checks import golden_sums
from labkit.harness import run_lab
from labkit.pfm import write_pfm

ROOT = pathlib.Path(__file__).resolve().parent.parent

# Golden scenes and the settings tests render them at. Small on purpose: the files stay
# small (64x64x3 float32 = 48 KiB each) and a test render takes well under a second.
GOLDEN_SCENES = {
    "cornell": {"width": 64, "height": 64, "bounces": 4},
    "showcase": {"width": 64, "height": 64, "bounces": 8},
}
RENDERS = 64         # K: independent renders per scene
SPP_PER_RENDER = 256  # n: paths per pixel in each
FIRST_SEED = 1_000_000  # far from the seeds tests use


def make_golden(scene: str, binary: pathlib.Path) -> None:
    settings = GOLDEN_SCENES[scene]
    scene_path = ROOT / "common" / "scenes" / f"{scene}.json"
    seeds = range(FIRST_SEED, FIRST_SEED + RENDERS)
    workers = max(1, len(os.sched_getaffinity(0)))
    with concurrent.futures.ThreadPoolExecutor(workers) as pool:
        runs = list(pool.map(lambda seed: run_lab(binary, scene=scene_path, spp=SPP_PER_RENDER,
                                                  seed=seed, **settings), seeds))
    images = np.stack([r.image.astype(np.float64) for r in runs])
    mean = images.mean(axis=0)
    path_variance = images.var(axis=0, ddof=1) * SPP_PER_RENDER
    out = ROOT / "reference" / "golden" / scene
    out.mkdir(parents=True, exist_ok=True)
    write_pfm(out / "golden.pfm", mean.astype(np.float32))
    write_pfm(out / "variance.pfm", path_variance.astype(np.float32))
    meta = {
        "scene": f"common/scenes/{scene}.json",
        **settings,
        "golden_spp": RENDERS * SPP_PER_RENDER,
        "renders": RENDERS,
        "spp_per_render": SPP_PER_RENDER,
        "seeds": [seeds.start, seeds.stop - 1],
        "made_by": runs[0].json["lab"] + " reference",
        "device": runs[0].json["device"],
        "date": datetime.date.today().isoformat(),
        "host": platform.node(),
    }
    with tempfile.NamedTemporaryFile("w", dir=out, delete=False) as f:
        json.dump(meta, f, indent=2)
        f.write("\n")
    os.replace(f.name, out / "meta.json")
    print(f"{scene}: {meta['golden_spp']} paths/pixel at {settings['width']}x{settings['height']}"
          f" -> {out.relative_to(ROOT)}")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", choices=sorted(GOLDEN_SCENES), action="append")
    parser.add_argument("--binary", default=str(ROOT / "lab01-ref"))
    args = parser.parse_args()
    for scene in args.scene or sorted(GOLDEN_SCENES):
        make_golden(scene, pathlib.Path(args.binary))
    # The grader refuses golden data that does not match this record
    # (grading/checks/golden_sums.py).
    golden_sums.RECORD.write_text(golden_sums.record())
    print(f"checksums -> {golden_sums.RECORD.relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
