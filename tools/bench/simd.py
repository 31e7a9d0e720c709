"""Lab 02 benchmark: the SIMD variants against the lab-01 reference, on one core.

    make bench-simd (python3 -m tools.bench.simd)
                                       reduced Cornell baseline: 200x200, 512 spp
    python3 -m tools.bench.simd --full the Cornell baseline: 600x600, 512 spp (minutes)
    python3 -m tools.bench.simd --packets
                                       the handout's table of packet widths and methods:
                                       Cornell 400x400x64 and showcase 300x300x64 at 8
                                       bounces, best of 5, with the handout's targets
    python3 -m tools.bench.simd --only lab02
                                       one variant (yours: lab02, lab02a) against lab01-ref

Every binary runs pinned to one CPU (taskset; --cpu picks which), interleaved (one of each,
round after round), and each row reports its best round: a machine that slows down or speeds
up during the run affects every row alike. Speedup is the ratio of best render times (render
only, as each binary reports it). With --cpu-time, each row's seconds are instead the CPU time
of its process (user + system, as the kernel counts it for the child): on a machine shared
with other jobs, a run that had to wait for the CPU is then not charged for the wait. Every
image is compared byte for byte with lab01-ref's of the same round. Prints a table and the
load average before and after; asserts nothing. Report only what it printed.
"""
import argparse
import os
import pathlib
import resource
import shutil
import sys

from labkit.harness import build, run_lab

ROOT = pathlib.Path(__file__).resolve().parents[2]

# (row name, binary, environment, what). The references are timed by default; --only may
# also name a student's build.
VARIANTS = [
    ("lab01-ref", "lab01-ref", {}, "lab 01 reference (scalar)"),
    ("lab02a-ref", "lab02a-ref", {}, "Part A: SSE Vec3"),
    ("lab02-prims", "lab02-prims", {}, "one ray x 8 primitives"),
    ("lab02-ref-avx2", "lab02-ref-avx2", {}, "Part B: 8 paths per packet"),
    ("lab02-ref", "lab02-ref", {}, "the CPU's width, compacted"),
]
STUDENT_BUILDS = [
    ("lab02a", "lab02a", {}, "your Part A"),
    ("lab02", "lab02", {}, "your Part B"),
]
# The handout's table (section 8): every width and method of lab02-bench.
PACKETS = [
    ("lab01-ref", "lab01-ref", {}, "lab 01 reference (scalar)"),
    ("8 lanes", "lab02-bench", {"RT_SIMD_LANES": "8", "RT_SIMD_COMPACT": "0"},
     "AVX2, as students write it"),
    ("16 lanes", "lab02-bench", {"RT_SIMD_LANES": "16", "RT_SIMD_COMPACT": "0"}, "AVX-512"),
    ("8 compacted", "lab02-bench", {"RT_SIMD_LANES": "8", "RT_SIMD_COMPACT": "1"},
     "AVX2, survivors repacked"),
    ("16 compacted", "lab02-bench", {"RT_SIMD_LANES": "16", "RT_SIMD_COMPACT": "1"},
     "AVX-512, survivors repacked"),
]
# The handout's targets for lab02-ref (the widest compacted packets), per scene: AVX-512, AVX2.
TARGETS = {"cornell": (3.5, 2.4), "showcase": (3.2, 2.2)}
# --packets: each scene at the size its target is stated for.
PACKET_SCENES = [("cornell", 400, 64, 4), ("showcase", 300, 64, 8)]


def has_avx512() -> bool:
    flags = next((line for line in pathlib.Path("/proc/cpuinfo").read_text().splitlines()
                  if line.startswith("flags")), "").split()
    return all(f in flags for f in ("avx512f", "avx512dq", "avx512vl", "avx512bw"))


def children_cpu_seconds() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def time_table(variants, scene, size, spp, bounces, repeat, cpu, cpu_time=False):
    """Best render of each variant over `repeat` interleaved rounds (render seconds, or the
    process's CPU seconds with cpu_time); whether each image was lab01-ref's (the first
    variant's) of the same round in every round."""
    settings = dict(scene=ROOT / "common" / "scenes" / f"{scene}.json", width=size,
                    height=size, spp=spp, bounces=bounces)
    best, identical = {}, {name: True for name, *_ in variants}
    for _ in range(repeat):
        base_image = None
        for name, binary, env, _ in variants:
            launcher = ["taskset", "-c", str(cpu)] if shutil.which("taskset") else []
            if env:
                launcher += ["env", *(f"{k}={v}" for k, v in env.items())]
            before = children_cpu_seconds()
            run = run_lab(ROOT / binary, launcher=launcher, timeout=3600, **settings)
            if cpu_time:
                spent = children_cpu_seconds() - before
                run.json["paths_per_second"] *= run.json["seconds"] / spent
                run.json["seconds"] = spent
            if base_image is None:
                base_image = run.image.tobytes()
            identical[name] &= run.image.tobytes() == base_image
            if name not in best or run.json["seconds"] < best[name]["seconds"]:
                best[name] = run.json
    return best, identical


def print_table(variants, best, identical, heading):
    base = best[variants[0][0]]["seconds"]
    print(heading)
    print(f"| {'variant':<14} | {'what':<28} | {'seconds':>8} | {'Mpaths/s':>8} | "
          f"{'speedup':>7} | bits |")
    print(f"|{'-' * 16}|{'-' * 30}|{'-' * 10}|{'-' * 10}|{'-' * 9}|------|")
    for name, _, _, what in variants:
        r = best[name]
        print(f"| {name:<14} | {what:<28} | {r['seconds']:>8.3f} | "
              f"{r['paths_per_second'] / 1e6:>8.2f} | {base / r['seconds']:>6.2f}x | "
              f"{'same' if identical[name] else 'DIFF'} |")


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--full", action="store_true", help="600x600 (the baseline), not 200x200")
    p.add_argument("--packets", action="store_true",
                   help="the handout's table: packet widths and methods on both scenes")
    p.add_argument("--size", type=int, help="image width and height")
    p.add_argument("--spp", type=int)
    p.add_argument("--bounces", type=int)
    p.add_argument("--scene", default="cornell")
    p.add_argument("--repeat", type=int, help="rounds; each row keeps its best (default 3; "
                   "--packets: 5)")
    p.add_argument("--cpu", type=int, default=None, help="the CPU to pin to (default: the "
                   "last this process may use)")
    p.add_argument("--only", action="append", help="variant(s) to time besides lab01-ref")
    p.add_argument("--cpu-time", action="store_true",
                   help="time each process's CPU seconds, not its reported render seconds")
    a = p.parse_args()
    cpu = a.cpu if a.cpu is not None else max(os.sched_getaffinity(0))
    load_before = os.getloadavg()

    if a.packets:
        variants = PACKETS if has_avx512() else [v for v in PACKETS if "16" not in v[0]]
        build(*sorted({binary for _, binary, _, _ in variants}))
        repeat = a.repeat or 5
        scenes = (
            [(a.scene, a.size or 400, a.spp or 64, a.bounces or 4)] if a.size else PACKET_SCENES
        )
        for scene, size, spp, bounces in scenes:
            best, identical = time_table(variants, scene, size, spp, bounces, repeat, cpu,
                                         a.cpu_time)
            print_table(variants, best, identical,
                        f"'{scene}' {size}x{size}, {spp} spp, {bounces} bounces, CPU {cpu} only, "
                        f"best of {repeat} interleaved rounds"
                        f"{', process CPU seconds' if a.cpu_time else ''}")
            target = TARGETS.get(scene)
            if target:
                widest = "16 compacted" if has_avx512() else "8 compacted"
                bar = target[0] if has_avx512() else target[1]
                got = best["lab01-ref"]["seconds"] / best[widest]["seconds"]
                print(f"lab02-ref's method ({widest}): {got:.2f}x, target {bar}x "
                      f"({'met' if got >= bar else 'NOT met'})")
            print()
    else:
        size = a.size or (600 if a.full else 200)
        if a.only:
            known = [name for name, *_ in VARIANTS + STUDENT_BUILDS]
            unknown = [name for name in a.only if name not in known]
            if unknown:
                p.error(f"unknown variant {', '.join(unknown)}; known: {', '.join(known)}")
            variants = [VARIANTS[0]] + [v for v in VARIANTS[1:] + STUDENT_BUILDS if v[0] in a.only]
        else:
            variants = VARIANTS
        build(*(binary for _, binary, _, _ in variants))
        repeat = a.repeat or 3
        spp, bounces = a.spp or 512, a.bounces or 4
        best, identical = time_table(variants, a.scene, size, spp, bounces, repeat, cpu,
                                     a.cpu_time)
        print_table(variants, best, identical,
                    f"'{a.scene}' {size}x{size}, {spp} spp, {bounces} bounces, CPU {cpu} only, "
                    f"best of {repeat} interleaved rounds"
                    f"{', process CPU seconds' if a.cpu_time else ''}")
    load_after = os.getloadavg()
    device = best["lab01-ref"]["device"].split(",")[0]
    print(f"CPU: {device}, {os.cpu_count()} logical cores, AVX-512: "
          f"{'yes' if has_avx512() else 'no'}; load average {load_before[0]:.1f} before, "
          f"{load_after[0]:.1f} after")
    return 0


if __name__ == "__main__":
    sys.exit(main())
