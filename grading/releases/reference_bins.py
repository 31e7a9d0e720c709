"""Prebuilt reference binaries for a student release (grading/releases/release.py).

The grader times and checks a student's build against lab01-ref (and lab04-ref in lab 04), and
students compare their timings with their lab's reference, but a release for lab NN holds no
solution sources of lab NN or later. So those labs' references are compiled here, from the
course repository, and ship as binaries in reference-bin/; the release's GNUmakefile (read by
GNU make before Makefile) serves `make labNN-ref` from there. Earlier labs' references are
built from their shipped solutions, as in the course repository.

The binaries are built in a copy of the repository under build/release/ (kept between
releases, so a second release only relinks; its objects are keyed by the build's flags and
make files) with three changes that make them run on the students' machines rather than on
this one:
- `-march=native` becomes `-march=x86-64-v2` (any x86-64 CPU of the last fifteen years; the
  AVX2 code of lab 02 is compiled with -mavx2 anyway and checks the CPU at run time). The
  flags keep -ffp-contract=off, so the images are the same bits as a native build's.
- the default scene path compiled in (RT_SOURCE_DIR, the source tree's absolute path) becomes
  ".", so `./labNN-ref` with no --scene finds common/scenes/cornell.json from the release's
  root, as the grader runs it.
- CUDA code is compiled for cuda.mk's architectures of a machine without a GPU (sm_75 to sm_90
  and compute_90 PTX), not for the GPUs of this machine, if it has any; under CI (CI=true:
  the tests' releases, which no student receives) for CI's two (CUDA_NO_GPU_ARCH).
They need x86-64 Linux with the libraries `make deps` installs (OpenMPI for lab 04).
"""
from __future__ import annotations

import fcntl
import filecmp
import hashlib
import os
import pathlib
import shutil
import subprocess

from labkit import registry
from labkit.harness import ROOT

# The binaries a lab ships when its solution does not (each lab's `ships` in labs/labs.toml):
# what the grader runs and what students time themselves against. Lab 02 has two parts, and
# Part B two references: lab02-ref-avx2 is what students write (8 AVX2 lanes), the yardstick
# of their speed; lab02-ref runs at the CPU's width with compacted packets (handout 02,
# section 8). Besides the references themselves, the binaries built from a lab's solution
# that its handout runs: lab 02's worked example (lab02-prims), lab 03's schedule benchmark
# (lab03-bench) and the OpenMP/MPI references over lab 02's packets (`make render`'s
# renderer, handout 02's comparison).
REFERENCES = {lab.number: list(lab.ships) for lab in registry.labs()}
# Built where nvcc is; a release without them says so (GPU labs then build only the
# student's own code).
GPU_LABS = registry.gpu_labs()
PORTABLE_ARCH = "-march=x86-64-v2"
MIRROR = ROOT / "build" / "release" / "tree"
LOCK = ROOT / "build" / "release" / "lock"


class BuildError(RuntimeError):
    pass


def make_environment() -> dict[str, str]:
    """This process's environment without what a make that runs us passes on (MAKEFLAGS
    carries its command line's variables, e.g. OPT=...): the references are built with the
    Makefile's own flags, and only the changes made here."""
    return {k: v for k, v in os.environ.items() if k not in ("MAKEFLAGS", "MFLAGS", "MAKELEVEL")}


def make_variable(name: str) -> str:
    """A variable of the repository's Makefile as make computes it."""
    rule = f"print-release-var: ; @echo $({name})"
    p = subprocess.run(["make", "-s", "-C", str(ROOT), f"--eval={rule}", "print-release-var"],
                       capture_output=True, text=True, check=True, env=make_environment())
    return p.stdout.strip()


def portable_opt() -> str:
    opt = make_variable("OPT")
    if "-march=native" not in opt.split():
        raise BuildError(f"the Makefile's OPT ({opt}) has no -march=native to make portable")
    return " ".join(PORTABLE_ARCH if flag == "-march=native" else flag for flag in opt.split())


def build_key(opt: str, cuda_arch: str) -> str:
    """Names the mirror's object folder. make does not rebuild an object when only its flags
    change, so objects built under other flags or other make rules must never be reused:
    anything that changes them changes the key, and the build starts afresh."""
    h = hashlib.sha256(f"{opt}\0{cuda_arch}".encode())
    for f in ["Makefile", "cuda.mk", "labs/labs.toml",
              *sorted(str(p.relative_to(ROOT)) for p in ROOT.glob("labs/*/lab.mk"))]:
        h.update(f.encode() + b"\0" + (ROOT / f).read_bytes())
    return h.hexdigest()[:16]


def sync_mirror(files: list[str], objects: str) -> None:
    """Make MIRROR hold exactly `files` of the repository, and of its object folders only
    `objects`. A file whose content changed is rewritten (so it is newer than its objects
    and make rebuilds them); an unchanged one keeps its time, so make does not."""
    wanted = set(files)
    for f in files:
        src, dst = ROOT / f, MIRROR / f
        if dst.is_file() and filecmp.cmp(src, dst, shallow=False):
            continue
        dst.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(src, dst)
        shutil.copymode(src, dst)
    for path in MIRROR.glob("obj-*"):
        if path.name != objects:
            shutil.rmtree(path)
    for path in MIRROR.rglob("*"):
        rel = path.relative_to(MIRROR)
        if not rel.parts[0].startswith("obj-") and path.is_file() and rel.as_posix() not in wanted:
            path.unlink()


def build(targets: list[str], files: list[str], dest: pathlib.Path) -> tuple[list[str], str]:
    """Build `targets` in the mirror of `files` and copy those that built into `dest`; (their
    names, the build's output). One release at a time builds and copies there (a lock)."""
    LOCK.parent.mkdir(parents=True, exist_ok=True)
    opt = portable_opt()
    cuda_arch = make_variable("CUDA_NO_GPU_ARCH")
    objects = f"obj-{build_key(opt, cuda_arch)}"
    with open(LOCK, "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        sync_mirror(files, objects)
        for t in targets:  # phony targets relink anyway; a stale binary must not count as built
            (MIRROR / t).unlink(missing_ok=True)
        # -k: a GPU reference that cannot build (no nvcc) must not stop the CPU ones.
        # -j: one compiler per core; a first release compiles every reference from scratch.
        # CURDIR=. sets RT_SOURCE_DIR (the default scene's folder) to the working directory.
        cores = len(os.sched_getaffinity(0))
        make = subprocess.Popen(["make", "-k", "-s", f"-j{cores}", "-C", str(MIRROR), "CURDIR=.",
                                 f"OPT={opt}", f"CUDA_ARCH={cuda_arch}", f"BUILD={objects}",
                                 *targets], env=make_environment(), text=True, errors="replace",
                                stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
        try:
            log = make.communicate()[0]
        except BaseException:  # interrupted: make stops its compilers, removes half-built files
            make.terminate()
            make.wait()
            raise
        built = [t for t in targets if (MIRROR / t).is_file()]
        dest.mkdir(parents=True, exist_ok=True)
        for t in built:
            shutil.copy2(MIRROR / t, dest / t)
        return built, log


def front_door(lab: str, prebuilt: list[str], student_folders: list[str]) -> str:
    """The release's GNUmakefile. GNU make reads it before Makefile, twice over:
    - as the front door (`make X`): it copies each prebuilt reference out of reference-bin/
      where missing or older, then runs Makefile for the goals with `-o` for every prebuilt
      one (`--assume-old`: never rebuilt, so a target that needs ./lab01-ref, such as
      bench-serial, finds the copy rather than linking a solution the release lacks);
    - after Makefile, in that inner run (`-f Makefile -f GNUmakefile`), to compile the unit
      tests against the student's own copies of shared files (`student_folders` first on
      their include path), as the student's lab binary is.
    `make test` and `make test-labs` run the release's own tests: Makefile's first build every
    binary of the course, which needs the solutions. `LAB` defaults to the release's lab."""
    includes = " ".join(f"-I{folder}" for folder in student_folders)
    unit = (f"$(BUILD)/tests/unit/%.o: LAB_INCLUDES = {includes}\n" if includes
            else "# (no shared file is the student's in this lab)\n")
    return f"""\
# Lab {lab} release: GNU make reads this file before Makefile (see grading/README.md).
# Lab {lab} and the labs after it come without their solution sources, so their reference
# binaries ship prebuilt in reference-bin/ (x86-64 Linux) and are copied into place by every
# make run; Makefile never rebuilds them (-o). Every goal is otherwise Makefile's.
PREBUILT := {' '.join(prebuilt)}
LAB ?= {lab}
PYTHON ?= python3

ifeq ($(firstword $(MAKEFILE_LIST)),Makefile)
# The inner run, read after Makefile: the unit tests see the student's copies of shared files.
{unit}else
GOALS := $(or $(MAKECMDGOALS),help)
OWN_GOALS := $(filter $(PREBUILT) test test-labs,$(GOALS))
OTHER_GOALS := $(filter-out $(OWN_GOALS),$(GOALS))
# $(MAKE) is written out in each recipe, so that make -n runs the inner make too.
INNER = --no-print-directory -f Makefile -f GNUmakefile $(addprefix -o ,$(PREBUILT)) LAB=$(LAB)
.PHONY: $(filter-out $(PREBUILT),$(GOALS)) release-prebuilt release-goals
.DEFAULT_GOAL := $(firstword $(GOALS))

# Copied, then renamed: a binary that is running (a grade in progress) cannot be overwritten.
$(PREBUILT): %: reference-bin/%
\t@cp reference-bin/$@ $@.partial-copy && mv -f $@.partial-copy $@
release-prebuilt: $(PREBUILT)

test: release-prebuilt
\t@$(MAKE) $(INNER) deps test-unit
\t$(PYTHON) -m pytest -q tests
test-labs: release-prebuilt
\t$(PYTHON) -m pytest -q tests
# The other goals of the command line, in one run of Makefile.
ifneq ($(OTHER_GOALS),)
$(OTHER_GOALS): release-goals ; @:
release-goals: release-prebuilt
\t@$(MAKE) $(INNER) $(OTHER_GOALS)
endif
endif
"""
