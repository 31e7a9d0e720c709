"""Lab 04's ranks: every distribution of rows, and threads within each rank (mpirun as
the grader, the tools and the tests start it is labkit/mpi.py)."""
from __future__ import annotations

import math
import re

from grading.checks.check_result import CheckResult
from grading.checks.identity import row_ranges
from labkit.harness import run_lab
from labkit.mpi import mpirun

DISTRIBUTIONS = ("block", "interleaved", "dynamic")


def report_rows(stderr: str) -> dict[int, set[int]]:
    """RT_MPI_REPORT's lines ("rank 1: ... : rows 1,4,7-9"): {rank: the rows it rendered}."""
    rows: dict[int, set[int]] = {}
    for rank, ranges in re.findall(r"^rank (\d+): .*: rows (\S+)$", stderr, re.M):
        rows[int(rank)] = set()
        for part in ranges.split(","):
            first, _, last = part.partition("-")
            if first.isdigit() and (not last or last.isdigit()):
                rows[int(rank)].update(range(int(first), int(last or first) + 1))
    return rows


def check_distributions(binary, ranks: int = 3, width: int = 16, height: int = 12) -> CheckResult:
    """Lab 04's tasks 2 and 3, which the image cannot show (every distribution renders lab
    01's bits, blocks included): the rows each rank rendered, as RT_MPI_REPORT lists them,
    for `ranks` ranks: interleaved is every `ranks`-th row from the rank's own; dynamic is
    not the fixed bands of block. Half the points each."""
    bands = {r: set(range(height * r // ranks, height * (r + 1) // ranks)) for r in range(ranks)}
    verdicts = []
    for distribution in ("interleaved", "dynamic"):
        run = run_lab(binary, width=width, height=height, spp=2,
                      launcher=mpirun(ranks, distribution, "RT_MPI_REPORT=1"))
        rows = report_rows(run.stderr)
        if sorted(rows) != list(range(ranks)) or set().union(*rows.values()) != set(range(height)):
            verdicts.append((False, f"{distribution}: RT_MPI_REPORT=1 does not list every "
                                    f"row once among ranks 0-{ranks - 1}"))
        elif distribution == "interleaved":
            want = {r: set(range(r, height, ranks)) for r in range(ranks)}
            verdicts.append((rows == want, f"interleaved: rank 1 rendered rows "
                                           f"{row_ranges(sorted(rows[1]))}" + (
                "" if rows == want else f", not {row_ranges(sorted(want[1]))} (rank r renders "
                                        f"rows r, r + {ranks}, ...: task 2 undone?)")))
        else:
            verdicts.append((rows != bands, "dynamic: " + (
                "rows handed out as ranks finish" if rows != bands else
                "the rows were split into block's fixed bands (task 3, the master and its "
                "workers, undone?)")))
    passed = sum(ok for ok, _ in verdicts)
    detail = f"{ranks} ranks, {width}x{height}: " + "; ".join(text for _, text in verdicts)
    return CheckResult("rows per distribution", passed == len(verdicts), detail,
                       credit=passed / len(verdicts))


# A rank's --threads share its rows (handout 04, task 4) when its busiest thread did less than
# this part of the run's CPU time: two threads sharing the work do about half each; one rank
# whose loop is not threaded does nearly all of it, less only mpirun's own start-up, which a
# render of HYBRID_SETTINGS (about 2 s of CPU time on the course's two-core VM) keeps small.
HYBRID_SHARED = 0.7
HYBRID_SETTINGS = dict(width=256, height=256, spp=128)


def check_hybrid_threads(binary, threads: int = 2) -> CheckResult:
    """Lab 04's task 4, which the image cannot show (an unthreaded rank renders the same
    bits): one rank run with `threads` OpenMP threads, and the CPU time of each of its threads
    measured by the grader (as lab 03's serial check does). Passes where no thread did
    HYBRID_SHARED of the work, at any load: a thread's share does not depend on the cores
    the machine gave."""
    run = run_lab(binary, **HYBRID_SETTINGS, threads=threads, launcher=mpirun(1))
    share = run.thread_share
    if math.isnan(share):
        return CheckResult("hybrid threads", True, "the threads' CPU time could not be measured "
                           "here; marked for regrade", regrade=True, credit=0.0, provisional=1.0)
    shared = share < HYBRID_SHARED
    detail = (f"1 rank x {threads} threads, {HYBRID_SETTINGS['width']}x"
              f"{HYBRID_SETTINGS['height']} at {HYBRID_SETTINGS['spp']} spp: its busiest thread "
              f"did {share:.0%} of the CPU time (measured by the grader, thread by thread)")
    if not shared:
        detail += ("; one thread did the rank's work: the rows a rank renders are shared among "
                   "its --threads with an OpenMP loop (task 4, hybrid, undone?)")
    return CheckResult("hybrid threads", shared, detail, credit=1.0 if shared else 0.0)
