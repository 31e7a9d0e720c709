#!/usr/bin/env python3
"""Lab 02 benchmark: the SIMD variants against the lab-01 reference, on one core.

    python3 tools/bench_simd.py                  reduced Cornell baseline: 200x200, 512 spp
    python3 tools/bench_simd.py --full           the Cornell baseline: 600x600, 512 spp (minutes)
    python3 tools/bench_simd.py --only lab02     one variant (yours: lab02, lab02a) against lab01-ref

The binaries run interleaved (one of each, round after round), and each row reports its best
round: a machine that slows down or speeds up during the run affects every row alike. Speedup
is the ratio of best render times (render only, as each binary reports it). Prints a table and
the load average before and after; asserts nothing. Report only what it printed.
"""
import argparse
import os
import pathlib
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
from grading.harness import build, run_lab  # noqa: E402

# The references, timed by default; --only may also name a student's build.
VARIANTS = [
    ("lab01-ref", "lab 01 reference (scalar)"),
    ("lab02a-ref", "Part A: SSE Vec3"),
    ("lab02-prims", "one ray x 8 primitives"),
    ("lab02-ref", "Part B: 8 paths per packet"),
]
STUDENT_BUILDS = [
    ("lab02a", "your Part A"),
    ("lab02", "your Part B"),
]


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--full", action="store_true", help="600x600 (the baseline), not 200x200")
    p.add_argument("--size", type=int, help="image width and height")
    p.add_argument("--spp", type=int, default=512)
    p.add_argument("--bounces", type=int, default=4)
    p.add_argument("--scene", default="cornell")
    p.add_argument("--repeat", type=int, default=3, help="rounds; each row keeps its best")
    p.add_argument("--only", action="append", help="variant(s) to time besides lab01-ref")
    a = p.parse_args()
    size = a.size or (600 if a.full else 200)
    if a.only:
        known = [name for name, _ in VARIANTS + STUDENT_BUILDS]
        unknown = [name for name in a.only if name not in known]
        if unknown:
            p.error(f"unknown variant {', '.join(unknown)}; known: {', '.join(known)}")
        variants = [VARIANTS[0]] + [v for v in VARIANTS[1:] + STUDENT_BUILDS if v[0] in a.only]
    else:
        variants = VARIANTS
    build(*(name for name, _ in variants))

    settings = dict(scene=ROOT / "common" / "scenes" / f"{a.scene}.json", width=size,
                    height=size, spp=a.spp, bounces=a.bounces)
    load_before = os.getloadavg()
    best = {}
    for _ in range(a.repeat):
        for name, _ in variants:
            summary = run_lab(ROOT / name, **settings).json
            if name not in best or summary["seconds"] < best[name]["seconds"]:
                best[name] = summary
    load_after = os.getloadavg()

    base = best["lab01-ref"]["seconds"]
    print(f"'{a.scene}' {size}x{size}, {a.spp} spp, {a.bounces} bounces, one thread, "
          f"best of {a.repeat} interleaved rounds")
    print(f"CPU: {best['lab01-ref']['device'].split(',')[0]}, {os.cpu_count()} logical cores; "
          f"load average {load_before[0]:.1f} before, {load_after[0]:.1f} after")
    print(f"| {'binary':<12} | {'what':<27} | {'seconds':>8} | {'Mpaths/s':>8} | {'speedup':>7} |")
    print(f"|{'-' * 14}|{'-' * 29}|{'-' * 10}|{'-' * 10}|{'-' * 9}|")
    for name, what in variants:
        r = best[name]
        print(f"| {name:<12} | {what:<27} | {r['seconds']:>8.2f} | "
              f"{r['paths_per_second'] / 1e6:>8.2f} | {base / r['seconds']:>6.2f}x |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
