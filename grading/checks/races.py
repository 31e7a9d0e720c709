"""Lab 03's races that no image shows: the hand-in built for ThreadSanitizer (LLVM's OpenMP and
its Archer tool: grading/grading.mk's race-variant) and run on a small scene.

A variable the threads share where each needs its own (a pixel or sample index declared
outside the parallel loop) is a data race whose image is often right: the optimiser keeps the
index in a register, so every render is lab 01's bits and every other check passes. Built at
-O0 the shared variable lives in memory, and ThreadSanitizer sees two threads write it with
nothing ordering them. It reports what happened in this run only (a race on a path the run
did not take is not seen), with no false reports on OpenMP's own synchronisation once Archer
tells it what OpenMP's barriers order (measured: the reference is clean at 2 and 4 threads)."""
from __future__ import annotations

import dataclasses
import pathlib
import re
import shutil

from grading.checks.check_result import CheckResult
from labkit import sandbox
from labkit.harness import ROOT, current_policy, make_in_root, policy, run_lab

RUBRICS = {"openmp"}  # the rubric kinds whose labs are graded for races (lab 03's)

# A small render: every thread takes rows, every row many samples; under ThreadSanitizer a
# run is ~10x slower, about a second here.
RACE_SETTINGS = dict(width=64, height=64, spp=8, seed=7)
RACE_THREADS = (2, 4)
# A race shows only where two threads ran the loop at once: a run whose busiest thread did
# SHARED of the CPU time (on a busy machine the others may not have started before it
# finished the rows) tells nothing, and is run again, up to ATTEMPTS times.
SHARED = 0.9
ATTEMPTS = 3
# ThreadSanitizer reports every race (not only the first) and exits with RACE_STATUS; Archer's
# note about libomp's own uninstrumented code is followed (ignore_noninstrumented_modules).
RACE_STATUS = 66
# The one option a run at home needs too (the rerun line gives it).
HOME_OPTIONS = "ignore_noninstrumented_modules=1"
TSAN_OPTIONS = f"exitcode={RACE_STATUS} halt_on_error=0 {HOME_OPTIONS} history_size=2"
# ThreadSanitizer reserves its shadow memory as address space, many times RLIMIT_AS's 4 GiB:
# the run is limited by time, CPU and files as every run is, not by address space (as CUDA's).

SUMMARY = re.compile(r"SUMMARY: ThreadSanitizer: data race (\S+?):(\d+)(?::(\d+))? in (\S+)")


def build(lab_folder: str, sources: pathlib.Path | None,
          trusted: bool) -> tuple[pathlib.Path | None, str]:
    """(the ThreadSanitizer binary, "") or (None, why). As the lab's own binary is built: at
    home (`make grade`) `make lab03-race` of labs/03-openmp/skeleton; a hand-in (--sources)
    in the sandbox, in the lab's students' tree (make race-variant)."""
    if shutil.which("clang++") is None:
        return None, "clang++ is missing on the grading machine (make deps installs it)"
    if sources is None:
        p = make_in_root("lab03-race", capture_output=True, text=True, errors="replace")
        return (ROOT / "lab03-race", "") if p.returncode == 0 else (None, p.stdout + p.stderr)
    from grading.compile import build_in_sandbox
    binary, errors, _ = build_in_sandbox(lab_folder, sources, "race-variant", trusted=trusted)
    return binary, errors


def where(summary: re.Match) -> str:
    """`render.cpp line 64` of a report's summary, the file by its own name."""
    path, line = summary.group(1), summary.group(2)
    return f"{path.rsplit('/', 1)[-1]} line {line}"


def check_races(binary, threads=RACE_THREADS) -> CheckResult:
    """Runs the ThreadSanitizer build at each thread count; fails naming the first race's
    place in the hand-in's code, with the command to see the report at home."""
    launcher = ["/usr/bin/env", f"TSAN_OPTIONS={TSAN_OPTIONS}"]
    now = current_policy()
    if not now.trusted and sandbox.isolation() == sandbox.USER:
        # LLVM's OpenMP registers itself in a file of /dev/shm or /tmp at start-up and stops
        # where it cannot (OMP Error #179); the user sandbox gives a run neither, as both are
        # shared there. Where bubblewrap runs (a course machine) the check is made.
        return CheckResult("no data race", True,
                           "not run in the user sandbox, which gives a run no /dev/shm or /tmp "
                           "that LLVM's OpenMP needs to start; marked for regrade where "
                           "bubblewrap runs", regrade=True, credit=0.0, provisional=1.0)
    unbounded = dataclasses.replace(now, limits=dataclasses.replace(now.limits, memory_bytes=None))
    for count in threads:
        for _ in range(ATTEMPTS):
            with policy(unbounded):
                run = run_lab(binary, **RACE_SETTINGS, threads=count, launcher=launcher,
                              check=False)
            if run.returncode == RACE_STATUS or not run.thread_share >= SHARED:
                break
        races = list(SUMMARY.finditer(run.stderr))
        if run.returncode == RACE_STATUS or races:
            places = sorted({where(m) for m in races})
            again = " ".join([f"TSAN_OPTIONS={HOME_OPTIONS}", "./lab03-race",
                              "--threads", str(count),
                              *(f"--{k} {v}" for k, v in RACE_SETTINGS.items())])
            return CheckResult(
                "no data race", False,
                f"a data race at {count} threads, found by ThreadSanitizer: "
                f"{', '.join(places) or 'in the program'} "
                f"({len(races)} report{'s' if len(races) != 1 else ''}): two threads touch the "
                f"same variable there, at least one writing, with nothing ordering them. A "
                f"variable each thread needs its own (an index, a sample's state) must be "
                f"declared inside the parallel loop; the image may well be right, as the "
                f"compiler kept it in a register this time; rerun: make lab03-race && "
                f"{again}", credit=0.0)
        if run.returncode != 0 or run.image is None:
            return CheckResult("no data race", False,
                               f"the ThreadSanitizer build did not render at {count} threads "
                               f"(exit status {run.returncode}): {run.stderr.strip()[-300:]}",
                               credit=0.0)
    counts = " and ".join(str(t) for t in threads)
    return CheckResult("no data race", True,
                       f"ThreadSanitizer saw no data race at {counts} threads "
                       f"({RACE_SETTINGS['width']}x{RACE_SETTINGS['height']}, "
                       f"{RACE_SETTINGS['spp']} spp)", credit=1.0)
