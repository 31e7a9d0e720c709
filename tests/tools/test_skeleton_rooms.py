"""A student's file holds the student's code: what they write and what they must read to write
it, never a copy of the library around it (DESIGN.md, section 11).

- Every skeleton file with a TODO is at most 300 lines.
- No run of 40 consecutive lines of a skeleton file (compared after stripping trailing
  whitespace; blank lines count as lines) stands again in a file of common/: a student's copy
  of library code is code they may edit and hand in, and a second copy to keep in step.
- A file students write (a lab's `shared` entry in labs/labs.toml) has a name of its own: it
  is included only by the one header of common/ it belongs to and by its lab's own sources,
  so an `#include` of any other shared header always means the library, never a student's
  copy; and no skeleton file stands in for a shared file other than its lab's own.
"""
import pathlib
import re

import pytest

from labkit import registry
from labkit.harness import ROOT

MAX_LINES = 300
RUN = 40
SOURCE_SUFFIXES = {".h", ".cuh", ".cpp", ".cu"}
INCLUDE = re.compile(r'^\s*#\s*include\s*[<"]([^>"]+)[>"]', re.MULTILINE)

LABS = {entry.path.name: entry.path for entry in registry.labs()}
SKELETON_FILES = sorted(p for lab in LABS.values() for p in (lab / "skeleton").rglob("*")
                        if p.is_file())
COMMON_FILES = sorted(p for p in (ROOT / "common").rglob("*")
                      if p.is_file() and p.suffix in SOURCE_SUFFIXES)


def rel(path: pathlib.Path) -> str:
    return str(path.relative_to(ROOT))


def lines_of(path: pathlib.Path) -> list[str]:
    return [line.rstrip() for line in path.read_text().splitlines()]


@pytest.mark.parametrize("path", [p for p in SKELETON_FILES if "TODO" in p.read_text()],
                         ids=rel)
def test_a_skeleton_file_with_a_todo_is_short(path):
    count = len(lines_of(path))
    assert count <= MAX_LINES, (
        f"{rel(path)} is {count} lines: a student's file holds what they write and what they "
        f"must read to write it (at most {MAX_LINES}); move the library part to common/")


@pytest.fixture(scope="module")
def common_runs() -> dict:
    """Every run of RUN consecutive lines of common/'s sources -> where it first stands."""
    runs = {}
    for path in COMMON_FILES:
        lines = lines_of(path)
        for start in range(len(lines) - RUN + 1):
            runs.setdefault(tuple(lines[start:start + RUN]), (path, start + 1))
    return runs


@pytest.mark.parametrize("path", SKELETON_FILES, ids=rel)
def test_no_run_of_a_skeleton_stands_again_in_common(path, common_runs):
    lines = lines_of(path)
    for start in range(len(lines) - RUN + 1):
        found = common_runs.get(tuple(lines[start:start + RUN]))
        assert found is None, (
            f"{rel(path)}:{start + 1} and {rel(found[0])}:{found[1]}: the same {RUN} lines; "
            "a student's file holds only what they write (the rest belongs in common/, in a "
            "header the student's file is included beside)")


def includes_by_name() -> dict:
    """Bare header name -> the source files (outside skeleton/ and build/) that include it."""
    found = {}
    for top in ("common", "labs", "bench", "tests", "tools", "grading"):
        for path in (ROOT / top).rglob("*"):
            if (not path.is_file() or path.suffix not in SOURCE_SUFFIXES
                    or "skeleton" in path.relative_to(ROOT).parts):
                continue
            for name in INCLUDE.findall(path.read_text(errors="replace")):
                found.setdefault(pathlib.PurePath(name).name, set()).add(path)
    return found


STUDENT_FILES = [(lab, ROOT / shared) for lab, files in registry.shared_sources().items()
                 for shared in files]


@pytest.mark.parametrize("lab, shared", STUDENT_FILES,
                         ids=[f"{lab}:{s.name}" for lab, s in STUDENT_FILES])
def test_a_students_file_is_included_by_its_library_and_its_lab_only(lab, shared):
    includers = includes_by_name().get(shared.name, set())
    library = sorted(rel(p) for p in includers if p.is_relative_to(ROOT / "common"))
    elsewhere = sorted(rel(p) for p in includers
                       if not p.is_relative_to(ROOT / "common") and not p.is_relative_to(LABS[lab]))
    assert len(library) <= 1 and not elsewhere, (
        f"{rel(shared)}, which lab {lab}'s students write, is included by "
        f"{', '.join(library + elsewhere)}: an override of it would stand in for all of them; "
        "give the student's part a header of its own, included by its library header only")
    namesakes = sorted(rel(p) for p in COMMON_FILES if p.name == shared.name and p != shared)
    assert not namesakes, f"{rel(shared)} shares its name with {', '.join(namesakes)}"


@pytest.mark.parametrize("path", SKELETON_FILES, ids=rel)
def test_a_skeleton_file_stands_in_only_for_its_labs_shared_file(path):
    lab = next(name for name, folder in LABS.items() if path.is_relative_to(folder))
    below = path.relative_to(LABS[lab] / "skeleton")
    if len(below.parts) > 1:
        # A subfolder holds a whole replacement of the shared header of its name, on the path
        # of its part's build only (lab 02's part-a/vec3.h, an SSE Vec3 for every file of
        # ./lab02a): the student's own file, from solution/, never a copy of common/'s.
        assert (LABS[lab] / "solution" / below).is_file(), rel(path)
        return
    own = {pathlib.PurePath(s).name for s in registry.shared_sources().get(lab, [])}
    namesakes = [rel(p) for p in COMMON_FILES if p.name == path.name]
    assert not namesakes or path.name in own, (
        f"{rel(path)} has the name of {', '.join(namesakes)}, which is not a file lab {lab}'s "
        "students write (its `shared` in labs/labs.toml)")
