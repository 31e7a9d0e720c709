"""The student repository for one lab.

    make release LAB=03 OUT=../lab03-release

A release for lab NN holds the skeletons of lab NN and every later lab, the solutions of the
earlier labs (lab NN builds on them), common/ with the solution regions of lab NN and later
replaced by their skeleton form (labkit/skeletons.py), the scenes, the golden images, the
handouts, the public tests, the grader (students run `make grade LAB=NN`, trusted) and the
reference binaries of lab NN and later, prebuilt (grading/releases/reference_bins.py says why
and how). It holds no solution source of lab NN or later, no test that is not public, no instructor
tool and no secret: grading/releases/leaks.py checks the finished folder, and the release is refused
when it finds anything.

The release is written atomically: it is assembled in a hidden folder beside OUT and renamed
to OUT only once complete and checked; OUT must not exist or be an empty folder. Every
refusal is one line on stderr and exit status 2.
"""
from __future__ import annotations

import fnmatch
import os
import pathlib
import re
import secrets
import shutil
import signal
import subprocess
import sys
import textwrap
import time

from grading.releases import handin, leaks, reference_bins
from grading.releases.gradescope import repository_files
from labkit import registry
from labkit.harness import ROOT

# Top-level entries of the repository that ship (then filtered by leaks.NEVER_SHIPPED and
# leaks.PUBLIC_TESTS): anything else, such as a stray binary at the root, does not.
# pyproject.toml puts the root on pytest's import path (labkit, grading, tools are packages).
SHIPPED_TOP = ("Makefile", "cuda.mk", "README.md", "DESIGN.md", ".gitignore", "pyproject.toml",
               "common", "labs", "labkit", "grading", "handouts", "reference", "tests", "tools",
               "bench")


class ReleaseError(Exception):
    """Why no release was written: one line for the user."""


def parse_lab(lab: str, folders: dict[str, str]) -> str:
    if lab not in folders:
        raise ReleaseError(f"LAB must be one of {', '.join(folders)} (got {lab!r})")
    return lab


def check_out(out: pathlib.Path) -> None:
    if out.is_symlink() or (out.exists() and not out.is_dir()):
        raise ReleaseError(f"OUT={out} exists and is not a folder; give a new folder")
    if out.is_dir() and any(out.iterdir()):
        raise ReleaseError(f"OUT={out} is not empty; give a new or empty folder "
                           f"(a release never overwrites one)")


def shipped(path: str, lab: str, folders: dict[str, str]) -> bool:
    """Whether a file of the repository belongs in lab `lab`'s release."""
    if path.split("/")[0] not in SHIPPED_TOP:
        return False
    if any(fnmatch.fnmatch(path, p) for p in leaks.NEVER_SHIPPED):
        return False
    if path.startswith("tests/") and not any(fnmatch.fnmatch(path, p) for p in leaks.PUBLIC_TESTS):
        return False
    return not any(path.startswith(f"labs/{name}/solution/")
                   for number, name in folders.items() if number >= lab)


def skeleton_form(lab: str, folders: dict[str, str]) -> set[str]:
    """Shared files whose solution regions belong to lab `lab` or later: they ship as their
    skeleton (common/core/path_steps.h is lab 01's, so only a lab-01 release ships it so)."""
    return {path for number, name in folders.items() if number >= lab
            for path in leaks.skeletons.SHARED_SOURCES.get(name, [])}


# A lab README's lines that name what only the course repository holds (the lab's tests, the
# GPU check that runs them), between these two lines, are left out of a release.
COURSE_ONLY = re.compile(r"^<!-- course repository only -->\n.*?^<!-- end course repository "
                         r"only -->\n", re.M | re.S)


def for_students(text: str) -> str:
    """A markdown file as a release ships it: without its course-repository-only parts."""
    return COURSE_ONLY.sub("", text)


def copy_sources(stage: pathlib.Path, lab: str, folders: dict[str, str],
                 files: list[str]) -> None:
    as_skeleton = skeleton_form(lab, folders)
    for f in files:
        if not shipped(f, lab, folders):
            continue
        src, dst = ROOT / f, stage / f
        dst.parent.mkdir(parents=True, exist_ok=True)
        if f in as_skeleton:
            dst.write_text(leaks.skeletons.skeleton_text(src.read_text(), f))
            shutil.copymode(src, dst)
        elif f.endswith(".md") and COURSE_ONLY.search(src.read_text()):
            dst.write_text(for_students(src.read_text()))
            shutil.copymode(src, dst)
        else:
            shutil.copy2(src, dst)


def add_references(stage: pathlib.Path, lab: str, files: list[str]) -> list[str]:
    """Build and copy the prebuilt references of lab `lab` and later into reference-bin/;
    returns their names. A CPU reference must build (the grader needs lab01-ref, lab04-ref);
    a GPU one is left out, saying so, where it cannot."""
    targets = [t for number, names in reference_bins.REFERENCES.items() if number >= lab
               for t in names]
    fresh = not any(reference_bins.MIRROR.glob("obj-*"))
    print(f"release: building {len(targets)} reference binaries for any x86-64 CPU in "
          f"{reference_bins.MIRROR.relative_to(ROOT)}"
          + (" (the first release compiles every reference and, with nvcc, every GPU "
             "architecture: minutes; later releases relink)" if fresh else ""), flush=True)
    start = time.monotonic()
    built, log = reference_bins.build(targets, files, stage / leaks.REFERENCE_BIN)
    print(f"release: built {len(built)} in {time.monotonic() - start:.0f} s", flush=True)
    missing = [t for t in targets if t not in built]
    gpu = {t for number in reference_bins.GPU_LABS for t in reference_bins.REFERENCES[number]}
    cpu_missing = [t for t in missing if t not in gpu]
    if cpu_missing:
        last = (log.strip().splitlines() or ["(no output)"])[-1]
        raise ReleaseError(f"could not build {', '.join(cpu_missing)}: {last}")
    if missing:
        print(f"release: left out {', '.join(missing)} (the CUDA toolkit is missing or the "
              f"build failed); those labs ship without a reference binary", file=sys.stderr)
    return sorted(built)


def no_gpu_section(lab: str) -> str:
    """What a student of a GPU lab does without an NVIDIA GPU of their own (cuda.mk)."""
    return f"""
**No NVIDIA GPU here?** Lab {lab} renders on one, but most of the work does not need it:

```sh
make lab{lab}                # compiles your code where nvcc is; it runs only on a GPU
make kernel-report        # your kernels' registers, spills, stack: build/kernel-report.md
make grade-gpu            # on the course's login node: make grade on a GPU machine (Slurm)
```

`make grade-gpu` submits one Slurm job (one GPU) from this folder, which must be a checkout
the GPU machines see (your home on the course's login node, where `sbatch` is), waits for it
(minutes when the queue is busy) and prints the score table; `results.json` and the images
land here. `make run-gpu RUN='./lab{lab} --width 128 --height 128 --spp 16 --out quick.ppm'`
runs any command there the same way (write `$$` for a `$` in RUN). Without a GPU, `make
grade` itself says so in one line and marks every check for regrade: nothing is scored.
"""


def student_readme(lab: str, folders: dict[str, str], prebuilt: list[str]) -> str:
    """The release's README.md: what students read first (the course's README is staff's)."""
    name = folders[lab]
    files = handin.handin_files(lab)
    later = [f"{n} ({folders[n]})" for n in folders if n > lab]
    earlier = [f"{n} ({folders[n]})" for n in folders if n < lab]
    # What a student runs to build and try lab NN's code at a small size (labs/labs.toml).
    try_it = registry.lab(lab).try_command
    build = f"make {' '.join(registry.lab(lab).student)}"
    title = (ROOT / "handouts" / f"{name}.md").read_text().splitlines()[0].lstrip("# ")
    return f"""\
# {title}

Read `handouts/{name}.md` first: it teaches the lab, says how it is graded and what to hand in.

**Your code** is in `labs/{name}/skeleton/`: {", ".join(f"`{f}`" for f in files)}. Every place
to fill in is marked `TODO(lab{lab})`. Nothing else is yours to change: the grader builds
exactly these files with this repository's `common/`.

```sh
make deps                 # install what the labs need (compiler libraries, OpenMPI, pytest, numpy)
{build:<25} # build your code into ./lab{lab}
{try_it}
make grade                # the autograder's checks: a score table, results.json (up to minutes)
make test                 # the unit tests of common/ and the public tests (minutes)
make render               # the Cornell box with the fastest reference here, into cornell.ppm
make handin               # handin-lab{lab}.zip: the files to upload to Gradescope
make help                 # every command
```

`make grade` grades lab {lab} (add `LAB=NN` for another); it builds `./lab{lab}` first and
writes `results.json` and, where an image check fails, `grading-heatmaps/report.html`.
{no_gpu_section(lab) if registry.lab(lab).gpu else ""}
What else is here:
- the reference binaries of lab {lab} and later, prebuilt for x86-64 Linux in
  `reference-bin/`, which any `make` copies to the top of this folder (`./lab{lab}-ref`); run
  them from here or give `--scene`:
{textwrap.fill(", ".join(f"`{b}`" for b in prebuilt), 92, initial_indent="  ",
               subsequent_indent="  ")}.
- {f"the solutions of labs {', '.join(earlier)}: lab {lab} builds on them." if earlier
   else "no solutions: this is the first lab."}
- {f"the skeletons of labs {', '.join(later)}." if later else "no later lab."}

This folder is a git repository with one commit, the release as you got it: `git diff` shows
what you changed. Commit your work as you go.
"""


def check_skeletons() -> None:
    """The shipped skeletons must be what labkit/skeletons.py makes of the solutions now: a
    solution changed without `make skeletons` would give students a skeleton of the old one."""
    try:
        generated = list(leaks.skeletons.generated_files())
    except leaks.skeletons.MarkerError as e:
        raise ReleaseError(f"a solution's markers are broken: {e}") from None
    stale = [path.relative_to(ROOT).as_posix() for path, text in generated
             if not path.is_file() or path.read_text() != text]
    if stale:
        raise ReleaseError(f"skeletons out of date (run make skeletons): {', '.join(stale)}")


def commit(stage: pathlib.Path, lab: str) -> None:
    """Make the release a git repository with one commit holding every file: students start
    from it, and `git diff` shows them what they changed."""
    env = {**reference_bins.make_environment(), "GIT_AUTHOR_NAME": "Course staff",
           "GIT_AUTHOR_EMAIL": "staff@course.invalid", "GIT_COMMITTER_NAME": "Course staff",
           "GIT_COMMITTER_EMAIL": "staff@course.invalid"}
    for args in (["init", "-q", "--initial-branch=main"], ["add", "-A", "-f", "."],
                 ["commit", "-q", "--no-verify", "--no-gpg-sign", "-m", f"Lab {lab} release"]):
        p = subprocess.run(["git", "-c", "core.hooksPath=/dev/null", *args], cwd=stage, env=env,
                           capture_output=True, text=True)
        if p.returncode != 0:
            raise ReleaseError(f"git {args[0]} failed: "
                               f"{(p.stderr.strip().splitlines() or ['no output'])[-1]}")


def make_release(lab: str, out: pathlib.Path, secret: str | None = None) -> pathlib.Path:
    """Write lab `lab`'s release to `out` (which must not exist or be empty); ReleaseError
    says why not. `secret`: the hidden scene's secret, which no file may contain."""
    folders = leaks.lab_folders(ROOT)
    lab = parse_lab(lab, folders)
    out = out.absolute()
    check_out(out)
    missing = [n for n, name in folders.items() if not (ROOT / "labs" / name / "solution").is_dir()]
    if missing:
        raise ReleaseError(f"no solution of lab {missing[0]} here: a release is made from the "
                           f"course repository, not from a release")
    check_skeletons()
    out.parent.mkdir(parents=True, exist_ok=True)
    # The folder's name is chosen before it is made, so that the cleanup knows it whenever an
    # interrupt comes (a signal can arrive between any two steps, even while the handler's
    # thread blocks it: numpy's threads take it).
    stage = out.parent / f".{out.name}.partial-{secrets.token_hex(6)}"
    try:
        try:
            stage.mkdir(mode=0o700)  # private until complete
        except FileExistsError:  # a clash of random names: someone else's, never removed
            stage = None
            raise ReleaseError("a folder of the same random name appeared; try again") from None
        files = repository_files()
        copy_sources(stage, lab, folders, files)
        prebuilt = add_references(stage, lab, files)
        student_folders = [f"labs/{folders[lab]}/skeleton"] \
            if leaks.skeletons.SHARED_SOURCES.get(folders[lab]) else []
        (stage / "GNUmakefile").write_text(
            reference_bins.front_door(lab, prebuilt, student_folders))
        (stage / "README.md").write_text(student_readme(lab, folders, prebuilt))
        problems = leaks.leaks(stage, lab, folders, secret)
        if problems:
            more = f" (and {len(problems) - 1} more)" if len(problems) > 1 else ""
            raise ReleaseError(f"refusing to release lab {lab}: {problems[0]}{more}")
        commit(stage, lab)
        umask = os.umask(0)
        os.umask(umask)
        stage.chmod(0o777 & ~umask)
        check_out(out)  # again: something may have written there meanwhile
        os.rename(stage, out)  # replaces an empty folder, atomically
    except BaseException as e:
        if isinstance(e, KeyboardInterrupt) and stage is not None and not stage.exists() \
                and out.is_dir():
            return out  # it came just after the rename: the release is complete
        if stage is not None:
            shutil.rmtree(stage, ignore_errors=True)
        raise
    return out


def main(argv=None) -> int:
    args = sys.argv[1:] if argv is None else argv
    if len(args) != 2 or not args[1]:
        print("error: release: usage: python3 -m grading.releases.release NN OUT_DIR "
              "(make release LAB=NN OUT=DIR)", file=sys.stderr)
        return 2

    def interrupted(signum, _frame):
        raise KeyboardInterrupt(signal.Signals(signum).name)
    signal.signal(signal.SIGTERM, interrupted)
    try:
        # The instructor's fixed secret (grading/checks/hidden.py); without one, each grade draws
        # its own and there is none to leak.
        out = make_release(args[0], pathlib.Path(args[1]), os.environ.get("GRADING_SECRET"))
    except (ReleaseError, reference_bins.BuildError) as e:
        print(f"error: release: {e}", file=sys.stderr)
        return 2
    except (OSError, subprocess.CalledProcessError) as e:  # an unwritable OUT, no git, no make
        print(f"error: release: {e}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("error: release: interrupted; nothing written", file=sys.stderr)
        return 130
    print(f"wrote {out}: the lab {args[0]} release")
    return 0


if __name__ == "__main__":
    sys.exit(main())
