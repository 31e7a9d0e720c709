"""Compiling a submission's sources in the sandbox. The compiler reads what it is told to:
a render.cpp with `#include "/path/to/labs/01-serial/solution/render.cpp"` would otherwise
hand in the solution, and compile errors would print any file the grader can read. So the
build runs under bubblewrap too, seeing of the repository only what building a lab variant
needs: the Makefile and the labs' make fragments, common/ (the shared sources and headers),
the lab folders' own top-level files and the built driver objects in build/, read-only; no
solutions, no references, no golden data, no grader.

The Makefile stays the one place that knows how a lab is built (`make variant`); the driver
objects must be up to date beforehand (building lab01-ref, and lab04-ref for lab 04, does
that), as the sandbox cannot write build/.
"""
from __future__ import annotations

import pathlib
import shutil

from grading import gpu
from grading.harness import ROOT
from grading.sandbox import Limits, Runner

COMPILE_LIMITS = Limits(wall_seconds=300, cpu_seconds=600, output_bytes=1 << 20)


# Solutions a lab's own build reads (its lab.mk puts them on the include path): lab 07 is
# lab 06's reference wavefront with the student's pool, so its students are given lab 06's
# queue and stage loop. Only that lab's builds see them.
SHARED_SOLUTIONS = {"07-soa": ("labs/06-cuda-split/solution",)}


def visible_tree(variant_lab: str = "") -> list[pathlib.Path]:
    """The parts of the repository a variant build of `variant_lab` reads."""
    paths = [ROOT / "Makefile", ROOT / "cuda.mk", ROOT / "grading" / "grading.mk",
             ROOT / "common", ROOT / "build"]
    for lab in sorted((ROOT / "labs").iterdir()):
        paths += [f for f in sorted(lab.iterdir()) if f.is_file()]  # lab.mk, shared drivers
    paths += [ROOT / folder for folder in SHARED_SOLUTIONS.get(variant_lab, ())]
    return [p for p in paths if p.exists()]


def build_in_sandbox(variant_lab: str, src: pathlib.Path,
                     target: str = "variant") -> tuple[pathlib.Path | None, str]:
    """Build the sources in `src` as `variant_lab` (e.g. 01-serial) into src/lab with
    `make target` (cuda-variant for a CUDA lab): (binary, "") or (None, the compiler's
    output)."""
    # nvcc is found by its absolute path: the sandbox's PATH holds only the system's folders,
    # and the toolkit (under /usr/local) is visible but not on it.
    nvcc = shutil.which("nvcc")
    extra = [f"NVCC={nvcc}"] if target == "cuda-variant" and nvcc else []
    if target == "cuda-variant" and (arch := gpu.cuda_arch_flags()):
        extra.append(f"CUDA_ARCH={arch}")  # the GPU here only (gpu.cuda_arch_flags says why)
    with Runner(trusted=False) as r:
        for path in visible_tree(variant_lab):
            r.bind(path)
        r.bind(src, writable=True)
        out = r.run(["make", "-s", "-C", str(ROOT), target, f"VARIANT_LAB={variant_lab}",
                     f"VARIANT={src.resolve()}", *extra], COMPILE_LIMITS)
    binary = src / "lab"
    if out.failure is None and binary.is_file():
        return binary, ""
    return None, f"{out.failure}\n{out.stdout}{out.stderr}"
