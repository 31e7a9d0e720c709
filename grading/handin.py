"""What a student hands in for lab NN, packed, and found again in what was uploaded.

    make handin                 (a release: its lab)  -> handin-labNN.zip
    python3 -m grading.handin NN [--out FILE.zip]

The hand-in is the lab's skeleton files, as the student finished them: the files of
labs/NN-name/skeleton/, at the top of the zip (lab 02's Part A keeps its folder,
part-a/vec3.h). Gradescope unpacks the upload into its submission folder, and
`make grade-batch` takes one such folder per student; both give it to `locate`, which
finds the files where a student may have put them (at the top, or in one folder at any
depth: a zipped folder, a repository checkout) and otherwise refuses in one line naming
the files that are missing. The grader builds only the top-level files it lists.
"""
from __future__ import annotations

import argparse
import os
import pathlib
import subprocess
import sys
import zipfile

from grading.harness import ROOT

LAB_FOLDERS = {"01": "01-serial", "02": "02-simd", "03": "03-openmp", "04": "04-mpi",
               "05": "05-cuda-mega", "06": "06-cuda-split", "07": "07-soa"}


class HandinError(Exception):
    """Why a hand-in cannot be made or used: one line."""


def skeleton(lab: str) -> pathlib.Path:
    return ROOT / "labs" / LAB_FOLDERS[lab] / "skeleton"


def handin_files(lab: str) -> list[str]:
    """The files of lab `lab`'s hand-in, relative to its skeleton folder: the top-level ones
    (what the grader builds) first, then those in folders."""
    files = [p.relative_to(skeleton(lab)).as_posix() for p in skeleton(lab).rglob("*")
             if p.is_file()]
    return sorted(files, key=lambda f: ("/" in f, f))


def graded_files(lab: str) -> list[str]:
    """The hand-in's files that the grader builds: those at the top."""
    return [f for f in handin_files(lab) if "/" not in f]


def pack(lab: str, out: pathlib.Path) -> list[str]:
    """Write the hand-in zip from this checkout's skeleton folder; returns the files that
    are still as the release shipped them (a warning, not a refusal: a partial lab earns
    partial points). Written to a temporary name, then renamed: never half a zip."""
    files = handin_files(lab)
    missing = [f for f in files if not (skeleton(lab) / f).is_file()]
    if missing:
        raise HandinError(f"labs/{LAB_FOLDERS[lab]}/skeleton/ lacks {', '.join(missing)}")
    partial = out.with_name(f".{out.name}.partial-{os.getpid()}")
    try:
        with zipfile.ZipFile(partial, "w", zipfile.ZIP_DEFLATED) as z:
            for f in files:
                z.write(skeleton(lab) / f, f)
        os.replace(partial, out)
    finally:
        partial.unlink(missing_ok=True)
    return unchanged(lab, files)


def unchanged(lab: str, files: list[str]) -> list[str]:
    """Files identical to the last commit's, where this is a git checkout (a release)."""
    folder = f"labs/{LAB_FOLDERS[lab]}/skeleton"
    p = subprocess.run(["git", "-C", str(ROOT), "diff", "--quiet", "HEAD", "--", folder],
                       capture_output=True)
    if p.returncode != 0:  # changes (1), or not a repository (128): nothing to say
        return []
    return files


def locate(lab: str, submission: pathlib.Path) -> tuple[pathlib.Path, list[str]]:
    """(the folder of `submission` that holds lab `lab`'s graded files, those it lacks): the
    submission itself when it holds any of them at the top, else the one folder below it (at
    any depth, links not followed) holding the most. HandinError when none holds any, or
    two folders compete."""
    wanted = graded_files(lab)

    def held(folder: pathlib.Path) -> list[str]:
        return [f for f in wanted if (folder / f).is_file() and not (folder / f).is_symlink()]

    if held(submission):
        return submission, [f for f in wanted if f not in held(submission)]
    best: list[tuple[int, pathlib.Path]] = []
    for folder, dirs, _names in os.walk(submission):
        dirs[:] = sorted(d for d in dirs if not d.startswith((".", "__MACOSX")))
        n = len(held(pathlib.Path(folder)))
        if n:
            best.append((n, pathlib.Path(folder)))
    if not best:
        raise HandinError(f"the hand-in holds none of lab {lab}'s files "
                          f"({', '.join(wanted)}; make handin packs them)")
    most = max(n for n, _ in best)
    top = [folder for n, folder in best if n == most]
    if len(top) > 1:
        names = ", ".join(f.relative_to(submission).as_posix() for f in top[:3])
        raise HandinError(f"the hand-in holds lab {lab}'s files in more than one folder "
                          f"({names}); hand in one copy (make handin)")
    return top[0], [f for f in wanted if f not in held(top[0])]


def prepare(lab: str, submission: pathlib.Path, workdir: pathlib.Path) -> tuple[pathlib.Path, str]:
    """(the folder to build, a note or ""). A graded file the hand-in lacks is taken from the
    skeleton, as the student was given it (never common/'s copy of a shared file, which in
    the grader's repository is the solution), and the note names it in one line."""
    folder, missing = locate(lab, submission)
    if not missing:
        return folder, ""
    workdir.mkdir(parents=True, exist_ok=True)
    for f in graded_files(lab):
        source = skeleton(lab) / f if f in missing else folder / f
        (workdir / f).write_bytes(source.read_bytes())
    return workdir, (f"the hand-in lacks {', '.join(missing)}: graded with the skeleton's "
                     f"(lab {lab} needs {', '.join(graded_files(lab))}; make handin packs them)")


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("lab", help="the lab number, 01-07")
    p.add_argument("--out", type=pathlib.Path, help="default: handin-labNN.zip")
    a = p.parse_args(argv)
    if a.lab not in LAB_FOLDERS:
        print(f"error: handin: LAB must be one of {', '.join(LAB_FOLDERS)} (got {a.lab!r})",
              file=sys.stderr)
        return 2
    out = a.out or pathlib.Path(f"handin-lab{a.lab}.zip")
    try:
        same = pack(a.lab, out)
    except (HandinError, OSError) as e:
        print(f"error: handin: {e}", file=sys.stderr)
        return 2
    print(f"wrote {out}: {', '.join(handin_files(a.lab))} (upload it to Gradescope as it is)")
    if same:
        print(f"warning: handin: labs/{LAB_FOLDERS[a.lab]}/skeleton/ is unchanged since the "
              f"release's commit: this is the skeleton as given", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
