"""Benchmarks of lab 04 (MPI): distributions x ranks, and hybrid MPI + OpenMP, against lab 01.

    make bench-mpi (python3 -m tools.bench.mpi table)
                               seconds, speedup over lab01-ref and efficiency for each
                               distribution at 1, 2 and 4 ranks, and hybrid ranks x threads;
                               measured interleaved with lab01-ref, best of --repeat
    python3 -m tools.bench.mpi rows
                               what each band of rows costs: block and interleaved with
                               --bands ranks, CPU time per rank (RT_MPI_REPORT), and the
                               speedup each would reach on that many equal, dedicated cores.
                               All ranks share one CPU (unless --cpus says otherwise), so the
                               CPU times measure work, not how fast each rank's core was

Builds lab01-ref and lab04-ref first. Prints Markdown tables; asserts nothing. Other work on
the machine disturbs timings: each table line says what the machine gave (the "capacity": N
serial renders at once against one alone, N = cores) and the load average; rerun when they
say the machine was busy. `--cpus 0,1` pins everything to those CPUs (taskset), to measure
"a two-core machine" on a bigger one.
"""
import argparse
import concurrent.futures
import os
import pathlib
import re
import sys
import time

from labkit.harness import available_cores, build, run_lab

ROOT = pathlib.Path(__file__).resolve().parents[2]

DISTRIBUTIONS = ["block", "interleaved", "dynamic"]
# mpirun as the tests run it; OpenMPI refuses root unless told (benchmarks run as root in CI
# containers too).
os.environ.setdefault("OMPI_ALLOW_RUN_AS_ROOT", "1")
os.environ.setdefault("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")


def parse_cpus(text):
    """taskset's list syntax: "0,1" or "0-3,8"."""
    cpus = set()
    for part in text.split(","):
        first, _, last = part.partition("-")
        cpus.update(range(int(first), int(last or first) + 1))
    return cpus


class Bench:
    def __init__(self, args):
        self.args = args
        self.pin = ["taskset", "-c", args.cpus] if args.cpus else []
        self.cores = len(parse_cpus(args.cpus)) if args.cpus else available_cores()
        self.lab01, self.lab04 = build("lab01-ref", "lab04-ref")
        self.settings = dict(width=args.width, height=args.height, spp=args.spp)

    def mpirun(self, ranks):
        cmd = [*self.pin, "mpirun", "-q", "--bind-to", "none", "-np", str(ranks)]
        if ranks > self.cores:
            cmd.insert(len(self.pin) + 2, "--oversubscribe")
        return cmd

    def serial(self):
        return run_lab(self.lab01, **self.settings, launcher=self.pin).json["seconds"]

    def mpi(self, ranks, threads, distribution, report=False):
        """(render seconds, wall seconds of the whole mpirun command, stderr)."""
        env = {"RT_MPI_DISTRIBUTION": distribution, "RT_MPI_REPORT": "1" if report else ""}
        old = {k: os.environ.get(k) for k in env}
        os.environ.update(env)
        try:
            start = time.perf_counter()
            run = run_lab(self.lab04, **self.settings, threads=threads,
                          launcher=self.mpirun(ranks))
            wall = time.perf_counter() - start
        finally:
            for k, v in old.items():
                if v is None:
                    os.environ.pop(k, None)
                else:
                    os.environ[k] = v
        return run.json["seconds"], wall, run.stderr, run.json["device"]

    def capacity(self):
        """Cores' worth of throughput now: `cores` serial renders at once against one."""
        one = self.serial()
        with concurrent.futures.ThreadPoolExecutor(self.cores) as pool:
            together = list(pool.map(lambda _: self.serial(), range(self.cores)))
        return self.cores * one / (sum(together) / len(together))

    def conditions(self):
        load = os.getloadavg()
        return f"load average {load[0]:.2f} {load[1]:.2f} {load[2]:.2f}"


def table(b: Bench) -> None:
    a = b.args
    configs = [(r, 1, d) for r in a.ranks for d in DISTRIBUTIONS]
    configs += [(r, t, a.hybrid_distribution) for r, t in a.hybrid]
    best = {c: (float("inf"), 0.0) for c in configs}
    serial, capacities = [], []
    device = ""
    print(f"before: {b.conditions()}", file=sys.stderr)
    for round_ in range(a.repeat):
        serial.append(b.serial())
        if not a.no_capacity:
            capacities.append(b.capacity())
        for c in configs:  # interleaved with the serial runs: drifts hit every line alike
            seconds, wall, _, dev = b.mpi(*c)
            if c == configs[0]:
                device = dev.split(",")[0]
            best[c] = min(best[c], (seconds, wall))
        print(f"round {round_ + 1}/{a.repeat}: lab01-ref {serial[-1]:.3f} s"
              + (f", capacity {capacities[-1]:.2f}x" if capacities else "")
              + f"; {b.conditions()}", file=sys.stderr)
    base = min(serial)
    print(f"Lab 04 on {device}, {b.cores} cores"
          + (f" (taskset -c {a.cpus})" if a.cpus else "")
          + f"; {a.width}x{a.height}, {a.spp} spp, Cornell box; best of {a.repeat}, "
          f"interleaved with lab01-ref")
    print(f"lab01-ref: {base:.3f} s (all runs: {', '.join(f'{s:.3f}' for s in serial)})")
    if capacities:
        print(f"machine capacity while measuring: {', '.join(f'{c:.2f}x' for c in capacities)} "
              f"({b.cores} serial renders at once vs one; {b.cores:.0f}x is an idle machine)")
    print(f"after: {b.conditions()}")
    print()
    print("| distribution | ranks x threads | render s | speedup | efficiency | mpirun wall s |")
    print("|---|---|---:|---:|---:|---:|")
    for ranks, threads, distribution in configs:
        seconds, wall = best[(ranks, threads, distribution)]
        workers = ranks * threads
        note = " (oversubscribed)" if workers > b.cores else ""
        speedup = base / seconds
        print(f"| {distribution} | {ranks} x {threads}{note} | {seconds:.3f} | {speedup:.2f}x | "
              f"{speedup / min(workers, b.cores):.2f} | {wall:.2f} |")
    print()
    print("efficiency = speedup / cores used (min(ranks x threads, cores)); "
          "render s excludes mpirun start-up, MPI_Init and scene loading, wall s includes them.")


REPORT = re.compile(r"^rank (\d+): +(\d+) rows, +([\d.]+) s busy, +([\d.]+) s CPU", re.M)


def rows(b: Bench) -> None:
    a = b.args
    if not a.cpus:  # one CPU for all: equal cores, so CPU time is work
        b.pin = ["taskset", "-c", str(min(os.sched_getaffinity(0)))]
        b.cores = 1
    print(f"What the rows cost: {a.width}x{a.height}, {a.spp} spp, Cornell box, "
          f"{a.bands} ranks on CPU {b.pin[2]} (CPU time per rank)")
    print()
    for distribution in ("block", "interleaved"):
        _, _, stderr, _ = b.mpi(a.bands, 1, distribution, report=True)
        ranks = [(int(r), int(n), float(cpu)) for r, n, _, cpu in REPORT.findall(stderr)]
        total = max(sum(cpu for _, _, cpu in ranks), 1e-9)
        busiest = max(max(cpu for _, _, cpu in ranks), 1e-9)
        print(f"**{distribution}**, {a.bands} ranks:")
        print()
        print("| rank | rows | CPU s | share of the work |")
        print("|---:|---|---:|---:|")
        for r, n, cpu in ranks:
            what = (f"{r * a.height // a.bands}-{(r + 1) * a.height // a.bands - 1}"
                    if distribution == "block" else f"{r}, {r + a.bands}, ... ({n})")
            print(f"| {r} | {what} | {cpu:.3f} | {100 * cpu / total:.1f}% |")
        print()
        print(f"imbalance (busiest / mean) {busiest / (total / len(ranks)):.3f}: on {a.bands} "
              f"dedicated cores at most {total / busiest:.2f}x, not {a.bands}x")
        print()


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("what", choices=["table", "rows"])
    p.add_argument("--width", type=int, default=300)
    p.add_argument("--height", type=int, default=300)
    p.add_argument("--spp", type=int, default=64)
    p.add_argument("--repeat", type=int, default=3)
    p.add_argument("--ranks", type=lambda s: [int(x) for x in s.split(",")], default=[1, 2, 4],
                   help="rank counts of the distribution rows (default 1,2,4)")
    p.add_argument("--hybrid", type=lambda s: [tuple(map(int, x.split("x"))) for x in s.split(",")],
                   default=[(1, 2), (2, 2)], help="ranks x threads of the hybrid rows "
                   "(default 1x2,2x2)")
    p.add_argument("--hybrid-distribution", default="dynamic")
    p.add_argument("--bands", type=int, default=8, help="ranks for `rows` (default 8)")
    p.add_argument("--cpus", help="run everything on these CPUs (taskset -c LIST)")
    p.add_argument("--no-capacity", action="store_true",
                   help="skip the capacity measurement (quicker)")
    a = p.parse_args()
    b = Bench(a)
    table(b) if a.what == "table" else rows(b)
    return 0


if __name__ == "__main__":
    sys.exit(main())
