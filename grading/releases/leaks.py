"""What a student release for lab NN must not hold, checked on the finished folder before it is
given its name (grading/releases/release.py). The check is independent of how the release chose its
files: it reads every file that ended up there, so a mistake in the selection, a solution
pasted into a shared file or a secret committed by accident is caught all the same.

A release for lab NN leaks when it holds
- a solution folder of lab NN or later (labs/NN-name/solution/);
- a solution region marker or an instructor-only line (labkit/skeletons.py's markers and
  "//!" lines) in any file other than an earlier lab's solution: solution files of earlier
  labs and the shared files whose regions belong to earlier labs (SHARED_SOURCES) ship as
  they are, markers included. Markdown is not read for markers: the course's README.md and
  DESIGN.md show them in an example, and no Markdown file is compiled;
- a file the release never ships (NEVER_SHIPPED: the instructor's tools and tests);
- a test that is not public (PUBLIC_TESTS);
- an executable outside reference-bin/ (a binary built from solution sources, committed by
  accident);
- the hidden scene's secret (GRADING_SECRET, grading/checks/hidden.py), anywhere, in any file, or
  the scene made from it, as a scene file (what a saved copy of it would be);
- in its git repository (.git/), anything but one commit of the files as they are: the objects
  there are compressed, so they are not read byte by byte (compressed data holds a marker's
  bytes now and then by chance); git says instead whether every object it holds is the one
  commit, its trees and the files checked above.
"""
from __future__ import annotations

import fnmatch
import json
import pathlib
import subprocess

from grading.checks import hidden
from labkit import (  # skeletons: the one definition of the markers and of SHARED_SOURCES
    registry,
    skeletons,
)

# The instructor's side of the kit: the skeleton generator (it documents the markers), the
# golden-image generator, the grader's own tests (hostile submissions, the sandbox, the
# Gradescope bundle), the labs' tests (they test the references, mutants of the solutions and
# the skeletons' sync with them), CI, and this release tool itself.
NEVER_SHIPPED = ("labkit/skeletons.py", "tools/make_golden.py", "tests/grading/*",
                 "tests/labs/test_lab[0-9][0-9]*", ".ci/*", "grading/releases/release.py",
                 "grading/releases/leaks.py", "grading/releases/reference_bins.py")
# Tests students get: the shared command-line contract (run on the reference binaries) and
# the unit tests of common/ (which test lab 01's path tracer too: they fail until lab 01 is
# done, as they should). Every other test needs the solutions (pristine skeletons, skeleton
# sync) or is the grader's own.
PUBLIC_TESTS = ("tests/conftest.py", "tests/labs/conftest.py", "tests/labs/cuda_env.py",
                "tests/labs/test_bad_input.py", "tests/unit/*.cpp", "tests/cuda/*.cu")
REFERENCE_BIN = "reference-bin"
ELF_MAGIC = b"\x7fELF"


def lab_folders(root: pathlib.Path) -> dict[str, str]:
    """Lab number -> folder name: {"01": "01-serial", ...}, as labs/labs.toml under `root`
    declares them."""
    return {lab.number: lab.folder
            for lab in registry.parse((root / "labs" / "labs.toml").read_text())}


def earlier_solution_files(lab: str, folders: dict[str, str]) -> tuple[list[str], list[str]]:
    """(folder prefixes, shared file paths) whose solution regions belong to labs before `lab`:
    where markers may ship."""
    earlier = [name for number, name in folders.items() if number < lab]
    return ([f"labs/{name}/solution/" for name in earlier],
            [path for name in earlier for path in skeletons.SHARED_SOURCES.get(name, [])])


def is_marker(line: str) -> bool:
    return bool(skeletons.BEGIN.match(line) or skeletons.SKELETON.match(line)
                or skeletons.END.match(line) or skeletons.INSTRUCTOR_ONLY.match(line))


def parsed_json(data: bytes):
    try:
        return json.loads(data)
    except ValueError:
        return None


def git_output(release: pathlib.Path, *args: str) -> str:
    return subprocess.run(["git", "-c", f"safe.directory={release}", "-C", str(release), *args],
                          capture_output=True, text=True, check=True).stdout


def git_problems(release: pathlib.Path) -> list[str]:
    """Why the release's repository holds more than one commit of its files, one line each."""
    if not (release / ".git").exists():
        return []
    try:
        commits = git_output(release, "rev-list", "--all").split()
        if len(commits) != 1:
            return [f".git: {len(commits)} commits (a release is one commit of its files)"]
        changed = git_output(release, "diff", "--name-only", "--no-renames", "HEAD").split("\n")
        problems = [f"{name}: the release's commit holds another version of it"
                    for name in changed if name]
        reachable = len(git_output(release, "rev-list", "--objects", "--all").splitlines())
        counts = dict(line.split(": ") for line in
                      git_output(release, "count-objects", "-v").splitlines())
        stored = int(counts["count"]) + int(counts["in-pack"])
        if stored != reachable:
            problems.append(f".git: {stored - reachable} objects beyond the release's commit")
        return problems
    except (OSError, subprocess.CalledProcessError, KeyError, ValueError) as e:
        return [f".git: not a repository git can read ({e})"]


def leaks(release: pathlib.Path, lab: str, folders: dict[str, str],
          secret: str | None = None) -> list[str]:
    """Every reason `release` (a folder) may not be handed to students of lab `lab`, one line
    each; empty when it may."""
    problems = []
    solution_dirs, shared = earlier_solution_files(lab, folders)
    for number, name in folders.items():
        if number >= lab and (release / "labs" / name / "solution").exists():
            problems.append(f"labs/{name}/solution/: lab {number}'s solution (lab {lab} and "
                            f"later ship as skeletons)")
    secret_bytes = secret.encode() if secret else None
    secret_scene = hidden.hidden_scene(secret) if secret else None
    problems += git_problems(release)
    for path in sorted(p for p in release.rglob("*") if p.is_file() or p.is_symlink()):
        rel = path.relative_to(release).as_posix()
        if rel.startswith(".git/"):
            continue
        if path.is_symlink():
            problems.append(f"{rel}: a symbolic link (it could point at anything)")
            continue
        data = path.read_bytes()
        if any(fnmatch.fnmatch(rel, pattern) for pattern in NEVER_SHIPPED):
            problems.append(f"{rel}: an instructor's file, never shipped")
        elif rel.startswith("tests/") and not any(fnmatch.fnmatch(rel, p) for p in PUBLIC_TESTS):
            problems.append(f"{rel}: not a public test")
        if data.startswith(ELF_MAGIC) and not rel.startswith(f"{REFERENCE_BIN}/"):
            problems.append(f"{rel}: an executable outside {REFERENCE_BIN}/")
        if secret_bytes and secret_bytes in data:
            problems.append(f"{rel}: holds the hidden scene's secret (GRADING_SECRET)")
        if secret_scene and rel.endswith(".json") and parsed_json(data) == secret_scene:
            problems.append(f"{rel}: is the hidden scene made from the secret")
        if not data.startswith(ELF_MAGIC) and not rel.endswith(".md") \
                and not rel.startswith(tuple(solution_dirs)) and rel not in shared:
            text = data.decode(errors="replace")
            marked = [n for n, line in enumerate(text.splitlines(), 1) if is_marker(line)]
            if marked:
                problems.append(f"{rel}:{marked[0]}: a solution marker or instructor-only line "
                                f"({len(marked)} in the file)")
    return problems
