"""The per-lab test harness: build lab binaries, run them, load their images, time them.

Every lab binary takes the same command line (DESIGN.md), so one harness serves all
labs, the pytest suites and the grader alike.
"""
from __future__ import annotations

import concurrent.futures
import contextlib
import contextvars
import dataclasses
import fcntl
import json
import os
import pathlib
import re
import subprocess
import time
from typing import Callable, Sequence

import numpy as np

from labkit.pfm import read_pfm

# Every run, trusted or not, goes through the one runner (labkit/sandbox.py): a tool's timings
# and the grader's are taken the same way (the sandbox is skipped for trusted runs).
from labkit.sandbox import Limits, Runner

ROOT = pathlib.Path(__file__).resolve().parent.parent
SCENES = ROOT / "common" / "scenes"
GOLDEN = ROOT / "reference" / "golden"
DEFAULT_SCENE = SCENES / "cornell.json"  # what a lab binary renders without --scene

_built: set[str] = set()
_IN_TURN = "RT_MAKE_IN_TURN"  # set for the makes started inside a turn, and their children


def make_in_root(*args: str, **run_options) -> subprocess.CompletedProcess:
    """`make -s -C <the repository> ARGS`, one process at a time: processes that build in the
    repository side by side (the tests on every core, graders of one class) take turns, so two
    makes never write the same object at once. A make started inside a turn (make tradeoff's
    own builds) runs at once. A repository that cannot be written has no turns to take."""
    command = ["make", "-s", "-C", str(ROOT), *args]
    env = dict(run_options.pop("env", None) or os.environ)
    if env.get(_IN_TURN):
        return subprocess.run(command, env=env, **run_options)
    try:
        (ROOT / "build").mkdir(exist_ok=True)
        lock = open(ROOT / "build" / ".make-turn", "a")
    except OSError:
        return subprocess.run(command, env=env, **run_options)
    with lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        return subprocess.run(command, env={**env, _IN_TURN: "1"}, **run_options)


def build(*targets: str) -> list[pathlib.Path]:
    """Run `make TARGET...` once per process; return the binaries' paths."""
    wanted = [t for t in targets if t not in _built]
    if wanted:
        make_in_root(*wanted, check=True, stdout=subprocess.DEVNULL)
        _built.update(wanted)
    return [ROOT / t for t in targets]


def cpu_has_avx2() -> bool:
    """Whether this CPU runs lab 02's Part B (AVX2 and FMA), as its binaries check too."""
    for line in pathlib.Path("/proc/cpuinfo").read_text().splitlines():
        if line.startswith("flags"):
            return " avx2" in line and " fma" in line
    return False


def cpu_quota() -> float | None:
    """Cores' worth of CPU time this process's cgroup may use (cgroup v2 cpu.max, v1
    cpu.cfs_quota_us over cpu.cfs_period_us, the smallest along the cgroup's path), or None
    without a quota. A container run with --cpus=0.5 (Gradescope's default) has 0.5 here and
    still sees every CPU of the host."""
    quotas = []
    try:
        lines = pathlib.Path("/proc/self/cgroup").read_text().splitlines()
    except OSError:
        lines = []
    for line in lines:
        hierarchy, controllers, path = (line.split(":", 2) + ["", ""])[:3]
        if hierarchy == "0":  # v2
            folders = [pathlib.Path("/sys/fs/cgroup") / path.lstrip("/")]
            folders += list(folders[0].parents)
            for folder in folders:
                if not str(folder).startswith("/sys/fs/cgroup"):
                    break
                try:
                    quota, period = (folder / "cpu.max").read_text().split()
                except (OSError, ValueError):
                    continue
                if quota != "max":
                    quotas.append(int(quota) / int(period))
        elif "cpu" in controllers.split(","):
            for base in ("/sys/fs/cgroup/cpu,cpuacct", "/sys/fs/cgroup/cpu"):
                folder = pathlib.Path(base) / path.lstrip("/")
                for f in (folder, pathlib.Path(base)):
                    try:
                        quota = int((f / "cpu.cfs_quota_us").read_text())
                        period = int((f / "cpu.cfs_period_us").read_text())
                    except (OSError, ValueError):
                        continue
                    if quota > 0:
                        quotas.append(quota / period)
    return min(quotas) if quotas else None


def cpu_capacity() -> float:
    """Cores' worth of CPU this process may use: its CPUs, or its cgroup's quota if smaller."""
    cpus = len(os.sched_getaffinity(0))
    quota = cpu_quota()
    return min(cpus, quota) if quota else float(cpus)


def available_cores() -> int:
    """Whole cores this process may use (what thresholds scale with): its CPUs, or fewer when
    its cgroup's CPU quota is smaller (cpu_capacity)."""
    return max(1, int(cpu_capacity()))


@dataclasses.dataclass(frozen=True)
class RunPolicy:
    """How run_lab runs binaries: trusted (the lab tests, a student's own `make grade`) or in
    the sandbox (grading others' code), and under which limits (labkit/sandbox.py)."""
    trusted: bool = True
    limits: Limits = Limits(wall_seconds=600, memory_bytes=None)
    gpu: bool = False  # the binaries run on the GPU: the sandbox must show it (labkit/gpu.py)


_policy = RunPolicy()


@contextlib.contextmanager
def policy(p: RunPolicy):
    """Every run_lab inside the block, in any thread, runs under `p`. A module global rather
    than a context variable because the timing checks run binaries from worker threads."""
    global _policy
    saved, _policy = _policy, p
    try:
        yield p
    finally:
        _policy = saved


def current_policy() -> RunPolicy:
    return _policy


class RunError(RuntimeError):
    """The binary did not finish cleanly: crashed, timed out, flooded its output, exited
    non-zero. The message names the symptom first."""


class ImageError(RuntimeError):
    """The binary exited cleanly but its image cannot be graded: missing, unreadable, the wrong
    size, or holding NaN/Inf values (which make every comparison false, i.e. pass)."""


@dataclasses.dataclass
class Run:
    """One finished run of a lab binary."""
    returncode: int
    stdout: str
    stderr: str
    json: dict | None       # the --json summary, when the run succeeded
    image: np.ndarray | None  # (H, W, 3) float32 linear radiance, top row first
    wall_seconds: float = 0.0         # measured by the grader around the whole process tree
    cpu_seconds: float | None = None  # likewise, where it can be measured (trusted runs)
    thread_share: float = float("nan")  # of that CPU time, its busiest thread's (likewise)


def image_problem(image: np.ndarray, width: int | None, height: int | None) -> str | None:
    """Why an image cannot be graded, or None."""
    if image.ndim != 3 or image.shape[2] != 3:
        return f"the image has shape {image.shape}, not height x width x 3"
    if width is not None and height is not None and image.shape[:2] != (height, width):
        return (f"the image is {image.shape[1]}x{image.shape[0]} pixels; "
                f"{width}x{height} were asked for")
    nan, inf = int(np.isnan(image).sum()), int(np.isinf(image).sum())
    if nan or inf:
        return (f"the image holds {nan} NaN and {inf} infinite values (of {image.size}): "
                f"a non-finite pixel fails every check that reads the image")
    # Radiance is never negative, and no test scene comes near PLAUSIBLE_RADIANCE; values near
    # the float limit would overflow any sum of them.
    low, high = float(np.min(image)), float(np.max(image))
    if not (low >= 0.0 and high <= PLAUSIBLE_RADIANCE):
        return (f"the image holds values from {low:.3g} to {high:.3g}: radiance is never "
                f"negative and no test scene gives more than {PLAUSIBLE_RADIANCE:.0e}")
    return None


# The largest pixel value a test scene can give is about 1e2 (the point light seen through
# glass); 1e9 leaves room for any scene and keeps float32 sums of a million pixels finite.
PLAUSIBLE_RADIANCE = 1e9


def run_lab(binary: pathlib.Path | str, scene: pathlib.Path | str | None = None, *,
            width: int | None = None, height: int | None = None, spp: int | None = None,
            bounces: int | None = None, seed: int | None = None, threads: int | None = None,
            extra: Sequence[str] = (), launcher: Sequence[str] = (), timeout: float | None = None,
            cpu: int | None = None, check: bool = True) -> Run:
    """Render with a lab binary; returns its summary and PFM image.

    `launcher` prefixes the command (e.g. mpirun ...). With check=True a run that did not exit
    0 raises RunError naming the symptom (with the binary's stderr), and an image that is
    missing, of the wrong size or not finite raises ImageError. The run goes through
    labkit/sandbox.py under the current policy(); `timeout` (seconds) lowers its wall limit;
    `cpu` confines the whole run to that CPU, which it cannot widen (sandbox.Limits.cpu).
    """
    pol = current_policy()
    limits = pol.limits
    if timeout is not None and timeout < limits.wall_seconds:
        limits = dataclasses.replace(limits, wall_seconds=timeout)
    if cpu is not None:
        limits = dataclasses.replace(limits, cpu=cpu)
    if scene is None and not pol.trusted:
        scene = DEFAULT_SCENE  # the built-in default path is outside the sandbox's view
    with Runner(trusted=pol.trusted, gpu=pol.gpu) as r:
        cmd = [*launcher, r.input(binary), "--quiet", "--json", "--pfm", r.scratch("image.pfm")]
        for flag, value in (("--scene", scene), ("--width", width), ("--height", height),
                            ("--spp", spp), ("--bounces", bounces), ("--seed", seed),
                            ("--threads", threads)):
            if value is not None:
                cmd += [flag, r.input(value) if flag == "--scene" else str(value)]
        cmd += list(extra)
        out = r.run(cmd, limits)
        if check and out.failure:
            home = rerun_command(binary, scene, launcher, cmd[len(launcher) + 1:])
            raise RunError(failure_message(out.failure, out.stderr, launcher, home))
        ok = out.failure is None
        summary = _summary(out.stdout) if ok else None
        image = None
        if ok:
            data = r.output("image.pfm")
            if data is not None:
                pfm = r.root / "image.pfm"  # the grader's own copy, outside the scratch folder
                pfm.write_bytes(data)
                try:
                    image = read_pfm(pfm)
                except ValueError as e:
                    if check:
                        raise ImageError(f"the image is not a readable PFM: {e}") from None
        if check:
            if image is None:
                raise ImageError("the program exited 0 but wrote no image")
            problem = image_problem(image, width, height)
            if problem:
                raise ImageError(problem)
        return Run(out.returncode, out.stdout, out.stderr, summary, image, out.wall_seconds,
                   out.cpu_seconds, out.busiest_thread_share)


# How the binary being graded is called at home (./lab04), for the command a failing check
# tells the student to rerun; the grader sets it for a grade (rerun_as).
_home_binary: contextvars.ContextVar[str | None] = contextvars.ContextVar("home", default=None)


@contextlib.contextmanager
def rerun_as(name: str):
    token = _home_binary.set(name)
    try:
        yield
    finally:
        _home_binary.reset(token)


def rerun_command(binary, scene, launcher: Sequence[str], args: list[str]) -> str:
    """The command a student can run at home to see a failure again: the binary by its home
    name, the scene by its path in the repository. A scene made for one check (a temporary
    file, gone when the check ends; drawn from the grade's secret) is named by the public
    scene it varies, common/scenes/cornell.json, and the output by a file of the student's."""
    path = pathlib.Path(binary)
    shown = _home_binary.get() or (f"./{path.name}" if path.parent == ROOT else str(path))
    words = [*launcher, shown]
    scene_path = pathlib.Path(scene) if scene is not None else None
    args = list(args)
    for i, word in enumerate(args):
        if i and args[i - 1] == "--pfm":
            word = "out.pfm"
        elif i and args[i - 1] == "--scene" and scene_path is not None:
            inside = scene_path.resolve().is_relative_to(ROOT) and scene_path.exists()
            word = (str(scene_path.resolve().relative_to(ROOT)) if inside
                    else "common/scenes/cornell.json")
        words.append(word)
    return " ".join(words)


# OpenMPI's error classes students meet, in their words (the MPI standard's meaning).
MPI_ERRORS = {
    "MPI_ERR_TRUNCATE": "a message longer than the receive's buffer: the receive's count or "
                        "type does not match the send's",
    "MPI_ERR_COUNT": "a negative or impossible count",
    "MPI_ERR_TYPE": "an invalid datatype",
    "MPI_ERR_RANK": "a rank that does not exist in the communicator",
    "MPI_ERR_TAG": "an invalid tag",
    "MPI_ERR_BUFFER": "an invalid buffer pointer",
    "MPI_ERR_ARG": "an invalid argument",
}


def failure_message(failure: str, stderr: str, launcher: Sequence[str], home: str) -> str:
    """A failed run in the order a student acts on it: the symptom, its cause where it is
    identified (an MPI error by name, a deadlock), the command to rerun it, then the program's
    and mpirun's own last words."""
    cause = ""
    error = re.search(r"\bMPI_ERR_[A-Z_]+", stderr)
    call = re.search(r"An error occurred in (MPI_\w+)", stderr)
    if error:
        meaning = MPI_ERRORS.get(error.group(0), "see the MPI standard")
        where = f" in {call.group(1)}" if call else ""
        cause = f"; an MPI error{where}: {error.group(0)} ({meaning})"
    elif "timed out" in failure and any("mpirun" in str(w) for w in launcher):
        cause = ("; a rank waits for a message that never comes (a deadlock: a receive with "
                 "no matching send, or two ranks that both receive first)")
    said = stderr.strip()[-1500:]
    return f"{failure}{cause}; rerun: {home}" + (f"; it said: {said}" if said else "")


def _summary(stdout: str) -> dict | None:
    """The --json summary: the last line of stdout, when it is a JSON object."""
    lines = stdout.strip().splitlines()
    try:
        value = json.loads(lines[-1]) if lines else None
    except ValueError:
        return None
    return value if isinstance(value, dict) else None


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


# The least speedup that counts as shown. Measured on a two-core VM while other jobs started
# and stopped (2026-12-02): lab 01's reference timed against itself came out 1.26x (1.522 s
# against 1.210 s, best of 5 each, interleaved), with 1.59 cores' worth of capacity, whose
# 0.75 would have asked only 1.19x. A correct parallel lab on two cores shows 1.8x and more.
NOISE_FLOOR = 1.4


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
        1.8x at two MPI ranks) are shown by the benchmarks on a quiet machine. Never less
        than NOISE_FLOOR: on a machine whose load comes and goes, best-of-rounds timings of
        one serial program against itself differ by more than the capacity's fraction
        allows (below), and a serial hand-in must not pass by that."""
        return max(fraction * self.capacity, NOISE_FLOOR)

    def describe(self, name: str) -> str:
        return (f"{name} {self.speedup(name):.2f}x over the serial reference ({self.base:.3f} s "
                f"-> {self.best[name]:.3f} s) on {self.cores} cores giving "
                f"{self.capacity:.2f}x capacity; needs >= {self.required():.2f}x")


def measure_parallel(baseline: Callable[[], float], candidates: dict[str, Callable[[], float]],
                     rounds: int = 5,
                     together: Callable[[int], float] | None = None) -> ParallelTiming:
    """Interleaved rounds of: the baseline alone, `cores` copies of the baseline at once (the
    capacity: about `cores` when idle, close to 1 when other users' jobs share the CPUs, and
    then no program can show a speedup), and each candidate. Best of `rounds` each.

    `together(n)` (seconds for n copies at once, in one process tree) measures the copies as
    one program: where the kernel shares the CPUs by session (sched_autogroup), copies started
    as separate sessions get a share each, which a multithreaded program, one session, never
    gets; the grader's checks pass it. Without it the copies run from threads."""
    cores = available_cores()
    single, side_by_side_times = [], []
    times: dict[str, list[float]] = {name: [] for name in candidates}
    with concurrent.futures.ThreadPoolExecutor(cores) as pool:
        for _ in range(rounds):
            single.append(baseline())
            if together is not None:
                side_by_side_times.append(together(cores))
            else:
                side_by_side = list(pool.map(lambda _: baseline(), range(cores)))
                side_by_side_times.append(sum(side_by_side) / len(side_by_side))
            for name, candidate in candidates.items():
                times[name].append(candidate())
    together_times = side_by_side_times
    base = min(single)
    capacity = min(cores, cores * base / min(together_times))
    return ParallelTiming(cores, capacity, base, {n: min(t) for n, t in times.items()})
