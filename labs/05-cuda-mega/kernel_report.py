#!/usr/bin/env python3
"""The compiler's resource report of the CUDA labs' kernels as a table (`make kernel-report`).

Reads logs of `nvcc -Xptxas -v` (registers, stack frame, spills, shared and constant
memory per kernel and architecture; the build keeps one beside each CUDA object) and lists
the kernels compiled for one architecture, with the theoretical occupancy each kernel's
registers allow at its block size there. Needs no GPU.

    kernel_report.py PTXAS.LOG... --arch sm_90 [--out REPORT.md] [--json REPORT.json]
"""
from __future__ import annotations

import argparse
import json
import re
import shutil
import subprocess
import sys

# Per-multiprocessor limits (CUDA programming guide, "Compute capabilities"): registers,
# warps, blocks, shared memory per SM in bytes, register allocation unit per warp.
LIMITS = {
    75: dict(regs=65536, warps=32, blocks=16, smem=65536, unit=256),
    80: dict(regs=65536, warps=64, blocks=32, smem=167936, unit=256),
    86: dict(regs=65536, warps=48, blocks=16, smem=102400, unit=256),
    89: dict(regs=65536, warps=48, blocks=24, smem=102400, unit=256),
    90: dict(regs=65536, warps=64, blocks=32, smem=233472, unit=256),
}

ENTRY = re.compile(r"Compiling entry function '([^']+)' for '(sm_\d+)'")
FRAME = re.compile(r"(\d+) bytes stack frame, (\d+) bytes spill stores, (\d+) bytes spill loads")
USED = re.compile(r"Used (\d+) registers")
SMEM = re.compile(r"(\d+) bytes smem")
CMEM = re.compile(r"(\d+) bytes cmem\[(\d+)\]")


def demangle(names: list[str]) -> dict[str, str]:
    if not names or shutil.which("c++filt") is None:
        return {n: n for n in names}
    out = subprocess.run(["c++filt"], input="\n".join(names), capture_output=True,
                         text=True).stdout.splitlines()
    return dict(zip(names, out)) if len(out) == len(names) else {n: n for n in names}


def parse(log: str) -> list[dict]:
    kernels, current = [], None
    for line in log.splitlines():
        if m := ENTRY.search(line):
            current = dict(mangled=m.group(1), arch=m.group(2), registers=0, stack=0,
                           spill_stores=0, spill_loads=0, smem=0, cmem={})
            kernels.append(current)
        elif current is None:
            continue
        elif m := FRAME.search(line):
            current.update(stack=int(m[1]), spill_stores=int(m[2]), spill_loads=int(m[3]))
        elif m := USED.search(line):
            current["registers"] = int(m[1])
            if s := SMEM.search(line):
                current["smem"] = int(s[1])
            current["cmem"] = {int(b): int(n) for n, b in CMEM.findall(line)}
    names = demangle([k["mangled"] for k in kernels])
    for k in kernels:
        k["name"] = names[k["mangled"]]
        k["block_threads"] = block_threads(k["name"])
    return kernels


def block_threads(name: str) -> int:
    """render_kernel<T, memory, BLOCK, ...>, small_scene_kernel<SPHERES, RECTS, T, BLOCK, ...>;
    the benchmark's plain kernel uses 16x16."""
    if m := re.search(r"render_kernel<(\d+), [^,]+, (\d+),", name):
        return int(m[2])
    if m := re.search(r"small_scene_kernel<\d+, \d+, \d+, (\d+),", name):
        return int(m[1])
    return 256


def occupancy(registers: int, block: int, smem: int, arch: int) -> float:
    """Fraction of the SM's warp slots that resident blocks of this kernel can fill."""
    lim = LIMITS.get(arch, LIMITS[90])
    warps_per_block = -(-block // 32)
    regs_per_warp = -(-max(registers, 1) * 32 // lim["unit"]) * lim["unit"]
    by_regs = (lim["regs"] // regs_per_warp) // warps_per_block
    by_warps = lim["warps"] // warps_per_block
    by_smem = lim["smem"] // (smem + 1024) if smem else lim["blocks"]
    blocks = min(by_regs, by_warps, lim["blocks"], by_smem)
    return blocks * warps_per_block / lim["warps"]


# The kind sets the CUDA labs compile kernels for, by the names their sources use
# (geometry_set.h, material_set.h, kernel_choice.cuh, bench.cu).
KIND_SETS = {
    "Kinds<Sphere, Triangle, ConvexQuad, AxisRect>": "AnyGeometry",
    "Kinds<Sphere, Triangle, ConvexQuad>": "GeneralGeometry",
    "Kinds<Sphere, AxisRect>": "BoxGeometry",
    "Kinds<Sphere, ConvexQuad>": "SpheresAndQuads",
    "Kinds<Sphere, Triangle>": "SpheresAndTriangles",
    "Kinds<Diffuse, Mirror, Glass>": "AnyMaterial",
    "Kinds<Diffuse>": "DiffuseOnly",
}


# megakernel.cuh's PathLoop, as the demangler writes its values.
PATH_LOOPS = {"(PathLoop)0": "whole", "(PathLoop)1": "together", "(PathLoop)2": "regenerate",
              "(PathLoop)3": "claimed"}


# path_queue.cuh's Reserve: how a wavefront kernel's pushes reserve their places.
RESERVES = {"(Reserve)0": "per block", "(Reserve)1": "per warp", "(Reserve)2": "per thread"}


def short(name: str) -> str:
    for value, loop in PATH_LOOPS.items():
        name = name.replace(value, loop)
    name = name.replace("(SceneMemory)0", "global").replace("(SceneMemory)1", "constant")
    name = name.replace("(SceneMemory)2", "shared").replace("SceneMemory::", "")
    for value, how in RESERVES.items():
        name = name.replace(value, how)
    for kinds, alias in KIND_SETS.items():
        name = name.replace(kinds, alias)
    name = re.sub(r"\s+>", ">", name)  # the demangler writes "Foo<Bar<int> >"
    # render_kernel's last argument: the rectangles as slabs (the default, left unsaid) or by
    # the core's exact test.
    name = re.sub(r"(render_kernel<.*), true>", r"\1>", name)
    name = re.sub(r"(render_kernel<.*), false>", r"\1, exact rectangles>", name)
    # The kernel's parameter list (after its template arguments) says nothing new: dropped, so
    # that every template argument stays and no two kernels read alike.
    return re.sub(r"^void |(?<=>)\(.*\)$", "", name)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("logs", nargs="+", metavar="log")
    parser.add_argument("--arch", default="sm_90")
    parser.add_argument("--out")
    parser.add_argument("--json")
    args = parser.parse_args()
    # One text, so the names are demangled in one call (each log starts with its first entry).
    kernels = parse("\n".join(open(log).read() for log in args.logs))
    if not kernels:
        print(f"kernel-report: no kernels found in {' '.join(args.logs)}", file=sys.stderr)
        return 1
    found = sorted({k["arch"] for k in kernels})
    kernels = [k for k in kernels if k["arch"] == args.arch]
    if not kernels:
        print(f"kernel-report: the objects hold no {args.arch} code, only {', '.join(found)}: "
              f"make kernel-report KERNEL_REPORT_ARCH={found[-1]}", file=sys.stderr)
        return 1
    arch = int(args.arch.removeprefix("sm_"))
    seen, rows = set(), []
    for k in kernels:
        if k["mangled"] in seen:  # the same kernel compiled in two files
            continue
        seen.add(k["mangled"])
        k["occupancy"] = occupancy(k["registers"], k["block_threads"], k["smem"], arch)
        rows.append(k)
    lines = [f"Kernel resources for {args.arch} (nvcc -Xptxas -v); occupancy is the theoretical",
             "fraction of warp slots the registers allow at the kernel's block size "
             "(shared memory for the scene, when used, is dynamic and not counted).", "",
             "| kernel | block | registers | spill stores (B) | spill loads (B) | stack (B) "
             "| static smem (B) | occupancy |", "|---|---:|---:|---:|---:|---:|---:|---:|"]
    for k in rows:
        lines.append(f"| `{short(k['name'])}` | {k['block_threads']} | {k['registers']} | "
                     f"{k['spill_stores']} | {k['spill_loads']} | {k['stack']} | {k['smem']} | "
                     f"{k['occupancy']:.0%} |")
    text = "\n".join(lines) + "\n"
    if args.out:
        open(args.out, "w").write(text)
    if args.json:
        json.dump(rows, open(args.json, "w"), indent=1)
    print(text, end="")
    return 0


if __name__ == "__main__":
    sys.exit(main())
