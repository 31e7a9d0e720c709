"""Benchmarks of lab 03 (OpenMP): loop schedules, thread counts and the shared-RNG mistake.

    make bench-openmp (python3 -m tools.bench.openmp)   the handout's tables on this machine
    python3 -m tools.bench.openmp --min-capacity 1.8    a shared machine: only rounds run
                                                        while idle
    python3 -m tools.bench.openmp --mine --no-rng       your ./lab03 among the reference's rows
    python3 -m tools.bench.openmp --threads 1,2,4,8,16,32 --spp 64      a bigger machine

Prints three tables and asserts nothing:

1. The cost profile: how long each band of rows takes serially (lab03-row-costs), and the
   speedup each schedule could reach on T threads if these rows were its only cost (a
   model: no overhead, one core per thread).
2. Schedules x threads: lab03-bench with OMP_SCHEDULE set, plus lab03-ref (the default
   build), and when lab 02's renderer exists lab02-ref (SIMD, serial) and lab03-simd-ref
   (the "SIMD ✓" rows: OpenMP on lab 02's AVX2 geometry). Seconds,
   speedup over lab01-ref, efficiency, and whether every image was lab 01's bit for bit.
3. The shared-RNG mistake: lab03-shared-rng (one generator behind `omp critical`) and
   lab03-shared-rng-race (no lock: a data race), with whether their images repeat.

Timing (DESIGN.md, "Timing"): render seconds as the binaries report them, best of
--repeat, measured in rounds; each round runs the lab01-ref baseline and every
configuration once, so a machine that slows down during the run slows both sides alike.
The machine, its cores and its load average before and after are printed with the tables:
report them with any number you quote. Each round also measures the machine's capacity:
`cores` serial renders at once against one alone (2.0 on an idle two-core machine; near 1
when other users' jobs take a core). On a shared machine, --min-capacity 1.8 discards
the rounds run while it was busy, and the tables say how many were discarded.
"""
from __future__ import annotations

import argparse
import concurrent.futures
import heapq
import math
import os
import pathlib
import shutil
import subprocess
import sys
import tempfile

from labkit.harness import available_cores, build, cpu_has_avx2, run_lab

ROOT = pathlib.Path(__file__).resolve().parents[2]

SCHEDULES = ["static", "static,1", "dynamic,1", "dynamic,4", "guided"]
# Private copies of the binaries (run() makes the folder, main() fills it): other people's
# builds in the same tree may relink ./lab01-ref in the middle of a run.
BIN = pathlib.Path()


def row_costs(args) -> list[float]:
    """Serial render seconds of each row: the smallest of --repeat runs, row by row."""
    best = None
    for _ in range(args.repeat):
        run = run_lab(BIN / "lab03-row-costs", scene_path(args.scene), width=args.width,
                      height=args.height, spp=args.spp, seed=args.seed)
        line = next(ln for ln in run.stderr.splitlines() if ln.startswith("row-seconds:"))
        costs = [float(v) for v in line.split()[1:]]
        best = costs if best is None else [min(a, b) for a, b in zip(best, costs)]
    return best


def scene_path(scene: str) -> pathlib.Path:
    named = ROOT / "common" / "scenes" / f"{scene}.json"
    return named if named.exists() else pathlib.Path(scene)


def capacity_now(render: dict, cores: int) -> float:
    """Cores' worth of throughput the machine gives us now: `cores` serial renders at once
    against the mean of the same renders, one alone before them (the kernel shares CPUs among
    sessions, so on a machine busy with other users' jobs this falls towards 1)."""
    alone = run_lab(BIN / "lab01-ref", **render).json["seconds"]
    with concurrent.futures.ThreadPoolExecutor(cores) as pool:
        times = list(pool.map(lambda _: run_lab(BIN / "lab01-ref", **render).json["seconds"],
                              range(cores)))
    return cores * alone / (sum(times) / len(times))


def chunks(n: int, threads: int, schedule: str) -> list[tuple[int, int]]:
    """The (first row, row count) chunks libgomp hands out for a schedule, in order."""
    kind, _, chunk = schedule.partition(",")
    c = int(chunk) if chunk else 0
    out, start = [], 0
    if kind == "static" and not c:  # one contiguous block per thread, the first n % T larger
        q, r = divmod(n, threads)
        for t in range(threads):
            size = q + (1 if t < r else 0)
            out.append((start, size))
            start += size
        return out
    while start < n:
        if kind == "guided":  # remaining / threads, at least the chunk size
            size = max(math.ceil((n - start) / threads), c or 1)
        else:
            size = c or 1
        size = min(size, n - start)
        out.append((start, size))
        start += size
    return out


def modelled_speedup(costs: list[float], threads: int, schedule: str) -> float:
    """Serial time over the time the slowest thread would take: the load-balance bound."""
    pieces = [sum(costs[s:s + k]) for s, k in chunks(len(costs), threads, schedule)]
    if schedule.startswith("static"):  # fixed assignment: chunk i to thread i % T
        load = [0.0] * threads
        for i, p in enumerate(pieces):
            load[i % threads] += p
        makespan = max(load)
    else:  # each chunk to whichever thread is free first
        free = [0.0] * threads
        for p in pieces:
            heapq.heappush(free, heapq.heappop(free) + p)
        makespan = max(free)
    return sum(costs) / makespan


def print_profile(costs: list[float], schedules: list[str]) -> None:
    n = len(costs)
    bands = 10
    mean = sum(costs) / n
    print(f"Cost of a row, serial (lab03-row-costs; fastest of the runs, row by row): "
          f"{n} rows, {sum(costs):.3f} s in all")
    print(f"{'rows':>11} {'ms/row':>8} {'x mean':>7}")
    for b in range(bands):
        lo, hi = b * n // bands, (b + 1) * n // bands
        band = costs[lo:hi]
        print(f"{lo:>5}-{hi - 1:<5} {1e3 * sum(band) / len(band):>8.3f} "
              f"{sum(band) / len(band) / mean:>7.2f}")
    print(f"cheapest row {1e3 * min(costs):.3f} ms, dearest {1e3 * max(costs):.3f} ms")
    print()
    shown = [2, 4, 8, 16]  # a model needs no such cores: what bigger machines would see
    print("Load-balance model: the speedup each schedule allows if the rows above were the "
          "only cost")
    print(f"{'schedule':<11}" + "".join(f"{f'{t} threads':>11}" for t in shown))
    for s in schedules:
        print(f"{s:<11}" + "".join(f"{modelled_speedup(costs, t, s):>11.2f}" for t in shown))
    print()


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--scene", default="cornell",
                   help="a scene of common/scenes (cornell, showcase) or a scene file")
    p.add_argument("--width", type=int, default=300)
    p.add_argument("--height", type=int, default=300)
    p.add_argument("--spp", type=int, default=16)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--repeat", type=int, default=3, help="rounds; each time is the best of them")
    p.add_argument("--threads", default=None,
                   help="comma-separated thread counts (default: 1, 2, 4, ... up to the "
                        "cores, then twice the cores: oversubscribed)")
    p.add_argument("--schedules", default=" ".join(SCHEDULES),
                   help="space-separated OMP_SCHEDULE values (default: %(default)s)")
    p.add_argument("--min-capacity", type=float, default=0,
                   help="discard rounds during which the machine gave less than this many "
                        "cores' worth of throughput (measured before and after each round)")
    p.add_argument("--max-rounds", type=int, default=30,
                   help="with --min-capacity: give up after this many rounds in all")
    p.add_argument("--mine", action="store_true",
                   help="add rows for your own ./lab03 (labs/03-openmp/skeleton)")
    p.add_argument("--no-rng", action="store_true", help="leave out the shared-RNG rows")
    a = p.parse_args()
    schedules = a.schedules.split()

    cores = available_cores()
    if a.threads:
        threads = [int(t) for t in a.threads.split(",")]
    else:
        threads, t = [], 1
        while t < cores:
            threads.append(t)
            t *= 2
        threads += [cores, 2 * cores]
        threads = sorted(set(threads))

    targets = ["lab01-ref", "lab03-ref", "lab03-bench", "lab03-row-costs", "lab03-shared-rng",
               "lab03-shared-rng-race"]
    build(*targets)
    simd = cpu_has_avx2()
    if simd:
        targets += ["lab03-simd-ref", "lab02-ref"]
        build("lab03-simd-ref", "lab02-ref")
    if a.mine:
        targets.append("lab03")
        build("lab03")
    for t in targets:
        shutil.copy2(ROOT / t, BIN / t)

    load_before = os.getloadavg()
    probe = run_lab(BIN / "lab01-ref", scene_path(a.scene), width=a.width, height=a.height,
                    spp=1).json
    cpu = probe["device"].split(",")[0]
    print(f"Lab 03 benchmark: {a.scene} {a.width}x{a.height}, {a.spp} spp, {probe['bounces']} "
          f"bounces, seed {a.seed}; best of {a.repeat}, interleaved with lab01-ref")
    print(f"machine: {cpu}, {cores} cores available; load average before "
          f"{load_before[0]:.2f} {load_before[1]:.2f} {load_before[2]:.2f}")
    print()
    print_profile(row_costs(a), schedules)

    render = dict(scene=scene_path(a.scene), width=a.width, height=a.height, spp=a.spp,
                  seed=a.seed)
    # (table, label, threads, binary, environment as (name, value) pairs)
    configs = []
    for s in schedules:
        for t in threads:
            configs.append(("schedule", s, t, "lab03-bench", (("OMP_SCHEDULE", s),)))
    for t in threads:
        configs.append(("schedule", "lab03-ref", t, "lab03-ref", ()))
    if a.mine:
        for t in threads:
            configs.append(("schedule", "your lab03", t, "lab03", ()))
    if simd:
        configs.append(("schedule", "lab02-ref (SIMD)", 1, "lab02-ref", ()))
        for t in threads:
            configs.append(("schedule", "SIMD ✓ lab03", t, "lab03-simd-ref", ()))
    if not a.no_rng:
        for t in threads:
            configs.append(("rng", "shared, critical", t, "lab03-shared-rng", ()))
        for t in threads:
            configs.append(("rng", "shared, racing", t, "lab03-shared-rng-race", ()))

    base_times, capacities, reference = [], [], None
    times = {c: [] for c in configs}
    images = {c: set() for c in configs}
    saved = dict(os.environ)
    kept = discarded = 0
    while kept < a.repeat and kept + discarded < a.max_rounds:
        before = capacity_now(render, cores) if a.min_capacity else None
        round_base, round_times, round_images = None, {}, {}
        run = run_lab(BIN / "lab01-ref", **render)
        round_base, reference = run.json["seconds"], run.image.tobytes()
        for c in configs:
            _, _, t, binary, env = c
            os.environ.clear()
            os.environ.update(saved)
            os.environ.update(dict(env))
            run = run_lab(BIN / binary, threads=t, **render)
            round_times[c] = run.json["seconds"]
            round_images[c] = run.image.tobytes()
        os.environ.clear()
        os.environ.update(saved)
        after = capacity_now(render, cores)
        capacity = min(after, before) if before is not None else after
        print(f"round {kept + discarded + 1}: capacity {capacity:.2f}", file=sys.stderr)
        # Images count from every round: a nondeterministic image is a fact, load or not.
        for c in configs:
            images[c].add(round_images[c])
        if a.min_capacity and capacity < a.min_capacity:
            discarded += 1
            continue
        kept += 1
        capacities.append(capacity)
        base_times.append(round_base)
        for c in configs:
            times[c].append(round_times[c])
    if not kept:
        print(f"every one of {discarded} rounds was disturbed (capacity below "
              f"{a.min_capacity}): no timings")
        return 1
    if kept < a.repeat:
        print(f"note: only {kept} undisturbed rounds of the {a.repeat} wanted in "
              f"{a.max_rounds}: the times below are best of {kept}")
    load_after = os.getloadavg()
    base = min(base_times)

    print(f"lab01-ref (the baseline): {base:.3f} s best; all runs "
          + ", ".join(f"{t:.3f}" for t in base_times))
    print(f"capacity, each round kept ({cores} lab01-ref at once vs one alone; {cores} = an idle "
          "machine): " + ", ".join(f"{c:.2f}" for c in capacities)
          + (f"; {discarded} rounds below {a.min_capacity} discarded" if a.min_capacity
             else ""))
    print("speedup = lab01-ref's best / this best; efficiency = speedup / cores used, "
          "min(threads, cores)")
    print()

    def table(which: str, title: str, last_column: str, describe) -> None:
        rows = [c for c in configs if c[0] == which]
        if not rows:
            return
        print(title)
        print(f"{'':<17} {'threads':>7} {'seconds':>8} {'speedup':>8} {'effic.':>7}  "
              f"{last_column}")
        previous = None
        for c in rows:
            _, label, t, _, _ = c
            best = min(times[c])
            speedup = base / best
            efficiency = speedup / min(t, cores)
            over = " (oversubscribed)" if t > cores else ""
            name = label if label != previous else ""
            previous = label
            print(f"{name:<17} {t:>7} {best:>8.3f} {speedup:>8.2f} {efficiency:>7.0%}  "
                  f"{describe(c)}{over}")
        print()

    def vs_lab01(c) -> str:
        return "yes" if images[c] == {reference} else "NO"

    def repeats(c) -> str:
        if kept + discarded == 1:
            same = "one run only"
        else:
            same = "same every run" if len(images[c]) == 1 else f"{len(images[c])} different"
        lab01 = ", = lab 01" if reference in images[c] else ""
        return same + lab01

    table("schedule", "Schedules (OMP_SCHEDULE with lab03-bench; lab03-ref is the default "
          "build)", "image = lab 01, bit for bit, every run", vs_lab01)
    table("rng", "The classic mistake: one generator shared by all threads",
          f"images over {kept + discarded} runs", repeats)
    print(f"load average after {load_after[0]:.2f} {load_after[1]:.2f} {load_after[2]:.2f}")
    return 0


def run() -> int:
    global BIN
    BIN = pathlib.Path(tempfile.mkdtemp(prefix="bench_openmp-"))
    try:
        return main()
    except KeyboardInterrupt:
        return 130
    except subprocess.CalledProcessError as e:  # make said why, above
        print(f"error: bench_openmp: `{' '.join(map(str, e.cmd))}` failed", file=sys.stderr)
        return 2
    finally:
        shutil.rmtree(BIN, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(run())
