"""Broken lab-05 hand-ins for the GPU rubrics' tests: the reference hand-in (labs/05-cuda-mega/
solution/ and the megakernel's loops, common/cuda/render_kernel.cuh) with one classic GPU bug
each, built as `make cuda-variant` builds a student's folder. Each edit names the text it
replaces, which must be in the solution exactly once, so a change to the solution that moves
that text fails the build loudly instead of testing a mutant that is no longer broken.
"""
from __future__ import annotations

import dataclasses
import pathlib

from grading.compile import COMPILE_CHECK_ARCH
from grading.releases.leaks import skeletons
from labkit import gpu
from labkit.harness import ROOT, make_in_root
from labkit.variants import lab_sources

LAB = "05-cuda-mega"


def reference_hand_in(lab: str) -> dict[str, str]:
    """What a student of `lab` hands in, as the reference has it: the solution folder's files
    and the shared files the lab's students write (labkit/skeletons.py's SHARED_SOURCES)."""
    shared = {pathlib.Path(path).name: (ROOT / path).read_text()
              for path in skeletons.SHARED_SOURCES.get(lab, [])}
    return {**lab_sources(lab), **shared}


@dataclasses.dataclass(frozen=True)
class Mutant:
    what: str                             # the bug, as a student would make it
    file: str                             # the hand-in file edited
    edits: tuple[tuple[str, str], ...]    # (text in the solution, what replaces it)


MUTANTS = {
    # The kernel's launch returns at once; the pixels are copied into pinned memory with
    # cudaMemcpyAsync (queued after the kernel) and read on the host without waiting for the
    # copy, so the host reads them before the kernel has written them. (With pageable memory
    # cudaMemcpyAsync would wait and hide the bug; pinned memory is what makes it async.)
    "missing-sync": Mutant(
        "no synchronisation: the band is read back before the kernel has finished",
        "render.cu",
        (('    check_launch("running the render kernel");\n    return timer.seconds();',
          '    check(cudaGetLastError(), "launching the render kernel");  // and no wait\n'
          '    return 0.0;'),
         ("    args.pixels = band.data();\n",
          "    args.pixels = band.data();\n"
          "    Vec3* staging = nullptr;\n"
          "    check(cudaMallocHost(&staging, band.bytes()), \"allocating pinned memory\");\n"),
         ("        check(cudaMemcpy(&image.at(0, first), band.data(), args.rows * row_bytes,\n"
          "                         cudaMemcpyDeviceToHost),\n"
          "              \"copying the pixels back from the GPU\");\n",
          "        check(cudaMemcpyAsync(staging, band.data(), args.rows * row_bytes,\n"
          "                              cudaMemcpyDeviceToHost),\n"
          "              \"copying the pixels back from the GPU\");\n"
          "        std::copy(staging, staging + static_cast<size_t>(args.rows) * width,\n"
          "                  &image.at(0, first));\n"),
         ("    return seconds;\n",
          "    cudaDeviceSynchronize();\n    cudaFreeHost(staging);\n    return seconds;\n"))),
    # Row and column swapped when a thread finds its pixel: every pixel is stored where it
    # belongs but renders the camera ray of its mirror image across the diagonal, so a square
    # image comes out transposed.
    "swapped-index": Mutant(
        "wrong index arithmetic: x and y of the thread's pixel swapped",
        "render_kernel.cuh",
        (("    const int x = static_cast<int>(band_pixel % width);\n"
          "    const int y = args.first_row + static_cast<int>(band_pixel / width);\n",
          "    const int x = static_cast<int>(band_pixel / width);\n"
          "    const int y = args.first_row + static_cast<int>(band_pixel % width);\n"),)),
}


def mutant_sources(name: str) -> dict[str, str]:
    """The solution's files with the mutant's edits applied."""
    mutant = MUTANTS[name]
    files = reference_hand_in(LAB)
    text = files[mutant.file]
    for old, new in mutant.edits:
        if text.count(old) != 1:
            raise ValueError(f"mutant {name}: {LAB}'s reference {mutant.file} holds "
                             f"{text.count(old)} copies of the text to replace, not 1: "
                             f"{old.splitlines()[0].strip()!r}")
        text = text.replace(old, new)
    return {**files, mutant.file: text}


def build_cuda_folder(lab: str, folder: pathlib.Path, files: dict[str, str]) -> pathlib.Path:
    """`files` written into `folder` and built as `make cuda-variant` builds a CUDA lab's
    folder (the pristine skeletons are built so too); returns the binary."""
    folder.mkdir(parents=True, exist_ok=True)
    for name, text in files.items():
        (folder / name).write_text(text)
    # The grader's architectures: the GPU present, else sm_90 alone (grading/compile.py).
    arch = gpu.cuda_arch_flags() or COMPILE_CHECK_ARCH
    p = make_in_root("cuda-variant", f"VARIANT_LAB={lab}", f"VARIANT={folder}",
                     f"CUDA_ARCH={arch}", capture_output=True, text=True, timeout=900)
    if p.returncode != 0:
        raise RuntimeError(f"building {folder} as {lab} failed:\n{(p.stdout + p.stderr)[-3000:]}")
    return folder / "lab"
