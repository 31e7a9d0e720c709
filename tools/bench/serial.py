"""Benchmarks of the lab-01 reference (the baseline every speedup is measured against).

    make bench-serial the Cornell baseline (600x600, 512 spp, 4 bounces), best of --repeat
    make tradeoff    error against time: RMSE vs the golden image as spp grows

Prints tables; asserts nothing. Report only what it printed, with the machine it names.
"""
import argparse
import math
import pathlib
import sys

from labkit.compare import compare
from labkit.harness import golden, run_lab

ROOT = pathlib.Path(__file__).resolve().parents[2]

BINARY = ROOT / "lab01-ref"


def baseline(repeat: int, small: bool = False) -> None:
    size = dict(width=64, height=64, spp=8) if small else {}  # a check that it runs, no more
    runs = [run_lab(BINARY, **size).json for _ in range(repeat)]
    best = min(runs, key=lambda r: r["seconds"])
    print(f"Lab 01 reference, Cornell baseline, best of {repeat} ({best['device']})")
    print(f"{'size':>9} {'spp':>5} {'bounces':>7} {'seconds':>9} {'Mpaths/s':>9}")
    print(f"{best['width']}x{best['height']:<5} {best['spp']:>5} {best['bounces']:>7} "
          f"{best['seconds']:>9.2f} {best['paths_per_second'] / 1e6:>9.2f}")
    print("all runs (s): " + ", ".join(f"{r['seconds']:.2f}" for r in runs))


def tradeoff(scene: str, max_spp: int) -> None:
    g = golden(scene)
    print(f"Error against time, '{scene}' at {g.meta['width']}x{g.meta['height']}, "
          f"{g.meta['bounces']} bounces, golden {g.meta['golden_spp']} spp")
    print(f"{'spp':>6} {'seconds':>9} {'RMSE':>10} {'relMSE':>10} {'RMSE*sqrt(spp)':>15}")
    spp = 1
    while spp <= max_spp:
        run = run_lab(BINARY, g.scene, width=g.meta["width"], height=g.meta["height"],
                      spp=spp, bounces=g.meta["bounces"], seed=99)
        r = compare(run.image, spp, g.mean, g.variance, g.meta["golden_spp"])
        print(f"{spp:>6} {run.json['seconds']:>9.4f} {r.rmse:>10.5f} {r.relmse:>10.5f} "
              f"{r.rmse * math.sqrt(spp):>15.4f}")
        spp *= 2
    print("Monte Carlo: RMSE falls as 1/sqrt(spp) (last column flat) while time grows as spp.")


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("what", choices=["baseline", "tradeoff"])
    p.add_argument("--repeat", type=int, default=3)
    p.add_argument("--scene", default="cornell")
    p.add_argument("--max-spp", type=int, default=1024)
    p.add_argument("--small", action="store_true",
                   help="baseline at 64x64, 8 spp: that it runs, not a measurement")
    a = p.parse_args()
    if a.what == "baseline":
        baseline(a.repeat, a.small)
    else:
        tradeoff(a.scene, a.max_spp)
    return 0


if __name__ == "__main__":
    sys.exit(main())
