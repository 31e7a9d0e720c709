"""A class graded as a Slurm job array, where it outgrows one machine.

    make grade-slurm LAB=NN SUBMISSIONS=DIR [REPORT=DIR] [PARTITION=P] [TIME=H:MM:SS]
                     [MEM=SIZE] [PYTHON=python3] [ONLY=flagged]
    python3 -m grading.classes.slurm NN SUBMISSIONS --out REPORT [--partition P] [--time T]
                                     [--mem M] [--python NAME] [--only flagged] [--no-submit]

One array task per submission (`python3 -m grading.classes.batch ... --task K`: the K-th in name
order, in its own grader process, in the sandbox, with the batch's hidden-scene secret that
this step saves in REPORT before anything is submitted), then a merge job that runs once every
task has ended, however it ended (`--dependency=afterany`), and writes grades.csv and
report.html from the tasks' results.json (`--merge`). Each task asks for one whole node
(`--exclusive`): CPU labs are graded on speed, which another grade on the same cores would
distort. Each task asks for --time (default TIME, one hour: a grade's own budget is 40
minutes) and --mem (default MEM, 4G), on --partition where given (else the cluster's
default); the scripts call Python by name (--python, default python3, found on the node's
PATH), never by this machine's absolute path. What was asked is printed and written at the
top of each script. The references are built here once, before anything is submitted; the
tasks grade with --no-build (grading/references.py). The scripts are written to REPORT
(grade-array.sbatch, merge.sbatch) and submitted with sbatch, whose job ids are printed;
--no-submit only writes them. The repository must be on a file system every node sees (it
is each task's working directory). `--only flagged` (ONLY=flagged, as the merge's log
advises) submits only the tasks of the students REPORT flagged (or never graded), with the
saved secret, and the merge again.
"""
from __future__ import annotations

import argparse
import os
import pathlib
import shlex
import shutil
import subprocess
import sys
import tempfile

from grading import references, shown
from grading.classes import batch
from grading.grade import RUBRICS
from labkit.harness import ROOT


def students(submissions: pathlib.Path, out: pathlib.Path) -> list[str]:
    """The class's students in task order (what `--task K` of grading.batch grades)."""
    found = batch.submissions(submissions, out / ".unpacked")
    return list(batch.by_export(found, batch.export_submitters(submissions)))


DEFAULT_TIME = "01:00:00"
DEFAULT_MEM = "4G"
DEFAULT_PYTHON = "python3"


def asked(partition: str | None, time_limit: str, mem: str, python: str) -> str:
    """What the scripts ask of Slurm, in one line, and how to change it."""
    return (f"each task: --time={time_limit} --mem={mem} "
            f"{f'--partition={partition}' if partition else '(the default partition)'}, "
            f"{python} on the node's PATH (make grade-slurm TIME= MEM= PARTITION= PYTHON= "
            f"change them)")


def flagged_tasks(found: list[str], out: pathlib.Path) -> list[int]:
    """The task numbers of the students an earlier run of REPORT flagged or never graded."""
    return [k for k, student in enumerate(found)
            if (row := batch.previous(out, student)) is None or batch.flagged(row)]


def scripts(lab: str, submissions: pathlib.Path, out: pathlib.Path, n: int,
            partition: str | None, run_seconds: float | None, time_limit: str = DEFAULT_TIME,
            mem: str = DEFAULT_MEM, python: str = DEFAULT_PYTHON,
            tasks: list[int] | None = None) -> tuple[str, str]:
    """(the array job's script, the merge job's script); `tasks`: only these task numbers."""
    # Paths on a directive line stay on it (a newline would add a directive of its own):
    # one cleaner for everything shown or run (grading/shown.py).
    def q(text: object) -> str:
        return shlex.quote(shown.line(text))
    out_line = shown.line(str(out))
    part = f"#SBATCH --partition={shown.line(partition)}\n" if partition else ""
    part += f"#SBATCH --time={shown.line(time_limit)}\n#SBATCH --mem={shown.line(mem)}\n"
    part += f"# {shown.line(asked(partition, time_limit, mem, python))}\n"
    extra = f" --run-seconds {run_seconds:g}" if run_seconds else ""
    common = (f"cd {q(str(ROOT))}\n"
              f"{q(python)} -m grading.classes.batch {lab} {q(str(submissions))} "
              f"--out {q(str(out))}{extra}")
    array = f"""#!/bin/bash
#SBATCH --job-name=grade-lab{lab}
#SBATCH --array={",".join(map(str, tasks)) if tasks is not None else f"0-{n - 1}"}
#SBATCH --exclusive
#SBATCH --nodes=1
#SBATCH --output={out_line}/slurm-%A_%a.log
{part}# One submission per task: the K-th in name order (grading/classes/slurm.py).
{common} --task "$SLURM_ARRAY_TASK_ID"
"""
    merge = f"""#!/bin/bash
#SBATCH --job-name=grade-lab{lab}-merge
#SBATCH --nodes=1
#SBATCH --output={out_line}/slurm-merge-%j.log
{part}# grades.csv and report.html from every task's results.json (grading/classes/slurm.py).
{common} --merge
"""
    return array, merge


def sbatch(*args: str) -> str:
    p = subprocess.run(["sbatch", "--parsable", *args], capture_output=True, text=True)
    if p.returncode != 0:
        raise RuntimeError((p.stderr.strip().splitlines() or ["sbatch failed"])[-1])
    return p.stdout.strip().split(";")[0]


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("lab", choices=sorted(RUBRICS))
    p.add_argument("submissions", type=pathlib.Path)
    p.add_argument("--out", type=pathlib.Path, default=pathlib.Path("grades"))
    p.add_argument("--partition")
    p.add_argument("--run-seconds", type=float)
    p.add_argument("--time", default=DEFAULT_TIME, help=f"each task's --time ({DEFAULT_TIME})")
    p.add_argument("--mem", default=DEFAULT_MEM, help=f"each task's --mem ({DEFAULT_MEM})")
    p.add_argument("--python", default=DEFAULT_PYTHON,
                   help=f"the Python the tasks run, by name ({DEFAULT_PYTHON})")
    p.add_argument("--only", choices=["flagged"],
                   help="regrade only the students an earlier run of REPORT flagged")
    p.add_argument("--no-submit", action="store_true", help="write the scripts only")
    a = p.parse_args(argv)
    submissions, out = a.submissions.absolute(), a.out.absolute()
    if not submissions.is_dir():
        print(f"error: grade-slurm: {submissions}: not a folder of submissions", file=sys.stderr)
        return 2
    if not a.no_submit and shutil.which("sbatch") is None:
        print("error: grade-slurm: no sbatch here (Slurm's client, Debian's slurm-client); "
              "--no-submit writes the scripts only", file=sys.stderr)
        return 2
    line = references.build(a.lab)  # built once: the tasks run with --no-build, side by side
    if line:
        print(f"error: grade-slurm: {line}", file=sys.stderr)
        return 2
    batch.batch_secret(out)  # saved before any task starts: all of them read it
    found = students(submissions, out)
    n = len(found)
    if n == 0:
        print(f"error: grade-slurm: no submissions in {submissions}", file=sys.stderr)
        return 2
    tasks = None
    if a.only:
        if not any(out.glob("*/results.json")):
            print(f"error: grade-slurm: ONLY=flagged needs an earlier run's report in {out}",
                  file=sys.stderr)
            return 2
        tasks = flagged_tasks(found, out)
        if not tasks:
            print(f"no student of {out} is flagged: nothing to regrade")
            return 0
        n = len(tasks)
    array, merge = scripts(a.lab, submissions, out, n, a.partition, a.run_seconds,
                           a.time, a.mem, a.python, tasks)
    print(asked(a.partition, a.time, a.mem, a.python))
    paths = []
    for name, text in (("grade-array.sbatch", array), ("merge.sbatch", merge)):
        with tempfile.NamedTemporaryFile("w", dir=out, delete=False, suffix=".partial") as f:
            f.write(text)
        os.replace(f.name, out / name)
        paths.append(out / name)
    if a.no_submit:
        print(f"wrote {paths[0]} ({n} tasks) and {paths[1]}")
        return 0
    try:
        array_id = sbatch(str(paths[0]))
        merge_id = sbatch(f"--dependency=afterany:{array_id}", str(paths[1]))
    except RuntimeError as e:
        print(f"error: grade-slurm: {e}", file=sys.stderr)
        return 2
    print(f"submitted job array {array_id} ({n} tasks) and merge job {merge_id}: "
          f"{out / 'grades.csv'} when it ends")
    return 0


if __name__ == "__main__":
    sys.exit(main())
