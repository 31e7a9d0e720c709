"""The trusted references a grade runs, built before any grade starts and checked to run.

Graders side by side in one checkout (a batch, a Slurm array, a GPU batch) must never run a
reference while it is rewritten. The Makefile leaves a reference alone while it is up to date
and replaces it by a rename when it relinks (INTO_TARGET), so a grader runs the old file or the
new one; a batch builds the references once, before its first grader starts, and its graders
run with --no-build, so none of them runs make at all. A reference that cannot render a pixel
is the machine's fault, never the submission's: the grade is refused, marked for regrade.
"""
from __future__ import annotations

import pathlib

from labkit import gpu, registry
from labkit.harness import ROOT, RunPolicy, make_in_root, policy, run_lab


def names(lab: str) -> list[str]:
    """The references lab `lab`'s grade runs: lab01-ref always (every speedup's baseline, the
    hidden scene's golden data), lab04-ref for an MPI lab (mpirun's start-up), the lab's own
    for a GPU lab (the baseline of its speed)."""
    wanted = ["lab01-ref"]
    if registry.lab(lab).kind == "mpi":
        wanted.append("lab04-ref")
    if gpu.is_gpu_lab(lab):
        wanted.append(f"lab{lab}-ref")
    return wanted


def build(lab: str) -> str | None:
    """`make` lab `lab`'s references (nothing is relinked while they are up to date); None,
    or make's last line of error in one line."""
    p = make_in_root(*names(lab), capture_output=True, text=True, errors="replace")
    if p.returncode == 0:
        return None
    said = (p.stderr.strip() or p.stdout.strip()).splitlines()[-1:] or [f"status {p.returncode}"]
    return f"make {' '.join(names(lab))} failed: {said[0][:300]}"


def problem(lab: str) -> str | None:
    """Why a CPU reference of lab `lab` cannot be run now, in one line marked for regrade, or
    None: each must exist and render one pixel, trusted. A GPU lab's own reference is checked
    on the GPU, in the sandbox too, by grade.gpu_problem."""
    for name in names(lab):
        if name != "lab01-ref" and gpu.is_gpu_lab(lab):
            continue
        path = ROOT / name
        if not path.is_file():
            return (f"the reference {name} is not built (make {name}); not graded, marked "
                    f"for regrade")
        with policy(RunPolicy(trusted=True)):
            try:
                run = run_lab(path, width=1, height=1, spp=1, check=False, timeout=60)
            except OSError as e:
                run, said = None, str(e)
        if run is not None and run.returncode == 0 and run.image is not None:
            continue
        if run is not None:
            said = (run.stderr.strip().splitlines()[-1:] or [f"exit status {run.returncode}"])[0]
        return (f"the reference {name} cannot run on this machine ({said[:300]}); not graded, "
                f"marked for regrade")
    return None


def missing(lab: str) -> list[pathlib.Path]:
    """The references of lab `lab` that are not built."""
    return [ROOT / n for n in names(lab) if not (ROOT / n).is_file()]
