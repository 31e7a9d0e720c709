"""The CPU labs side by side, in the shape of the report's Table 4, on this machine.

    make bench-cpu                       Cornell at 300x300, 128 spp (quick)
    python3 -m tools.bench.cpu --full    the baseline: 600x600, 512 spp, 4 bounces

Every row is a reference solution; time is render time as the binary reports it (best of
--repeat, rows interleaved round by round so a busy spell hits all of them); speedup is
against the lab-01 reference measured in the same rounds; efficiency is speedup / cores used.
It builds only the binaries it times (`make -k`; a row whose binary does not build here is
listed as such, with make's reason), and prints the load average before and after and the
machine's capacity measured alongside (how many cores' worth of throughput it gave: copies
of lab01-ref at once against one alone), without which no speedup here means anything.
Prints a table; asserts nothing.
"""
import argparse
import datetime
import json
import os
import pathlib
import re
import subprocess
import sys

from labkit.harness import available_cores, measure_parallel, run_lab

ROOT = pathlib.Path(__file__).resolve().parents[2]

# OpenMPI refuses to run as root unless told; benchmarks run as whoever runs them.
os.environ.setdefault("OMPI_ALLOW_RUN_AS_ROOT", "1")
os.environ.setdefault("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")


# lab02-ref runs the widest packets the CPU has (AVX-512 or AVX2): the ISA it ran is in the
# row's `device` and under the table.
PACKETS = "SIMD B: packets"


def rows(cores: int):
    """(label, binary, threads, launcher, cores used)"""
    mpirun = ["mpirun", "--oversubscribe", "--bind-to", "none", "-np", str(cores)]
    return [
        ("serial (lab 01)", "lab01-ref", None, [], 1),
        ("SIMD A: SSE vec3", "lab02a-ref", None, [], 1),
        (PACKETS, "lab02-ref", None, [], 1),
        (f"OpenMP, {cores} threads", "lab03-ref", cores, [], cores),
        (f"OpenMP + SIMD, {cores} threads", "lab03-simd-ref", cores, [], cores),
        (f"MPI, {cores} ranks", "lab04-ref", 1, mpirun, cores),
        (f"MPI + SIMD, {cores} ranks", "lab04-simd-ref", 1, mpirun, cores),
    ]


def build(binaries: list[str]) -> dict[str, str]:
    """`make -k` the binaries; returns binary -> why it did not build (make's last line that
    is not make's own "*** [...] Error")."""
    p = subprocess.run(["make", "-k", "-s", "-C", str(ROOT), *binaries], capture_output=True,
                       text=True)
    said = [line for line in (p.stdout + p.stderr).splitlines()
            if line.strip() and not re.match(r"make(\[\d+\])?: \*\*\*", line)]
    return {b: (said[-1] if said else "make failed")[:120] for b in binaries
            if p.returncode != 0 and not (ROOT / b).exists()}


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--full", action="store_true", help="the 600x600, 512 spp baseline")
    p.add_argument("--repeat", type=int, default=3)
    p.add_argument("--record", metavar="FILE.json",
                   help="also write the table as JSON (reference/timings/ keeps these)")
    a = p.parse_args()
    size, spp = (600, 512) if a.full else (300, 128)
    cores = available_cores()
    table = rows(cores)
    not_built = build(sorted({binary for _, binary, *_ in table}))
    if "lab01-ref" in not_built:
        print(f"error: bench-cpu: lab01-ref, the baseline, does not build: "
              f"{not_built['lab01-ref']}", file=sys.stderr)
        return 2
    load_before = os.getloadavg()
    best = {label: None for label, *_ in table}
    ran = {}  # label -> the binary's own words for how it ran (threads, ISA, packet width)
    for _ in range(a.repeat):
        for label, binary, threads, launcher, _ in table:
            path = ROOT / binary
            if not path.exists():
                continue
            run = run_lab(path, width=size, height=size, spp=spp, bounces=4, threads=threads,
                          launcher=launcher)
            s = run.json["seconds"]
            ran[label] = run.json.get("device", "")
            best[label] = s if best[label] is None else min(best[label], s)
    serial = best["serial (lab 01)"]
    device = ran["serial (lab 01)"]
    capacity = measure_parallel(
        lambda: run_lab(ROOT / "lab01-ref", width=size // 4, height=size // 4, spp=spp,
                        bounces=4).json["seconds"], {}, rounds=a.repeat).capacity
    load_after = os.getloadavg()
    print(f"Cornell {size}x{size}, {spp} spp, 4 bounces; best of {a.repeat}; "
          f"{cores} cores available; {device.split(',')[0]}")
    print(f"load average {load_before[0]:.2f} before, {load_after[0]:.2f} after; capacity "
          f"{capacity:.2f} of {cores} cores ({cores} copies of lab01-ref at once against one "
          f"alone: below {cores} the machine is shared, and speedups shrink with it)")
    print(f"{'version':<32} {'seconds':>8} {'speedup':>8} {'efficiency':>10}")
    for label, binary, _, _, used in table:
        if best[label] is None:
            why = not_built.get(binary, "missing")
            print(f"{label:<32} not built: {binary}: {why}")
            continue
        speedup = serial / best[label]
        print(f"{label:<32} {best[label]:>8.3f} {speedup:>7.2f}x {speedup / used:>9.0%}")
    if ran.get(PACKETS):
        print(f"SIMD B ran on {ran[PACKETS]}")
    if a.record:
        record = {
            "what": f"Cornell {size}x{size}, {spp} spp, 4 bounces, best of {a.repeat}",
            "cpu": device.split(",")[0], "cores": cores,
            "load_average_before": load_before[0], "load_average_after": load_after[0],
            "capacity": capacity,
            "date": datetime.date.today().isoformat(),
            "rows": [{"version": label, "binary": binary, "cores_used": used,
                      "seconds": best[label], "device": ran.get(label, ""),
                      "speedup": serial / best[label] if best[label] else None}
                     for label, binary, _, _, used in table if best[label] is not None],
        }
        path = pathlib.Path(a.record)
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(json.dumps(record, indent=2) + "\n")
        print(f"recorded in {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
