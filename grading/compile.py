"""Compiling a submission's sources in the sandbox, in the students' tree.

The compiler reads what it is told to: a render.cpp with `#include "/path/to/labs/01-serial/
solution/render.cpp"` would otherwise hand in the solution, and compile errors would print any
file the grader can read. So the build runs in the sandbox too, seeing only a copy of the
students' tree of its lab (grading/students_tree.py: the skeleton forms of the shared files the
lab's students write, the drivers built from them, never a solution or the references' build/)
with the submission's files in it; the tree is read-only there but for the submission's folder.

The Makefile stays the one place that knows how a lab is built (`make variant`). Every folder
the build used is removed; the binary is kept in a folder of its own until the grader exits.
"""
from __future__ import annotations

import atexit
import pathlib
import shutil
import tempfile

from grading import source_rules, students_tree
from labkit import double_twin, gpu, registry
from labkit.sandbox import Limits, Runner

COMPILE_LIMITS = Limits(wall_seconds=300, cpu_seconds=600, output_bytes=1 << 20)
COMPILE_CHECK_ARCH = "-gencode arch=compute_90,code=sm_90"  # a CUDA build where no GPU is

_kept: list[pathlib.Path] = []


@atexit.register
def _remove_kept() -> None:
    for folder in _kept:
        shutil.rmtree(folder, ignore_errors=True)


def keep_binary(binary: pathlib.Path) -> pathlib.Path:
    """A copy of `binary` in a folder removed when the grader exits."""
    folder = pathlib.Path(tempfile.mkdtemp(prefix="graded-binary-"))  # the grader's alone:
    folder.chmod(0o700)  # each run gets a copy (labkit/sandbox.py, Runner.input)
    _kept.append(folder)
    kept = folder / "lab"
    shutil.copyfile(binary, kept)
    kept.chmod(0o755)
    double_twin.built_from_a_handin(kept)  # whatever it holds, it runs as it was built
    return kept


def build_in_sandbox(variant_lab: str, handin: pathlib.Path, target: str = "variant",
                     trusted: bool = False, files: dict[str, bytes] | None = None,
                     tree_lab: str | None = None) -> tuple[pathlib.Path | None, str, str]:
    """Build the hand-in folder `handin` as `variant_lab` (e.g. 01-serial) with `make target`
    (cuda-variant for a CUDA lab): (binary, "", note) or (None, why, note). `why` is one line
    for a hand-in refused before compiling, else the compiler's output; `note` says which
    expected files the skeleton's stubs stood in for. `files` (already read from the hand-in)
    and `tree_lab` (the lab whose students' tree it is built in) build a part of a lab
    (grading/checks/part_a.py: lab 02's Part A, variant 02-simd-a, in lab 02's tree)."""
    try:
        files, missing = (files, []) if files is not None else \
            students_tree.collect(handin, variant_lab)
    except students_tree.HandInError as e:
        return None, f"refused: {e}", students_tree.ignored(handin)
    lab = students_tree.lab_number(variant_lab)
    try:
        source_rules.check(files, registry.lab(lab).handin_kib, lab)
    except source_rules.SourceError as e:
        return None, f"refused: {e}", students_tree.ignored(handin)
    note = "\n".join(line for line in (
        students_tree.ignored(handin),  # programs and other files: never run, only named
        f"not handed in, the skeleton's copy used: {', '.join(missing)}" if missing else "",
    ) if line)
    work = students_tree.stage(tree_lab or variant_lab, files, missing, target,
                               variant_lab=variant_lab)
    try:
        tree, src = work / "tree", work / "tree" / "submission"
        # nvcc is found by its absolute path: the sandbox's PATH holds only the system's
        # folders, and the toolkit (under /usr/local) is visible but not on it.
        nvcc = shutil.which("nvcc")
        extra = [f"NVCC={nvcc}"] if target == "cuda-variant" and nvcc else []
        if target == "cuda-variant":
            # The GPU here only (gpu.cuda_arch_flags says why); without one the build can only
            # show whether the sources compile, which one architecture shows as well as six.
            extra.append(f"CUDA_ARCH={gpu.cuda_arch_flags() or COMPILE_CHECK_ARCH}")
        with Runner(trusted=trusted) as r:
            r.close_to_others(work)
            r.bind(tree)
            r.bind(src, writable=True)
            out = r.run(["make", "-s", "-C", str(tree), target, f"VARIANT_LAB={variant_lab}",
                         f"VARIANT={src}", *extra], COMPILE_LIMITS)
        if out.foreign:  # the compiler and make are the system's: nothing else may run
            return None, f"refused: its build ran a program it was not given: {out.foreign}", note
        binary = src / "lab"
        if out.failure is None and binary.is_file() and not binary.is_symlink():
            return keep_binary(binary), "", note
        # The compiler names files by the grader's temporary folders: the student's by name.
        said = (out.stdout + out.stderr).replace(f"{src}/", "").replace(f"{tree}/", "")
        return None, f"{out.failure}\n{said}", note
    finally:
        shutil.rmtree(work, ignore_errors=True)
