"""The per-lab test harness: build lab binaries, run them, load their images, time them.

Every lab binary takes the same command line (shared/DESIGN.md), so one harness serves all
labs, the pytest suites and the grader alike.
"""
from __future__ import annotations

import concurrent.futures
import dataclasses
import json
import os
import pathlib
import subprocess
import tempfile
import time
from typing import Callable, Sequence

import numpy as np

from grading.pfm import read_pfm

ROOT = pathlib.Path(__file__).resolve().parent.parent
SCENES = ROOT / "common" / "scenes"
GOLDEN = ROOT / "reference" / "golden"

_built: set[str] = set()


def build(*targets: str) -> list[pathlib.Path]:
    """Run `make TARGET...` once per process; return the binaries' paths."""
    wanted = [t for t in targets if t not in _built]
    if wanted:
        subprocess.run(["make", "-s", "-C", str(ROOT), *wanted], check=True,
                       stdout=subprocess.DEVNULL)
        _built.update(wanted)
    return [ROOT / t for t in targets]


def cpu_has_avx2() -> bool:
    """Whether this CPU runs lab 02's Part B (AVX2 and FMA), as its binaries check too."""
    for line in pathlib.Path("/proc/cpuinfo").read_text().splitlines():
        if line.startswith("flags"):
            return " avx2" in line and " fma" in line
    return False


def available_cores() -> int:
    """Cores this process may run on (what thresholds scale with)."""
    return len(os.sched_getaffinity(0))


@dataclasses.dataclass
class Run:
    """One finished run of a lab binary."""
    returncode: int
    stdout: str
    stderr: str
    json: dict | None       # the --json summary, when the run succeeded
    image: np.ndarray | None  # (H, W, 3) float32 linear radiance, top row first


def run_lab(binary: pathlib.Path | str, scene: pathlib.Path | str | None = None, *,
            width: int | None = None, height: int | None = None, spp: int | None = None,
            bounces: int | None = None, seed: int | None = None, threads: int | None = None,
            extra: Sequence[str] = (), launcher: Sequence[str] = (), timeout: float = 600,
            check: bool = True) -> Run:
    """Render with a lab binary; returns its summary and PFM image.

    `launcher` prefixes the command (e.g. mpirun ...). With check=True a non-zero exit
    raises with the binary's stderr in the message.
    """
    with tempfile.TemporaryDirectory() as tmp:
        pfm = pathlib.Path(tmp) / "image.pfm"
        cmd = [*launcher, str(binary), "--quiet", "--json", "--pfm", str(pfm)]
        for flag, value in (("--scene", scene), ("--width", width), ("--height", height),
                            ("--spp", spp), ("--bounces", bounces), ("--seed", seed),
                            ("--threads", threads)):
            if value is not None:
                cmd += [flag, str(value)]
        cmd += list(extra)
        p = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
        if check and p.returncode != 0:
            raise RuntimeError(f"{' '.join(cmd)} exited {p.returncode}: {p.stderr.strip()}")
        summary = json.loads(p.stdout.strip().splitlines()[-1]) if p.returncode == 0 else None
        image = read_pfm(pfm) if p.returncode == 0 and pfm.exists() else None
        return Run(p.returncode, p.stdout, p.stderr, summary, image)


@dataclasses.dataclass
class Golden:
    """Converged reference data for one scene (made by tools/make_golden.py)."""
    scene: pathlib.Path
    mean: np.ndarray      # converged image
    variance: np.ndarray  # per-pixel variance of a single path
    meta: dict            # settings it was made with: width, height, bounces, golden_spp...


def golden(name: str) -> Golden:
    folder = GOLDEN / name
    meta = json.loads((folder / "meta.json").read_text())
    return Golden(ROOT / meta["scene"], read_pfm(folder / "golden.pfm"),
                  read_pfm(folder / "variance.pfm"), meta)


def best_of(fn: Callable[[], float], n: int) -> float:
    """The smallest of n measurements: the least disturbed by everything else running."""
    return min(fn() for _ in range(n))


def render_seconds(binary, **kwargs) -> float:
    """Render time the binary reports itself (render only, per DESIGN.md)."""
    return run_lab(binary, **kwargs).json["seconds"]


def interleaved_speedup(baseline: Callable[[], float], candidate: Callable[[], float],
                        n: int = 3) -> tuple[float, float, float]:
    """(speedup, best baseline seconds, best candidate seconds), measured alternately in one
    run so that a machine slowing down or speeding up affects both sides alike."""
    base, cand = [], []
    for _ in range(n):
        base.append(baseline())
        cand.append(candidate())
    return min(base) / min(cand), min(base), min(cand)


def wall_seconds(cmd: Sequence[str]) -> float:
    """Wall-clock time of a whole command (for launchers whose startup counts)."""
    start = time.perf_counter()
    subprocess.run(cmd, check=True, capture_output=True)
    return time.perf_counter() - start


@dataclasses.dataclass
class ParallelTiming:
    """Best render seconds of a serial baseline and of parallel candidates, measured in the
    same interleaved rounds, with the machine's capacity measured alongside."""
    cores: int                 # available_cores()
    capacity: float            # how many cores' worth of throughput the machine gave us
    base: float                # the baseline's best seconds
    best: dict[str, float]     # each candidate's best seconds

    def speedup(self, name: str) -> float:
        return self.base / self.best[name]

    def required(self, fraction: float = 0.75) -> float:
        """The speedup a correct parallel lab must show here: a fraction of the measured
        capacity. That holds on a busy machine and with SMT, because the capacity is
        measured under the same conditions; the labs' real bars (0.9 x cores for OpenMP,
        1.8x at two MPI ranks) are shown by the benchmarks on a quiet machine."""
        return fraction * self.capacity

    def describe(self, name: str) -> str:
        return (f"{name} {self.speedup(name):.2f}x over the serial reference ({self.base:.3f} s "
                f"-> {self.best[name]:.3f} s) on {self.cores} cores giving "
                f"{self.capacity:.2f}x capacity; needs >= {self.required():.2f}x")


def measure_parallel(baseline: Callable[[], float], candidates: dict[str, Callable[[], float]],
                     rounds: int = 5) -> ParallelTiming:
    """Interleaved rounds of: the baseline alone, `cores` copies of the baseline at once (the
    capacity: about `cores` when idle, close to 1 when other users' jobs share the CPUs, and
    then no program can show a speedup), and each candidate. Best of `rounds` each."""
    cores = available_cores()
    single, together = [], []
    times: dict[str, list[float]] = {name: [] for name in candidates}
    with concurrent.futures.ThreadPoolExecutor(cores) as pool:
        for _ in range(rounds):
            single.append(baseline())
            side_by_side = list(pool.map(lambda _: baseline(), range(cores)))
            together.append(sum(side_by_side) / len(side_by_side))
            for name, candidate in candidates.items():
                times[name].append(candidate())
    base = min(single)
    capacity = min(cores, cores * base / min(together))
    return ParallelTiming(cores, capacity, base, {n: min(t) for n, t in times.items()})
