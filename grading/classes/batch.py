"""Grade a whole class: one folder per student, graded one after the other, each in its own
grader process (a grader that dies on one submission does not take the class with it), all
with the same hidden scene; a CSV for the gradebook and an HTML page to read.

    python3 -m grading.classes.batch 01 SUBMISSIONS --out REPORT
    make grade-batch LAB=01 SUBMISSIONS=DIR REPORT=DIR

SUBMISSIONS may be Gradescope's export of the assignment, unzipped as it comes
(submission_<id>/ folders and submission_metadata.yml): grades.csv is then keyed by the
export's submission ids and names each one's submitters. Otherwise SUBMISSIONS/<student>/
holds the student's hand-in (its files, at the top or in one folder below:
grading/releases/handin.py finds them); SUBMISSIONS/<student>.zip is a hand-in zip as `make
handin` writes it. A hand-in is graded from its sources, always: a program in it is never run
(grading a built program is `python3 -m grading.grade --binary`, course staff's choice on their
command line). A zip over the intake's limits, or one that cannot be read, is refused in one
line, which becomes that student's cause; a metadata file that cannot be read costs the names,
never the grades.
REPORT/<student>/results.json is each student's results.json; REPORT/grades.csv and
REPORT/report.html sum them up: per student the points, the provisional points apart (a check
the machine was too busy to measure), the timed seconds, speedup and capacity, and the cause of
a failure (compile error, crash, timeout, race, work split, which image check); a last row sums
up the class and counts the flagged (provisional, or not graded for the machine's sake: regrade
those on a quiet machine). Progress goes to stdout as `[k/N] name ...` with an estimate of the
time left.
"""
from __future__ import annotations

import argparse
import concurrent.futures
import csv
import json
import os
import pathlib
import queue
import re
import shutil
import subprocess
import sys
import tempfile
import threading
import time
import zipfile

from grading import references, shown
from grading.checks import hidden
from grading.classes import class_page
from grading.classes.verdicts import failure_cause, flagged, provisional_points
from grading.grade import BUDGET_SECONDS, RUBRICS
from grading.speed_numbers import speed_numbers
from labkit import gpu, sandbox
from labkit.harness import ROOT

# A grade ends within the grader's budget (grade.BUDGET_SECONDS) plus a compile; a grader
# still running well past it is stopped (SIGTERM: it writes its results and cleans up, then
# SIGKILL), so that one hand-in never holds up the class.
GRADER_SECONDS = BUDGET_SECONDS + 20 * 60
STOP_GRACE_SECONDS = 60


def grader_command(lab: str, folder: pathlib.Path, out: pathlib.Path, extra: list[str]) -> list:
    return [sys.executable, "-m", "grading.grade", lab, "--sources", str(folder),
            "--results", str(out / "results.json"), "--heatmaps", str(out / "heatmaps"), *extra]


def grade_one(lab: str, folder: pathlib.Path, out: pathlib.Path, extra: list[str],
              env: dict) -> dict:
    """One student's grade, from the hand-in's sources (anything else in it is named in
    results.json and never run)."""
    out.mkdir(parents=True, exist_ok=True)
    results = out / "results.json"
    stopped = ""
    with (out / "grader.log").open("w") as log:
        grader = subprocess.Popen(grader_command(lab, folder, out, extra), cwd=ROOT, env=env,
                                  stdout=log, stderr=subprocess.STDOUT)
        try:
            grader.wait(timeout=GRADER_SECONDS)
        except subprocess.TimeoutExpired:
            stopped = f"the grader did not finish in {GRADER_SECONDS:g} s and was stopped"
            grader.terminate()
            try:
                grader.wait(timeout=STOP_GRACE_SECONDS)
            except subprocess.TimeoutExpired:
                grader.kill()
                grader.wait()
    try:
        graded = json.loads(results.read_text())
    except (OSError, ValueError) as e:  # the grader always writes one; say so if it did not
        graded = {"score": 0, "output": f"the grader left no results.json: {e}", "tests": []}
    if stopped:  # said in results.json too, where a later merge reads it
        graded["output"] = f"{stopped}\n{graded.get('output', '')}".rstrip()
        results.write_text(json.dumps(graded, indent=2))
    return graded


def refused_results(lab: str, reason: str) -> dict:
    """results.json's content for a hand-in refused before any grader ran (a zip over the
    intake's limits): every check of the rubric 0, saying why; final, not flagged."""
    from grading.results import Results, Test
    results = Results()
    results.add_all(Test(i.id, i.label, i.points, visibility=i.visibility) for i in RUBRICS[lab])
    results.refuse(f"the hand-in was refused: {reason}")
    return results.as_dict()


class CleanWriter:
    """csv.writer whose every cell passes shown.cell: a name or a compiler's line that a
    spreadsheet would run as a formula is shown as text."""

    def __init__(self, f):
        self.writer = csv.writer(f)

    def writerow(self, cells) -> None:
        self.writer.writerow([shown.cell(c) for c in cells])


COLUMNS = ["student", "score", "max_score", "provisional_points", "flagged", "reference_s",
           "yours_s", "speedup", "capacity", "cause"]


def write_csv(path: pathlib.Path, lab: str, rows: dict[str, dict],
              submitters: dict[str, str] | None = None) -> None:
    """One row per student, then a summary row ("(class)": mean score, flagged count). The
    cause column is the instructor's: the check's own words, not the student hints. For a
    Gradescope export (`submitters`) each row is keyed by the export's submission id, and
    names its submitters."""
    labels = [i.label for i in RUBRICS[lab]]
    with path.open("w", newline="") as f:
        w = CleanWriter(f)
        head = ["submission_id", "submitters"] if submitters is not None else []
        w.writerow([*head, *COLUMNS, *labels])
        for student, r in rows.items():
            by_name = {t["name"]: t for t in r.get("tests", [])}
            numbers = speed_numbers(r)
            key = [submission_id(student), submitters.get(student, "")] \
                if submitters is not None else []
            w.writerow(
                [
                    *key,
                    student,
                    r.get("score", 0),
                    r.get("max_score", ""),
                    provisional_points(r),
                    "yes" if flagged(r) else "",
                    numbers["reference_s"],
                    numbers["yours_s"],
                    numbers["speedup"],
                    numbers["capacity"],
                    failure_cause(r),
                    *(by_name.get(label, {}).get("score", "") for label in labels),
                ]
            )
        w.writerow([*(["", ""] if submitters is not None else []),
                    *summary_row(lab, rows, labels)])


def summary_row(lab: str, rows: dict[str, dict], labels: list[str]) -> list:
    n = len(rows)
    scores = [r.get("score", 0) for r in rows.values()]
    mean = f"{sum(scores) / n:.1f}" if n else ""
    count = sum(flagged(r) for r in rows.values())
    passed = []
    for label in labels:
        ok = sum(any(t["name"] == label and t.get("status") == "passed" for t in r.get("tests", []))
                 for r in rows.values())
        passed.append(f"{ok}/{n} passed")
    return [
        f"(class: {n} students)",
        f"mean {mean}",
        max((r.get("max_score", 0) for r in rows.values()), default=""),
        sum(provisional_points(r) for r in rows.values()),
        f"{count} flagged",
        "",
        "",
        "",
        "",
        f"{sum(bool(failure_cause(r)) for r in rows.values())} lost points",
        *passed,
    ]


EXPORT_METADATA = "submission_metadata.yml"


class MetadataError(Exception):
    """submission_metadata.yml cannot be read as a whole: one line."""


MAX_METADATA_BYTES = 16 << 20  # an export of a few thousand submissions is a few MiB
UNREADABLE = "(unreadable in submission_metadata.yml)"


def _yaml_loader():
    """PyYAML's safe loader, reading a tag it does not know (Ruby's, or a hostile
    `!!python/...`) as an empty value instead of stopping: nothing is ever constructed."""
    import yaml

    class Loader(yaml.SafeLoader):
        pass
    Loader.add_constructor(None, lambda loader, node: None)
    return yaml, Loader


def _submitters(meta) -> list[dict[str, str]] | None:
    """One folder's submitters, or None where the entry is not what the export writes."""
    people = meta.get(":submitters") if isinstance(meta, dict) else None
    if not isinstance(people, list) or not all(
            isinstance(p, dict) and all(isinstance(v, (str, int, float)) for v in p.values())
            for p in people):
        return None  # a list, a tag read as nothing, where text belongs
    return [{_text(k).lstrip(":"): _text(v) for k, v in person.items()} for person in people]


def _text(value) -> str:
    """A YAML value as text: a character beyond U+FFFF escaped as a surrogate pair (as a
    JSON-style writer does) joined into one; a lone surrogate, which no file name can hold,
    read as U+FFFD."""
    return str(value).encode("utf-16", "surrogatepass").decode("utf-16", "replace")


def parse_export_metadata(text: str) -> dict[str, list[dict[str, str]] | None]:
    """Gradescope's submission_metadata.yml: folder -> its submitters (":name", ":sid",
    ":email" without the colons), None for an entry that is not what the export writes.
    With PyYAML where installed; else this subset of YAML, which is all the export writes for
    the fields read here. MetadataError when the file as a whole cannot be read."""
    try:
        yaml, loader = _yaml_loader()
    except ImportError:
        yaml = None
    if yaml is not None:
        try:
            data = yaml.load(text, Loader=loader) or {}
        except (yaml.YAMLError, RecursionError, ValueError) as e:
            raise MetadataError(f"not YAML: {shown.line(str(e).splitlines()[0])}") from None
        if not isinstance(data, dict):
            raise MetadataError(f"a {type(data).__name__} where a map of submission "
                                f"folders belongs")
        return {_text(folder): _submitters(meta) for folder, meta in data.items()}
    found: dict[str, list[dict[str, str]]] = {}
    folder, person = None, None
    for line in text.splitlines():
        if re.match(r"^[^\s#][^:]*:\s*$", line):
            folder, person = line.rstrip()[:-1].strip("'\""), None
            found[folder] = []
            continue
        m = re.match(r"^\s*(- )?\s*:(name|sid|email):\s*(.*?)\s*$", line)
        if folder is not None and m:
            if m.group(1) or person is None:
                person = {}
                found[folder].append(person)
            person[m.group(2)] = m.group(3).strip("'\"")
    return found


def export_submitters(folder: pathlib.Path) -> dict[str, str] | None:
    """Gradescope's export of an assignment (its folder unzipped: submission_<id>/ folders and
    submission_metadata.yml): submission folder -> "name <email> (sid)" of each submitter;
    None for a plain folder of students."""
    path = folder / EXPORT_METADATA
    if not path.is_file():
        return None
    try:
        if path.stat().st_size > MAX_METADATA_BYTES:
            raise MetadataError(f"larger than {MAX_METADATA_BYTES >> 20} MiB")
        parsed = parse_export_metadata(path.read_text(errors="replace"))
    except (MetadataError, OSError) as e:
        # The grades do not depend on it: every submission folder is graded, without names.
        print(f"warning: {path}: {e}; grading every submission_* folder without names",
              file=sys.stderr)
        return {entry.name if entry.is_dir() else entry.stem: UNREADABLE
                for entry in sorted(folder.iterdir())
                if entry.name.startswith("submission_") and (entry.is_dir() or
                                                            entry.suffix == ".zip")}
    bad = [name for name, people in parsed.items() if people is None]
    if bad:
        print(f"warning: {path}: {len(bad)} entries not as the export writes them "
              f"({shown.line(', '.join(bad[:3]))}{' ...' if len(bad) > 3 else ''}); graded "
              f"without names", file=sys.stderr)
    return {name: UNREADABLE if people is None else
            "; ".join(f"{p.get('name', '')} <{p.get('email', '')}> ({p.get('sid', '')})"
                      for p in people)
            for name, people in parsed.items()}


def submission_id(folder_name: str) -> str:
    """The export's id of a submission folder ("submission_123456" -> "123456")."""
    return folder_name.removeprefix("submission_")


SECRET_FILE = ".grading-secret"  # in REPORT: the batch's hidden-scene secret, for regrades


def batch_secret(out: pathlib.Path) -> str:
    """The batch's secret: the one saved in REPORT by an earlier run (a regrade must see the
    same hidden scene as the first grade), else $GRADING_SECRET or a new one, saved there
    (readable by its owner only)."""
    saved = out / SECRET_FILE
    if saved.is_file():
        return saved.read_text().strip()
    secret = hidden.secret_from_environment()
    out.mkdir(parents=True, exist_ok=True)
    fd = os.open(saved, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
    with os.fdopen(fd, "w") as f:
        f.write(secret + "\n")
    return secret


def submissions(folder: pathlib.Path, unpacked: pathlib.Path) -> dict[str, pathlib.Path | str]:
    """Student -> the folder to grade: SUBMISSIONS/<student>/, or SUBMISSIONS/<student>.zip
    unpacked under `unpacked`; or, for a zip refused (over the intake's limits, unreadable),
    the one line saying why, which becomes that student's cause."""
    found: dict[str, pathlib.Path | str] = {}
    for entry in sorted(folder.iterdir()):
        if entry.is_symlink():  # it would grade whatever it points at: a solution, /
            if entry.suffix == ".zip" or entry.is_dir():
                found[entry.stem if entry.suffix == ".zip" else entry.name] = shown.line(
                    f"{entry.name} is a symbolic link: hand in the folder or zip itself")
            continue
        if entry.is_dir():
            found[entry.name] = entry
        elif entry.suffix == ".zip" and entry.is_file():
            target = unpacked / entry.stem
            if not target.is_dir():  # unpacked aside, then renamed: tasks running at once
                partial = unpacked / f".{entry.stem}.partial-{os.getpid()}"
                try:
                    unzip(entry, partial)
                except ZipRefused as e:
                    shutil.rmtree(partial, ignore_errors=True)
                    found.setdefault(entry.stem, shown.line(f"{entry.name}: {e}"))
                    continue
                try:
                    os.rename(partial, target)
                except OSError:  # another task's copy came first
                    shutil.rmtree(partial, ignore_errors=True)
            found.setdefault(entry.stem, target)
    return found


# A hand-in is a few source files of tens of KiB: a zip far beyond that is refused before it
# fills the disk (a 1 MiB zip can unpack to 1 GiB).
ZIP_MAX_BYTES = 64 << 20      # unpacked, all members together
ZIP_MAX_MEMBERS = 4096
ZIP_MAX_DEPTH = 16            # folders above a member
ZIP_MAX_RATIO = 100           # unpacked to packed, once it unpacks to more than 1 MiB


class ZipRefused(Exception):
    """A hand-in zip that is not unpacked: one line."""


def by_export(found: dict[str, pathlib.Path | str],
              submitters: dict[str, str] | None) -> dict[str, pathlib.Path | str]:
    """For a Gradescope export, the submissions its metadata lists, in name order (the order
    Slurm's tasks count in); one it lists without a folder or zip is a row saying so."""
    if submitters is None:
        return found
    return {name: found.get(name, "the export holds no folder or zip of this submission")
            for name in sorted(submitters)}


def unzip(archive: pathlib.Path, target: pathlib.Path) -> None:
    """Unpack a hand-in zip into `target`: no absolute paths, no "..", nothing outside, and
    within the limits above, checked on what the zip declares and again on the bytes it
    actually unpacks (a header may lie). ZipRefused says which limit, or that it cannot be
    read."""
    target.mkdir(parents=True, exist_ok=True)
    try:
        with zipfile.ZipFile(archive) as z:
            members = z.infolist()
            if len(members) > ZIP_MAX_MEMBERS:
                raise ZipRefused(f"{len(members)} members, more than {ZIP_MAX_MEMBERS}")
            declared = sum(m.file_size for m in members)
            deepest = max((len(pathlib.PurePosixPath(m.filename).parts) - 1 for m in members),
                          default=0)
            if deepest > ZIP_MAX_DEPTH:
                raise ZipRefused(f"a member {deepest} folders deep, more than {ZIP_MAX_DEPTH}")
            if declared > ZIP_MAX_BYTES:
                raise ZipRefused(f"unpacks to {declared >> 20} MiB, more than "
                                 f"{ZIP_MAX_BYTES >> 20} MiB")
            _check_ratio(declared, archive.stat().st_size)
            written = 0
            for member in members:
                name = pathlib.PurePosixPath(member.filename)
                if member.is_dir() or name.is_absolute() or ".." in name.parts:
                    continue
                dest = target / name
                dest.parent.mkdir(parents=True, exist_ok=True)
                with z.open(member) as src, dest.open("wb") as dst:
                    while chunk := src.read(1 << 20):
                        written += len(chunk)
                        if written > ZIP_MAX_BYTES:
                            raise ZipRefused(f"unpacks to more than {ZIP_MAX_BYTES >> 20} MiB")
                        dst.write(chunk)
            _check_ratio(written, archive.stat().st_size)
    except (zipfile.BadZipFile, zipfile.LargeZipFile, NotImplementedError, EOFError,
            ValueError, OSError, RuntimeError) as e:
        raise ZipRefused(f"it cannot be read as a zip ({e})") from None


def _check_ratio(unpacked: int, packed: int) -> None:
    if unpacked > 1 << 20 and unpacked > ZIP_MAX_RATIO * max(packed, 1):
        raise ZipRefused(f"it unpacks {unpacked // max(packed, 1)} times its size, more than "
                         f"{ZIP_MAX_RATIO}")


def previous(out: pathlib.Path, student: str) -> dict | None:
    try:
        return json.loads((out / student / "results.json").read_text())
    except (OSError, ValueError):
        return None


def eta(done: int, total: int, elapsed: float) -> str:
    if not done:
        return ""
    left = elapsed / done * (total - done)
    return f", about {left / 60:.0f} min left" if left >= 90 else f", about {left:.0f} s left"


def gpu_indices() -> list[str]:
    """The GPUs to grade on, one submission each at once: CUDA_VISIBLE_DEVICES where set (a
    scheduler's choice), else every GPU nvidia-smi lists; [] where there is none."""
    visible = os.environ.get("CUDA_VISIBLE_DEVICES")
    if visible is not None:
        return [g for g in visible.split(",") if g.strip()]
    try:
        p = subprocess.run(["nvidia-smi", "--query-gpu=index", "--format=csv,noheader"],
                           capture_output=True, text=True, timeout=30)
    except (OSError, subprocess.TimeoutExpired):
        return []
    return [line.strip() for line in p.stdout.splitlines() if line.strip()] \
        if p.returncode == 0 else []


def grade_all(lab: str, todo: list[str], found: dict[str, pathlib.Path | str], out: pathlib.Path,
              extra: list[str], env: dict, rows: dict) -> None:
    """Grade `todo`, printing progress. A GPU lab on a host with several GPUs grades one
    submission per GPU at once (each grader sees one GPU: its speed is timed against the
    reference on that GPU); CPU labs, timed on the CPU's cores, one at a time."""
    gpus = gpu_indices() if gpu.is_gpu_lab(lab) else []
    lanes = max(1, len(gpus))
    free = queue.Queue()
    for g in gpus or [None]:
        free.put(g)
    lock = threading.Lock()
    start, done = time.monotonic(), [0]

    def one(student: str) -> None:
        device = free.get()
        try:
            with lock:
                where = f" on GPU {device}" if device is not None else ""
                print(f"[{done[0] + 1}/{len(todo)}] {shown.line(student)}{where} ..."
                      f"{eta(done[0], len(todo), time.monotonic() - start)}", flush=True)
            # The index counts as nvidia-smi does (PCI bus order), for CUDA and for the
            # sandbox, which shows this GPU's node only (labkit/gpu.py: assigned_node).
            local = env if device is None else {**env, "CUDA_VISIBLE_DEVICES": device,
                                                "CUDA_DEVICE_ORDER": "PCI_BUS_ID"}
            what = found[student]
            if isinstance(what, str):  # refused at intake: its row says why, nothing runs
                r = refused_results(lab, what)
                (out / student).mkdir(parents=True, exist_ok=True)
                (out / student / "results.json").write_text(json.dumps(r, indent=2))
            else:
                r = grade_one(lab, what, out / student, extra, local)
        finally:
            free.put(device)
        with lock:
            rows[student] = r
            done[0] += 1
            note = " (flagged)" if flagged(r) else ""
            print(shown.line(f"[{done[0]}/{len(todo)}] {student}: {r.get('score', 0)}/"
                             f"{r.get('max_score', '')}{note} {failure_cause(r)}"), flush=True)

    if lanes == 1:
        for student in todo:
            one(student)
        return
    print(f"grading on {lanes} GPUs at once", flush=True)
    with concurrent.futures.ThreadPoolExecutor(lanes) as pool:
        list(pool.map(one, todo))


def write_report(out: pathlib.Path, lab: str, rows: dict[str, dict | None],
                 submitters: dict[str, str] | None, regrade: str = "make grade-batch") -> None:
    """grades.csv and report.html; `regrade`: the command that graded the class, which regrades
    its flagged students with ONLY=flagged (a Slurm class's through Slurm again)."""
    rows = {s: r if r is not None else {"score": 0, "output": "not graded", "tests": []}
            for s, r in rows.items()}
    write_csv(out / "grades.csv", lab, rows, submitters)
    class_page.write_html(out / "report.html", lab, rows, [i.label for i in RUBRICS[lab]],
                          submitters)
    count = sum(flagged(r) for r in rows.values())
    print(f"wrote {out / 'grades.csv'} and {out / 'report.html'}: {len(rows)} students, "
          f"{count} flagged{f' (regrade them: {regrade} ... ONLY=flagged)' if count else ''}")


def exposure_problem(folders: list[pathlib.Path]) -> str | None:
    """One line refusing the batch where a student's run could read the class's hand-ins or
    results (the user sandbox without Landlock: labkit/sandbox.py, exposed), else None."""
    if sandbox.probe() is not None:
        return None  # each grader refuses in its own results.json, saying why
    for folder in folders:
        folder.mkdir(parents=True, exist_ok=True)
        if sandbox.exposed(folder):
            return (f"refusing to grade the class: this kernel has no Landlock, so each run, "
                    f"in the user sandbox, could read {shown.line(folder.resolve())}, which "
                    f"every user may enter; close it to other users (chmod 700 "
                    f"{shown.line(folder.resolve())}) or grade where bubblewrap or Landlock "
                    f"works")
    return None


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("lab", choices=sorted(RUBRICS))
    p.add_argument("submissions", type=pathlib.Path)
    p.add_argument("--out", type=pathlib.Path, default=pathlib.Path("grades"))
    p.add_argument("--run-seconds", type=float)
    p.add_argument("--only", choices=["flagged"],
                   help="regrade only the students an earlier run of this REPORT flagged, with "
                        "its saved secret, and merge them into its grades")
    p.add_argument("--task", type=int, metavar="K",
                   help="grade only the K-th submission (from 0, in name order), with REPORT's "
                        "saved secret: one task of a Slurm job array (grading/classes/slurm.py)")
    p.add_argument("--merge", action="store_true",
                   help="grade nothing: write grades.csv and report.html from REPORT's results")
    a = p.parse_args(argv)
    if not a.submissions.is_dir():
        print(f"error: {a.submissions}: not a folder of submissions", file=sys.stderr)
        return 2
    if (a.only or a.task is not None) and not (a.out / SECRET_FILE).is_file():
        print(f"error: {'ONLY=flagged' if a.only else '--task'} needs an earlier batch's "
              f"report in {a.out} (its secret and results); none there", file=sys.stderr)
        return 2
    if not a.merge and (line := exposure_problem([a.submissions, a.out])):
        print(f"error: {line}", file=sys.stderr)
        return 2
    # One secret for the batch, saved for regrades: every student gets the same hidden scene.
    env = {**os.environ, "GRADING_SECRET": batch_secret(a.out)}
    # Graders run side by side (one per GPU, a Slurm array's tasks): none of them runs make.
    # The references are built once, here (a Slurm array's by grading/classes/slurm.py, before it
    # submits), and never rewritten while a grade runs (grading/references.py).
    extra = ["--no-build", *(["--run-seconds", str(a.run_seconds)] if a.run_seconds else [])]
    if a.task is None and not a.merge and (line := references.build(a.lab)):
        print(f"error: {line}", file=sys.stderr)
        return 2
    submitters = export_submitters(a.submissions)
    # A task's zips are unpacked where every task and the merge see them; a whole batch's
    # in a temporary folder.
    keep = a.task is not None or a.merge
    unpacked = (
        a.out / ".unpacked" if keep else pathlib.Path(tempfile.mkdtemp(prefix="grade-batch-"))
    )
    try:
        found = submissions(a.submissions, unpacked)
        found = by_export(found, submitters)
        rows = {student: previous(a.out, student) for student in found}
        if a.merge:  # the last job of a class graded through Slurm (grading/classes/slurm.py)
            write_report(a.out, a.lab, rows, submitters, regrade="make grade-slurm")
            return 0
        if a.task is not None:
            if not 0 <= a.task < len(found):
                print(f"error: --task {a.task}: there are {len(found)} submissions (0 to "
                      f"{len(found) - 1})", file=sys.stderr)
                return 2
            todo = [list(found)[a.task]]
        else:
            todo = [s for s in found if not a.only or rows[s] is None or flagged(rows[s])]
        if a.only:
            print(f"regrading {len(todo)} flagged of {len(found)} students with the batch's "
                  f"saved secret", flush=True)
        grade_all(a.lab, todo, found, a.out, extra, env, rows)
    finally:
        if not keep:
            shutil.rmtree(unpacked, ignore_errors=True)
    if a.task is None:
        write_report(a.out, a.lab, rows, submitters)
    return 0


if __name__ == "__main__":
    sys.exit(main())
