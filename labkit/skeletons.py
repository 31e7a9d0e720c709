"""Generate each lab's skeleton from its solution (the single source).

A solution file marks what students write:

    // BEGIN SOLUTION
    ...the reference code...
    // SKELETON
    //> ...what the skeleton has instead, one line each, after "//> "...
    // END SOLUTION

The skeleton keeps everything outside the markers, drops the reference code and uncomments
the "//>" lines (keeping their indentation). Comment lines that start with "//!" are for
instructors only (how the file becomes a skeleton, where its solution lives): the skeleton
drops them too. A lab's solution/ files become skeleton/ files of
the same name; the shared files a lab lists as `shared` in labs/labs.toml (code the lab's
students write but later labs reuse, such as common/core/path_steps.h) become skeleton/
files too; the
lab's build puts skeleton/ first on the include path, so there they stand in for the shared
file.

    python3 -m labkit.skeletons           regenerate every skeleton (make skeletons)
    python3 -m labkit.skeletons --check   exit 1 and name the files that differ (make
                                          check-skeletons, the tests)

The grader and the release tools import it (labkit/, not tools/): both need the markers and
SHARED_SOURCES, and the grader imports nothing from tools/. A student release ships neither it
nor the solutions it reads (grading/releases/leaks.py).
"""
import argparse
import pathlib
import re
import sys

from labkit import registry

ROOT = pathlib.Path(__file__).resolve().parent.parent

# Lab folder -> the shared files whose solution regions belong to its students.
SHARED_SOURCES = registry.shared_sources()

BEGIN = re.compile(r"^\s*// BEGIN SOLUTION\s*$")
SKELETON = re.compile(r"^\s*// SKELETON\s*$")
END = re.compile(r"^\s*// END SOLUTION\s*$")
PLACEHOLDER = re.compile(r"^(\s*)//> ?(.*)$")
INSTRUCTOR_ONLY = re.compile(r"^\s*//!")


class MarkerError(Exception):
    pass


def skeleton_text(text: str, name: str) -> str:
    """The skeleton version of one solution file."""
    out, state = [], "outside"
    for number, line in enumerate(text.splitlines(keepends=True), 1):
        where = f"{name}:{number}"
        if BEGIN.match(line):
            if state != "outside":
                raise MarkerError(f"{where}: BEGIN SOLUTION inside a solution region")
            state = "solution"
        elif SKELETON.match(line):
            if state != "solution":
                raise MarkerError(f"{where}: SKELETON outside a solution region")
            state = "skeleton"
        elif END.match(line):
            if state == "outside":
                raise MarkerError(f"{where}: END SOLUTION without BEGIN SOLUTION")
            state = "outside"
        elif state == "outside":
            if not INSTRUCTOR_ONLY.match(line):
                out.append(line)
        elif state == "skeleton":
            m = PLACEHOLDER.match(line)
            if not m:
                raise MarkerError(f"{where}: skeleton lines must start with '//>'")
            out.append((m.group(1) + m.group(2)).rstrip() + "\n")
    if state != "outside":
        raise MarkerError(f"{name}: solution region not closed by END SOLUTION")
    return "".join(out)


def generated_files():
    """Yield (skeleton path, expected text) for every lab."""
    for lab in (entry.path for entry in registry.labs()):
        solution = lab / "solution"
        if not solution.is_dir():  # a student release: the solution is not there
            continue
        # solution/'s files keep their place below it (lab 02's part-a/vec3.h); shared files
        # land at the top of skeleton/.
        sources = [(p, p.relative_to(solution)) for p in sorted(solution.rglob("*")) if p.is_file()]
        sources += [(ROOT / s, pathlib.Path(s).name) for s in SHARED_SOURCES.get(lab.name, [])]
        for src, target in sources:
            rel = src.relative_to(ROOT)
            number = lab.name.split("-")[0]
            header = (f"// Lab {number}: your copy, yours to edit. Every place to fill in is "
                      f"marked TODO(lab{number}).\n")
            yield lab / "skeleton" / target, header + skeleton_text(src.read_text(), str(rel))


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true", help="report drift, change nothing")
    args = parser.parse_args()
    try:
        files = list(generated_files())
    except MarkerError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    stale = []
    for path, text in files:
        current = path.read_text() if path.exists() else None
        if current == text:
            continue
        stale.append(path.relative_to(ROOT))
        if not args.check:
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_text(text)
    if args.check and stale:
        print("skeletons out of date (run `make skeletons`): " + ", ".join(map(str, stale)),
              file=sys.stderr)
        return 1
    if not args.check:
        print(f"{len(files)} skeleton files, {len(stale)} rewritten")
    return 0


if __name__ == "__main__":
    sys.exit(main())
