"""What a student hands in for lab NN, packed, and found again in what was uploaded.

    make handin                 (a release: its lab)  -> handin-labNN.zip
    python3 -m grading.releases.handin NN [--out FILE.zip]

The hand-in is the lab's skeleton files, as the student finished them: the files of
labs/NN-name/skeleton/ that labs/labs.toml lists as its hand-in, at the top of the zip
(lab 02's Part A keeps its folder, part-a/vec3.h). Gradescope unpacks the upload into its
submission folder, and `make grade-batch` takes one such folder per student; the grader
finds the files where a student may have put them (grading/students_tree.py: at the top, or
in a folder at any depth, as in a zipped folder or a repository checkout) and builds only
the top-level ones.
"""
from __future__ import annotations

import argparse
import os
import pathlib
import subprocess
import sys
import zipfile

from labkit import registry
from labkit.harness import ROOT

# Lab number -> folder: {"01": "01-serial", ...} (labs/labs.toml).
LAB_FOLDERS = registry.folders()


class HandinError(Exception):
    """Why a hand-in cannot be made or used: one line."""


def skeleton(lab: str) -> pathlib.Path:
    return ROOT / "labs" / LAB_FOLDERS[lab] / "skeleton"


def handin_files(lab: str) -> list[str]:
    """The files of lab `lab`'s hand-in, relative to its skeleton folder (its registry entry's
    `handin`): the top-level ones (what the grader builds) first, then those in folders."""
    return sorted(registry.lab(lab).handin, key=lambda f: ("/" in f, f))


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


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("lab", help=f"the lab number: {', '.join(LAB_FOLDERS)}")
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
