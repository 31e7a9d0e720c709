"""Float against double (common/core/real.h): the lab-01 reference and its double build.

    make bench-precision

Time: the Cornell baseline at 200x200, 64 spp, the two builds alternately, best of 3 (render
time as each reports it). Error: each build's RMSE against the golden image at its size, with
the same seed, and how far the two images are from each other (the same random numbers, so
only rounding separates them). Prints a table; asserts nothing. Report only what it printed,
with the machine it names.
"""
import math
import pathlib
import sys

import numpy as np

from labkit.compare import compare
from labkit.harness import golden, run_lab

ROOT = pathlib.Path(__file__).resolve().parents[2]

BUILDS = {"float": ROOT / "lab01-ref", "double": ROOT / "lab01-ref-double"}
TIMED = dict(width=200, height=200, spp=64, seed=1)
ERROR_SPP = (64, 1024)


def main() -> int:
    seconds = {name: [] for name in BUILDS}
    device = ""
    for _ in range(3):
        for name, binary in BUILDS.items():
            run = run_lab(binary, **TIMED)
            assert run.json["precision"] == name, run.json
            seconds[name].append(run.json["seconds"])
            device = run.json["device"]
    g = golden("cornell")
    size = dict(width=g.meta["width"], height=g.meta["height"], bounces=g.meta["bounces"])
    print(f"Cornell box, lab 01 reference ({device})")
    print(f"time: {TIMED['width']}x{TIMED['height']}, {TIMED['spp']} spp, best of 3, alternating")
    for name in BUILDS:
        print(f"  {name:>6}: {min(seconds[name]):.3f} s  (runs: "
              + ", ".join(f"{s:.3f}" for s in seconds[name]) + ")")
    print(f"  double/float: {min(seconds['double']) / min(seconds['float']):.2f}x")
    print(f"error: {size['width']}x{size['height']}, seed 99, against the golden image "
          f"({g.meta['golden_spp']} spp)")
    print(f"{'spp':>6} {'RMSE float':>11} {'RMSE double':>12} {'RMS(d-f)':>10} "
          f"{'max|d-f|':>10} {'pixels equal':>13}")
    for spp in ERROR_SPP:
        images = {name: run_lab(b, g.scene, spp=spp, seed=99, **size).image
                  for name, b in BUILDS.items()}
        rmse = {name: compare(im, spp, g.mean, g.variance, g.meta["golden_spp"]).rmse
                for name, im in images.items()}
        diff = images["double"] - images["float"]
        equal = float(np.mean(np.all(diff == 0, axis=2)))
        print(f"{spp:>6} {rmse['float']:>11.5f} {rmse['double']:>12.5f} "
              f"{math.sqrt(float(np.mean(diff ** 2))):>10.2e} {float(np.abs(diff).max()):>10.2e} "
              f"{equal:>12.1%}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
