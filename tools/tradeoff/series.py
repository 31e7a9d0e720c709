"""What `make tradeoff` measures: one Series per renderer, each built here or marked
unavailable with the reason (which the report prints).

- the CPU references this host can build and run (lab01-ref ... lab04-simd-ref);
- the GPU reference (lab05-ref) and its double build (lab05-ref-double, shown like a
  variant) where nvidia-smi lists a GPU, they build and they render a pixel there;
- variants of the lab-01 reference built by `make variant` (labkit/variants.py): fast math,
  and a fixed world-space epsilon instead of the scale-aware ray offset of common/core/ray.h.
  A variant is one entry of VARIANTS: a name, what it changes, and either the files it
  stands in for and the make arguments, or a make target of its own (the double build,
  `make lab01-ref-double`: a `make variant` cannot mix double objects with the float driver,
  on purpose).
"""
from __future__ import annotations

import dataclasses
import os
import pathlib
import re
import shutil
import subprocess
from typing import Callable

from labkit.cuda_env import missing_gpu as gpu_missing
from labkit.harness import make_in_root
from labkit.mpi import mpirun
from labkit.variants import build_sources, lab_sources

ROOT = pathlib.Path(__file__).resolve().parents[2]

VARIANT_DIR = ROOT / "build" / "tradeoff" / "variants"
# Open MPI refuses to start as root unless told (containers, CI); as tools/bench/cpu.py does.
os.environ.setdefault("OMPI_ALLOW_RUN_AS_ROOT", "1")
os.environ.setdefault("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")


@dataclasses.dataclass
class Series:
    name: str                          # the row's label, e.g. "lab03-ref"
    what: str                          # one phrase for the report
    binary: pathlib.Path | None = None
    launcher: tuple = ()
    checked: bool = True               # must show slope -1/2 (references); variants are shown
    unavailable: str | None = None     # why there is no row, e.g. "double: not built yet"


# name, what it is, launcher. Each is `make NAME`; lab 04's run under mpirun with 2 ranks.
CPU_REFERENCES = [
    ("lab01-ref", "serial", ()),
    ("lab02a-ref", "serial, SSE Vec3 (lab 02 Part A)", ()),
    ("lab02-ref", "AVX2, 8 paths per packet, 1 thread", ()),
    ("lab03-ref", "OpenMP, every core", ()),
    ("lab03-simd-ref", "OpenMP + AVX2 packets, every core", ()),
    ("lab04-ref", "MPI, 2 ranks (mpirun)", tuple(mpirun(2))),
    ("lab04-simd-ref", "MPI + AVX2 packets, 2 ranks (mpirun)", tuple(mpirun(2))),
]


def first_words(text: str) -> str:
    """The first line of a program's message that says something (Open MPI opens with a row
    of dashes)."""
    return next((line.strip() for line in text.splitlines() if any(c.isalpha() for c in line)),
                "no message")


def make(target: str) -> str | None:
    """Builds `target`; returns None, or the last line of what make said when it failed that
    is not make's own "make: *** [...] Error 1" (which names no reason)."""
    p = make_in_root(target, capture_output=True, text=True)
    if p.returncode == 0:
        return None
    lines = [line for line in (p.stderr or p.stdout).strip().splitlines()
             if not re.match(r"make(\[\d+\])?: \*\*\*", line)]
    return f"does not build here: {lines[-1] if lines else 'make failed'}"


def cpu_references(names=None) -> list[Series]:
    out = []
    for name, what, launcher in CPU_REFERENCES:
        if names is not None and name not in names:
            continue
        s = Series(name, what, launcher=launcher)
        if launcher and shutil.which(launcher[0]) is None:
            s.unavailable = f"no {launcher[0]} on this machine"
        else:
            s.unavailable = make(name)
        if s.unavailable is None:
            s.binary = ROOT / name
        out.append(s)
    return out


def gpu_info() -> str | None:
    """'NAME, driver X' for each GPU nvidia-smi lists, or None (for the report's machine)."""
    if shutil.which("nvidia-smi") is None:
        return None
    p = subprocess.run(["nvidia-smi", "--query-gpu=name,driver_version",
                        "--format=csv,noheader"], capture_output=True, text=True)
    lines = [ln.strip() for ln in p.stdout.splitlines() if ln.strip()] if p.returncode == 0 else []
    if not lines:
        return None
    return "; ".join(f"{ln.split(',')[0].strip()}, driver {ln.split(',')[-1].strip()}"
                     for ln in lines)


def does_not_run(binary: pathlib.Path) -> str | None:
    """Why `binary` cannot render one pixel here, or None. A GPU build can compile where the
    GPU cannot be used (no driver, too old a driver, a GPU another job holds); finding out with
    a 1x1 render costs a CUDA start-up (0.31 s on the H200:
    `reference/gpu/` at commit `1fdebed`), finding out after
    minutes of reference renders costs those minutes."""
    try:
        p = subprocess.run([str(binary), "--quiet", "--width", "1", "--height", "1", "--spp",
                            "1"], capture_output=True, text=True, timeout=120)
    except (OSError, subprocess.TimeoutExpired) as e:
        return f"does not run here: {e}"
    if p.returncode == 0:
        return None
    return f"does not run here: {first_words(p.stderr).removeprefix('error: ')}"


# name, make target (= binary), what it is, checked. The double build is shown, not checked,
# as lab 01's is (VARIANTS below): what double costs on a GPU is the point.
GPU_REFERENCES = [
    ("lab05-ref", "lab05-ref", "CUDA megakernel (GPU)", True),
    ("lab05 double", "lab05-ref-double", "lab05-ref in double precision (-DRT_DOUBLE, GPU)",
     False),
    ("lab05 fast-math", "lab05-ref-fast-math", "lab05-ref built with --use_fast_math (GPU)", False),
    ("lab06-ref", "lab06-ref", "CUDA wavefront, array-of-structures path pool (GPU)", True),
    ("lab07-ref", "lab07-ref", "CUDA wavefront, structure-of-arrays path pool (GPU)", True),
]


def gpu_references() -> list[Series]:
    missing = gpu_missing()
    out = []
    for name, target, what, checked in GPU_REFERENCES:
        s = Series(name, what, checked=checked)
        s.unavailable = missing or make(target) or does_not_run(ROOT / target)
        if s.unavailable is None:
            s.binary = ROOT / target
        out.append(s)
    return out


# ---- variants of the lab-01 reference -------------------------------------------------------

FIXED_EPSILON = 1e-4  # world units: a typical hand-picked value, right for a unit-sized scene
_OFFSET_RETURN = re.compile(r"return p \+ n \* \(scale \* kRelativeOffset\);")


def fixed_epsilon_ray_h() -> str:
    """common/core/ray.h with offset_ray_origin moving the origin a fixed FIXED_EPSILON along
    the normal, whatever the scale. Made from the current ray.h (not a copy kept in the
    tree), so the variant changes that one line and follows every other edit of ray.h."""
    text = (ROOT / "common" / "core" / "ray.h").read_text()
    new, count = _OFFSET_RETURN.subn(
        f"(void)scale; return p + n * {FIXED_EPSILON!r}f;  // tradeoff variant: fixed epsilon",
        text)
    if count != 1:
        raise RuntimeError("common/core/ray.h: offset_ray_origin's return line changed; "
                           "update tools/tradeoff/series.py's fixed-epsilon variant")
    return new


@dataclasses.dataclass
class Variant:
    name: str
    what: str
    # Files standing in for the lab's (by bare name: ray.h, render.cpp...), and make variables.
    files: Callable[[], dict[str, str]] | None = None
    make_args: tuple = ()
    target: str | None = None     # a make target that builds it (its binary has that name)
    not_built: str | None = None  # why it has no build yet


VARIANTS = [
    Variant("lab01 fast-math", "lab01-ref's renderer compiled with -ffast-math",
            files=dict, make_args=("VARIANT_FLAGS_01-serial=-ffast-math",)),
    Variant("lab01 fixed-epsilon",
            f"lab01-ref with a fixed ray offset of {FIXED_EPSILON:g} along the normal "
            "(common/core/ray.h: scale-aware)",
            files=lambda: {"ray.h": fixed_epsilon_ray_h()}),
    Variant("lab01 double", "lab01-ref in double precision (-DRT_DOUBLE, common/core/real.h)",
            target="lab01-ref-double"),
]


def build_variant(v: Variant, log=print) -> Series:
    s = Series(v.name, v.what, checked=False)
    if v.not_built:
        s.unavailable = v.not_built
        return s
    if v.target:
        log(f"  building variant '{v.name}' (make {v.target}) ...")
        p = make_in_root(v.target, capture_output=True, text=True)
        if p.returncode != 0:
            s.unavailable = f"does not build: {first_words(p.stderr or p.stdout)}"
        else:
            s.binary = ROOT / v.target
        return s
    if not (ROOT / "labs" / "01-serial" / "solution").is_dir():  # a lab-01 student release
        s.unavailable = "not built here: lab 01's solution sources are not in this release"
        return s
    workdir = VARIANT_DIR / v.name.replace(" ", "-")
    if workdir.exists():
        shutil.rmtree(workdir)  # a stale file of an earlier variant must not stand in
    log(f"  building variant '{v.name}' (make variant) ...")
    try:
        s.binary = build_sources("01-serial", workdir, {**lab_sources("01-serial"), **v.files()},
                                 make_args=v.make_args)
    except RuntimeError as e:
        s.unavailable = f"does not build: {str(e).strip().splitlines()[-1]}"
    return s


def variants(names=None, log=print) -> list[Series]:
    """The VARIANTS called `names` (None: all), each built or marked unavailable."""
    return [build_variant(v, log) for v in VARIANTS if names is None or v.name in names]
