"""What the handouts and the README quote of the GPU records (reference/gpu/<card>/, one per
card), generated from them or checked against them, so that no figure there can drift from
its record.

    python3 -m tools.gpu.figures              rewrite the generated tables
    python3 -m tools.gpu.figures --check      exit 1 naming every figure that differs
    python3 -m tools.gpu.figures --timed-spp  the GPU labs' timed spp the record gives

Three kinds of figure:
- a table between the marker lines of table_markers(NAME, CARD) is generated whole by
  TABLES[NAME] from that card's record (the marker names it);
- a figure in the prose is one of PROSE's phrases, each a format string over a record
  (figures()): the file's (FILE_CARD) or the phrase's own (a (card, phrase) pair), which must
  stand in its file word for word as that record renders it;
- any other "N.NN ms" outside the tables must be a number one of the records holds (stale()),
  so an earlier run's figure left in the text fails too.
The GPU labs' timed_spp in labs/labs.toml is the spp the record of record.TIMED_SPP_CARD gives
for the grader's GPU_TIMED_SECONDS (record.timed_spp). tests/tools/test_gpu_figures.py runs
all of it.
"""
from __future__ import annotations

import argparse
import json
import re
import sys

from labkit import registry
from labkit.harness import ROOT
from tools.gpu import record as rec

FILES = ["README.md", "handouts/05-cuda-mega.md", "handouts/06-cuda-split.md",
         "handouts/07-soa.md", "labs/05-cuda-mega/README.md", "labs/06-cuda-split/README.md",
         "labs/07-soa/README.md"]


# The card whose record each file's prose quotes, where it is not the current one
# (record.CURRENT): labs 06 and 07, whose references the current record did not change, keep
# the H200's.
FILE_CARD = {"handouts/06-cuda-split.md": "h200", "handouts/07-soa.md": "h200",
             "labs/06-cuda-split/README.md": "h200", "labs/07-soa/README.md": "h200"}


def table_markers(name: str, card: str) -> tuple[str, str]:
    return (f"<!-- GPU record table '{name}': generated from reference/gpu/{card}/ by "
            f"`python3 -m tools.gpu.figures`; edit the record, not this table -->",
            f"<!-- end of GPU record table '{name}' -->")


def ms(x: float) -> str:
    return f"{x:.2f}"


def pct(x: float) -> str:
    return f"{100 * x:.0f}%"


def grouped(x: float) -> str:
    return f"{x:,.0f}"


def rows(header: list[str], align: list[str], body: list[list]) -> str:
    lines = ["| " + " | ".join(header) + " |", "|" + "|".join(align) + "|"]
    lines += ["| " + " | ".join(str(c) for c in r) + " |" for r in body]
    return "\n".join(lines)


def ncu_cells(r: dict, shape: str) -> list[str]:
    n = r["ncu"].get(shape)
    return ([f"{n['active']:.1f}", grouped(n["per_path"])] if n else
            ["not measured", "not measured"])


# ---- lab 05 -------------------------------------------------------------------------------
# lab05-ref runs two kernels: on a scene the small-scene kernels hold (the Cornell box) the one
# compiled for its counts (common/cuda/small_scene.cuh), lab05-bench's "reference"; on every
# other the kernel for its kinds (render_kernel.cuh, the one the students write),
# "kinds-kernel". Most shapes of lab05-bench change one thing of the kinds kernel, so the
# tables of those compare them with it. A record made before the small-scene kernel has no
# "kinds-kernel": its "reference" is the kinds kernel.
def kinds_shape(r) -> str:
    """The kinds kernel's shape in a record: "kinds-kernel" where its lab05-bench has that
    shape, else "reference" (a record made before the small-scene kernel)."""
    return "kinds-kernel" if "kinds-kernel" in r["lab05"] else "reference"


def has_small_reference(r) -> bool:
    """Whether the record's "reference" is the small-scene kernel (it has both kernels)."""
    return kinds_shape(r) != "reference"


def target_bar(r, config: str) -> str:
    """A lab 05 speed target as the record's benchmark printed it, without its card and scene."""
    bar = r["targets05"].get(config, {}).get("bar", "")
    return bar.split(" on an NVIDIA")[0]


def lab05_targets(r):
    b = r["lab05"]
    body = [["`reference`", ms(b["reference"]["best_ms"]), target_bar(r, "reference")]]
    if has_small_reference(r):
        body[0][0] = "`reference` (the small-scene kernel)"
        body.append(["`kinds-kernel` (the kernel you write)", ms(b["kinds-kernel"]["best_ms"]),
                     ""])
    return rows(["shape", "kernel ms", "target"], ["---", "---:", "---"], body + [
        ["`general`", ms(b["general"]["best_ms"]), target_bar(r, "general")],
        ["`plain` (section 2)", ms(b["plain"]["best_ms"]), ""]])


def lab05_split(r):
    b, pixels = r["lab05"], r["baseline"]["width"] * r["baseline"]["height"]
    return rows(["threads per pixel", "threads in the grid", "kernel ms"], ["---:", "---:", "---:"],
                [[n, grouped(n * pixels), ms(b[shape]["best_ms"])]
                 for n, shape in ((1, "split-1"), (16, "split-16"), (32, kinds_shape(r)))])


def lab05_scene_memory(r):
    b = r["lab05"]
    return rows(["shape", "scene in", "registers", "kernel ms"], ["---", "---", "---:", "---:"],
                [[f"`{s}`", b[s]["scene_memory"], b[s]["registers"], ms(b[s]["best_ms"])]
                 for s in (kinds_shape(r), "scene-shared", "scene-global")])


def lab05_blocks(r):
    b = r["lab05"]
    return rows(["threads per block", "registers", "occupancy", "kernel ms"],
                ["---:", "---:", "---:", "---:"],
                [[b[s]["block_threads"], b[s]["registers"], pct(b[s]["occupancy"]),
                  ms(b[s]["best_ms"])] for s in ("block-32", kinds_shape(r), "block-128")])


def lab05_registers(r):
    b = r["lab05"]
    return rows(["shape", "register cap", "registers", "local bytes", "occupancy", "kernel ms",
                 "active threads per warp", "thread instructions per path"],
                ["---", "---:", "---:", "---:", "---:", "---:", "---:", "---:"],
                [[f"`{s}`", "none" if b[s]["max_registers"] >= 255 else b[s]["max_registers"],
                  b[s]["registers"], b[s]["local_bytes"], pct(b[s]["occupancy"]),
                  ms(b[s]["best_ms"]), *ncu_cells(r, s)]
                 for s in ("no-register-cap", "regs-64", kinds_shape(r), "regs-48")])


def lab05_materials(r):
    b = r["lab05"]
    what = [("all-materials", "every material and primitive kind"),
            (kinds_shape(r), "diffuse only, spheres and rectangles")]
    return rows(["shape", "kernel compiled for", "registers", "kernel ms"],
                ["---", "---", "---:", "---:"],
                [[f"`{s}`", kinds, b[s]["registers"], ms(b[s]["best_ms"])] for s, kinds in what])


def lab05_divergence(r):
    k = kinds_shape(r)
    what = [("plain", "`plain` (`render_pixel` per pixel)", "Cornell, 4"),
            (k, f"`{k}`", "Cornell, 4"),
            (f"{k}, 1 bounce", f"`{k}`", "Cornell, **1**"),
            ("showcase", f"`{k}`'s shape, every material", "showcase (mirror, glass)")]
    if has_small_reference(r):  # the small-scene kernel, where the record profiled it
        what += [(s, "`reference` (the small-scene kernel)", scene) for s, scene in
                 (("reference", "Cornell, 4"), ("reference, 1 bounce", "Cornell, **1**"))
                 if s in r["ncu"]]
    body = []
    for shape, label, scene in what:
        n = r["ncu"][shape]
        body.append([label, scene, f"{n['active']:.1f}", f"{n['issue']:.0f}%",
                     grouped(n["per_path"]), grouped(n["integer"]), grouped(n["fp32"])])
    return rows(["kernel", "scene, bounces", "active threads per warp", "issue slots used",
                 "thread instructions per path", "integer", "FP32"],
                ["---", "---", "---:", "---:", "---:", "---:", "---:"], body)


def lab05_geometry(r):
    b = r["lab05"]
    walls = {"triangles": "10 triangles", "triangles-shared": "10 triangles",
             "quads": "5 convex quads", "general": "5 convex quads",
             "exact-rects": "5 axis-aligned rectangles, the core's exact test",
             kinds_shape(r): "5 axis-aligned rectangles, slabs",
             "any-geometry": "5 axis-aligned rectangles, slabs"}
    walls = {s: w for s, w in walls.items() if s in b}
    kinds = {"SpheresAndTriangles": "spheres, triangles", "SpheresAndQuads": "spheres, quads",
             "GeneralGeometry": "every kind but rectangles (`GeneralGeometry`)",
             "BoxGeometry": "spheres, rectangles (`BoxGeometry`)",
             "AnyGeometry": "every kind (`AnyGeometry`)"}
    body = [[f"**`{s}`**" if s == kinds_shape(r) else f"`{s}`", walls[s],
             kinds[b[s]["primitives"]],
             b[s]["scene_memory"], ms(b[s]["best_ms"]), *ncu_cells(r, s)] for s in walls]
    return rows(["shape", "the walls as", "kernel compiled for", "scene in", "kernel ms",
                 "active threads per warp", "thread instructions per path"],
                ["---", "---", "---", "---", "---:", "---:", "---:"], body)


def lab05_path_loops(r):
    b = r["lab05"]
    what = [(kinds_shape(r), "whole paths (`trace_samples`)"),
            ("regenerate", "path regeneration (`trace_samples_regenerating`)"),
            ("together", "lanes kept together (`trace_samples_together`)"),
            ("claimed", "samples claimed by the warp (`trace_samples_claimed`)"),
            ("claimed-regs-64", "samples claimed by the warp, at most 64 registers")]
    what = [(s, how) for s, how in what if s in b]
    return rows(["shape", "a thread's samples by", "registers", "local bytes", "kernel ms",
                 "active threads per warp", "thread instructions per path"],
                ["---", "---", "---:", "---:", "---:", "---:", "---:"],
                [[f"`{s}`", how, b[s]["registers"], b[s]["local_bytes"], ms(b[s]["best_ms"]),
                  *ncu_cells(r, s)] for s, how in what])


SMALL_SHAPES = [("small-selects", "the hit's surface chosen by selects as the loop finds it"),
                ("small-no-cull", "the shadow ray tested against every rectangle"),
                ("small-regs-56", "at most 56 registers"),
                ("small-regs-64", "at most 64 registers"),
                ("small-no-register-cap", "registers left to the compiler")]


def lab05_small_scene(r):
    """The small-scene kernel (lab05-bench's "reference" since it was chosen) against the
    kinds kernel ("kinds-kernel") and its own variations, with and without fast math; a record
    made before it holds neither, and the table says so."""
    if not has_small_reference(r):
        return ("(This record was made before lab05-ref chose the small-scene kernel: its "
                "`reference` is the kinds kernel, and it has no `kinds-kernel` or `small-` "
                "shapes.)")
    b, fast = r["lab05"], r["lab05_fast"]
    kinds_ms = b["kinds-kernel"]["best_ms"]
    what = [("kinds-kernel", "the kernel for the scene's kinds (`render_kernel`)"),
            ("reference", "the small-scene kernel: the scene's counts compiled in")]
    what += [(s, f"small-scene kernel, {how}") for s, how in SMALL_SHAPES if s in b or s in fast]

    def cells(s):
        if s not in b:
            return ["", "", "", "not in this build", ""]
        v = b[s]
        return ["none" if v["max_registers"] >= 255 else v["max_registers"], v["registers"],
                v["local_bytes"], ms(v["best_ms"]),
                "—" if s == "kinds-kernel" else pct(v["best_ms"] / kinds_ms - 1)]

    def fast_cell(s):
        return ms(fast[s]["best_ms"]) if s in fast else ""

    return rows(["shape", "kernel", "register cap", "registers", "local bytes", "kernel ms",
                 "against `kinds-kernel`", "kernel ms, fast math"],
                ["---", "---", "---:", "---:", "---:", "---:", "---:", "---:"],
                [[f"**`{s}`**" if s == "reference" else f"`{s}`", how, *cells(s), fast_cell(s)]
                 for s, how in what])


def lab05_process(r):
    return rows(["process (wall clock)", "kernel (CUDA events)"], ["---:", "---:"],
                [[f"{p['process_seconds']:.3f} s", f"{p['kernel_seconds']:.4f} s"]
                 for p in r["process"]])


def lab05_precision(r):
    a = r["accuracy"]
    body = []
    for build, label in (("lab05-ref", "default (FMA)"), ("lab05-ref-no-fma", "`--fmad=false`"),
                         ("lab05-ref-fast-math", "`--use_fast_math`")):
        x = a[build]
        same = x.get("vs_default_same_seed", {}).get("identical_pixels")
        body.append([label, "pass" if x["passed"] else "**fail**", f"{x['rmse']:.3e}",
                     f"{x['bias']:.2e} ({x['bias_se']:.1e})",
                     "—" if same is None else f"{100 * same:.1f}%",
                     f"{100 * x['identical_to_lab01_pixels']:.1f}%",
                     ms(1000 * x["baseline_kernel_seconds_best"])])
    return rows(["build", "golden comparison", "RMSE", "bias (standard error)",
                 "pixels identical to default build", "pixels identical to lab 01",
                 "baseline kernel ms"], ["---", "---", "---:", "---:", "---:", "---:", "---:"],
                body)


def lab05_fast_math(r):
    fast, plain = r["lab05_fast"], r["lab05"]
    return rows(["shape", "kernel ms, fast math", "without fast math"], ["---", "---:", "---:"],
                [[f"`{s}`", ms(fast[s]["best_ms"]), ms(plain[s]["best_ms"])]
                 for s in fast if s in plain])


# ---- labs 06 and 07 -----------------------------------------------------------------------
def lab06_reserve(r):
    c = r["scenes"]["bench-cornell"]
    how = [("", "one atomic per block (the reference)"),
           ("-atomic-per-warp", "one atomic per warp (`cooperative_groups::coalesced_threads()`)"),
           ("-atomic-each", "one atomic per thread")]
    return rows(["reserve", "AoS (lab 06) ms", "SoA (lab 07) ms"], ["---", "---:", "---:"],
                [[label, ms(c["AoS" + suffix]), ms(c["SoA" + suffix])] for suffix, label in how])


def lab06_staged(r):
    b = r["lab06"]
    body = []
    for name, label in (("AoS-stored-by-thread", "each thread stores its record"),
                        ("AoS", "the block's records staged and copied out together "
                                "(the reference)")):
        s = b[name]["stage"]
        body.append([label, ms(b[name]["best_ms"]), ms(s["generate_camera_paths"]["ms"]),
                     f"{ms(s['shade_hits']['ms'])} ({s['shade_hits']['registers']})"])
    return rows(["AoS pushes", "all kernels ms", "`generate_camera_paths` ms",
                 "`shade_hits` ms (registers)"], ["---", "---:", "---:", "---:"], body)


def lab06_popping(r):
    c = r["scenes"]["bench-cornell"]
    how = [("", "one thread per queue place (the reference)"),
           ("-grid-stride", "a grid that fills the GPU once, threads striding over the queue"),
           ("-prefetch", "each thread loads its next item ahead")]
    return rows(["pops", "AoS ms", "SoA ms"], ["---", "---:", "---:"],
                [[label, ms(c["AoS" + suffix]), ms(c["SoA" + suffix])] for suffix, label in how])


def ratio_cell(fast: str, a: float, b: float) -> str:
    return f"{fast}, {max(a, b) / min(a, b):.2f}×"


SCENES = [("bench-cornell", "Cornell box (baseline)", 4), ("bench-cornell-16", "Cornell box", 16),
          ("bench-showcase", "showcase (glass, mirrors, 5 materials)", 8),
          ("bench-showcase-16", "showcase", 16)]


def lab06_scenes(r):
    body = []
    for bench, label, bounces in SCENES:
        s = r["scenes"][bench]
        mega, aos, soa = s["megakernel"], s["AoS"], s["SoA"]
        faster = (ratio_cell("megakernel", mega, aos) + " over AoS" if mega < aos else
                  ratio_cell("**wavefront (AoS)**", mega, aos))
        body.append([label, bounces, ms(mega), ms(aos), ms(soa), faster])
    return rows(["scene", "bounces", "megakernel (lab 05)", "wavefront, AoS (lab 06)",
                 "wavefront, SoA (lab 07)", "faster"],
                ["---", "---:", "---:", "---:", "---:", "---"], body)


KERNELS = ["generate_camera_paths", "find_closest_hits", "shade_hits", "trace_shadow_rays",
           "accumulate_samples"]


def lab06_per_kernel(r):
    aos, soa = r["lab06"]["AoS"]["stage"], r["lab07"]["SoA"]["stage"]
    body = [[k, ms(aos[k]["ms"]), ms(soa[k]["ms"]),
             f"{aos[k]['registers']} / {soa[k]['registers']}",
             f"{aos[k]['blocks_per_sm']} / {soa[k]['blocks_per_sm']}"] for k in KERNELS]
    body.append(["**all**", ms(sum(aos[k]["ms"] for k in KERNELS)),
                 ms(sum(soa[k]["ms"] for k in KERNELS)), "", ""])
    mega = r["lab06"]["megakernel"]
    body.append(["megakernel (lab 05)", ms(mega["best_ms"]), "",
                 f"{mega['registers']} (capped)",
                 f"{mega['blocks_per_sm']} blocks of 64 ({pct(mega['occupancy'])})"])
    return rows(["kernel", "AoS ms", "SoA ms", "registers AoS / SoA",
                 "blocks of 128 / SM, AoS / SoA"], ["---", "---:", "---:", "---:", "---:"], body)


def lab06_occupancy(r):
    c = r["scenes"]["bench-cornell"]
    caps = [("", "none (the reference)"), ("-occupancy-50", "8 blocks (at most 64 registers)"),
            ("-occupancy-75", "12 blocks (at most 40 registers)"),
            ("-occupancy-100", "16 blocks (at most 32 registers)")]
    return rows(["blocks of 128 a multiprocessor", "AoS ms", "SoA ms"], ["---", "---:", "---:"],
                [[label, ms(c["AoS" + suffix]), ms(c["SoA" + suffix])] for suffix, label in caps])


def lab06_queues(r):
    a = r["lab06"]["AoS"]
    camera = a["active_paths"][0]
    body = [[b, f"{100 * p / camera:.1f}%", f"{100 * s / camera:.1f}%"]
            for b, (p, s) in enumerate(zip(a["active_paths"], a["shadow_rays"]))]
    body.append(["per camera path", f"{sum(a['active_paths']) / camera:.2f} queries",
                 f"{sum(a['shadow_rays']) / camera:.2f} shadow rays"])
    return rows(["bounce", "paths on the queue", "shadow rays"], ["---:", "---:", "---:"], body)


def lab07_results(r):
    b = r["lab07"]
    names = [("AoS", "AoS (lab 06)"), ("AoS-stored-by-thread", "AoS, each thread storing its "
                                                                "record"), ("SoA", "SoA (lab 07)")]
    body = [["all kernels", *[ms(b[n]["best_ms"]) for n, _ in names],
             ms(b["megakernel"]["best_ms"])]]
    body += [[k, *[ms(b[n]["stage"][k]["ms"]) for n, _ in names], ""] for k in KERNELS]
    return rows(["", *[label for _, label in names], "megakernel (lab 05)"],
                ["---", "---:", "---:", "---:", "---:"], body)


def lab07_scenes(r):
    body = []
    for bench, label, bounces in SCENES:
        s = r["scenes"][bench]
        aos, soa = s["AoS"], s["SoA"]
        by = f"{aos / soa:.2f}×" + ("" if soa < aos else " (AoS faster)")
        body.append([label, bounces, ms(aos), ms(soa), by, ms(s["megakernel"])])
    return rows(["scene", "bounces", "AoS (lab 06)", "SoA (lab 07)", "SoA faster by",
                 "megakernel (lab 05)"], ["---", "---:", "---:", "---:", "---:", "---:"], body)


TABLES = {f.__name__.replace("_", "-"): f for f in (
    lab05_targets, lab05_split, lab05_scene_memory, lab05_blocks, lab05_registers,
    lab05_materials, lab05_divergence, lab05_geometry, lab05_path_loops, lab05_small_scene,
    lab05_process,
    lab05_precision, lab05_fast_math, lab06_reserve, lab06_staged, lab06_popping, lab06_scenes,
    lab06_per_kernel, lab06_occupancy, lab06_queues, lab07_results, lab07_scenes)}


# ---- figures in the prose -----------------------------------------------------------------
def figures(r: dict) -> dict:
    """The names PROSE's phrases use: the record's figures, formatted as the text quotes them."""
    b, l6, l7 = r["lab05"], r["lab06"], r["lab07"]
    fast, acc, n = r["lab05_fast"], r["accuracy"], r["ncu"]
    k = kinds_shape(r)  # the kinds kernel, which section 7's counters and savings are of
    cornell, show16 = r["scenes"]["bench-cornell"], r["scenes"]["bench-showcase-16"]
    grade = {lab.number: lab.timed_spp for lab in registry.labs() if lab.gpu}
    slow_reserves = (cornell["AoS-atomic-each"], cornell["AoS-atomic-per-warp"])
    return {
        "device": r["baseline"]["device"].split(" (")[0],
        "device_short": " ".join(w for w in r["baseline"]["device"].split(" (")[0].split()
                                 if w in ("H100", "H200")),
        "ref": ms(b["reference"]["best_ms"]), "ref1": f"{b['reference']['best_ms']:.1f}",
        "general": ms(b["general"]["best_ms"]), "plain": ms(b["plain"]["best_ms"]),
        "plain_gpaths": f"{b['plain']['paths_per_second'] / 1e9:.1f}",
        "plain_regs": b["plain"]["registers"], "plain_occ": pct(b["plain"]["occupancy"]),
        "ref_target": target_bar(r, "reference"),
        "exact_rects": ms(b["exact-rects"]["best_ms"]) if "exact-rects" in b else "",
        "kinds": ms(b[k]["best_ms"]),
        "slab_saving": (pct(1 - b[k]["best_ms"] / b["exact-rects"]["best_ms"])
                        if "exact-rects" in b else ""),
        "claimed": ms(b["claimed"]["best_ms"]) if "claimed" in b else "",
        "ref_regs": b["reference"]["registers"], "ref_occ": pct(b["reference"]["occupancy"]),
        "ref_blocks": b["reference"]["blocks_per_sm"],
        "plain_saving": pct(1 - b[k]["best_ms"] / b["plain"]["best_ms"]),
        "active": f"{n[k]['active']:.1f}", "issue": f"{n[k]['issue']:.0f}%",
        "per_path": grouped(n[k]["per_path"]),
        "active1": f"{n[f'{k}, 1 bounce']['active']:.1f}",
        "active_show": f"{n['showcase']['active']:.1f}",
        "per_path_show": grouped(n["showcase"]["per_path"]),
        "integer": grouped(n[k]["integer"]),
        "fast_ref": ms(fast["reference"]["best_ms"]),
        "fast_gain": pct(1 - fast["reference"]["best_ms"] / b["reference"]["best_ms"]),
        "no_fma": ms(1000 * acc["lab05-ref-no-fma"]["baseline_kernel_seconds_best"]),
        "no_fma_cost": pct(acc["lab05-ref-no-fma"]["baseline_kernel_seconds_best"]
                           / acc["lab05-ref"]["baseline_kernel_seconds_best"] - 1),
        "fma_ref": ms(1000 * acc["lab05-ref"]["baseline_kernel_seconds_best"]),
        "fma_differs": pct(1 - acc["lab05-ref"]["identical_to_lab01_pixels"]),
        "context_ms": f"{r['host_ms']['context_creation']:.1f}",
        "download_ms": ms(r["host_ms"]["image_download"]),
        "l6": ms(l6["AoS"]["best_ms"]), "l6_1": f"{l6['AoS']['best_ms']:.1f}",
        "l6_by_thread": ms(l6["AoS-stored-by-thread"]["best_ms"]),
        "l6_vs_mega": f"{l6['AoS']['best_ms'] / l6['megakernel']['best_ms']:.1f}",
        "l7_aos": ms(l7["AoS"]["best_ms"]), "l7": ms(l7["SoA"]["best_ms"]),
        "l7_1": f"{l7['SoA']['best_ms']:.1f}",
        "l7_by": f"{l7['AoS']['best_ms'] / l7['SoA']['best_ms']:.2f}",
        "l7_vs_mega": f"{l7['SoA']['best_ms'] / l7['megakernel']['best_ms']:.1f}",
        "l7_mega": ms(l7["megakernel"]["best_ms"]),
        "warp_atomic": ms(cornell["AoS-atomic-per-warp"]),
        "thread_atomic": ms(cornell["AoS-atomic-each"]),
        "slow_reserve": f"{cornell['AoS'] / max(slow_reserves):.2f}",
        "cornell_aos": ms(cornell["AoS"]),
        "wins_show16": f"{show16['megakernel'] / show16['AoS']:.2f}",
        "l6_mega": ms(l6["megakernel"]["best_ms"]),
        "l7_aos_short": ms(l7["AoS"]["best_ms"]),
        "show16_aos": ms(show16["AoS"]), "show16_mega": ms(show16["megakernel"]),
        "queries": f"{sum(l6['AoS']['active_paths']) / l6['AoS']['active_paths'][0]:.2f}",
        "shadows": f"{sum(l6['AoS']['shadow_rays']) / l6['AoS']['active_paths'][0]:.2f}",
        "lab05_timed_spp": grade["05"], "lab06_timed_spp": grade["06"],
        "lab07_timed_spp": grade["07"],
    }


# Each file's phrases that quote the record, as the record renders them (figures()).
PROSE = {
    "README.md": [
        "ready; {ref1} ms for the baseline on an {device_short}",
        ("h200", "ready; {l6_1} ms on the H200 (lab 05's earlier megakernel is faster on the "
                 "baseline, {l6_vs_mega}×; lab 06 wins only on the showcase at 16 bounces, "
                 "{wins_show16}×"),
        ("h200", "ready; {l7_1} ms on the H200"),
    ],
    "handouts/05-cuda-mega.md": [
        "takes **{plain} ms** for the baseline: {plain_gpaths} billion paths per second, "
        "{plain_regs} registers, {plain_occ} occupancy",
        "the {plain_saving} that the kinds kernel takes off that",
        "the kernel is bound by instruction issue, with about {active} of 32 lanes active",
        "The kinds kernel takes **{kinds} ms**, {slab_saving} less than the kernel before it "
        "(the rectangles by the core's exact test, the `exact-rects` shape: {exact_rects} ms in "
        "the same run), and misses the target of {ref_target}",
        "With four bounces, {active} of 32 lanes are active. With one bounce, {active1}",
        "{active_show} active lanes",
        "Its schedulers issue in about {issue} of their cycles",
        "About {integer} of the ~{per_path} instructions per path are integer instructions",
        "**{context_ms} ms**",
        "copying the 4.3 MB image back {download_ms} ms",
        "It costs {no_fma_cost} of kernel time ({no_fma} against {fma_ref} ms)",
        "**FMA** makes {fma_differs} of the pixels differ from lab 01's",
        "it is **{fast_gain} faster**: {fast_ref} against {ref} ms",
        "render the golden Cornell view at 640x640, {lab05_timed_spp} spp",
    ],
    "handouts/06-cuda-split.md": [
        "**The speed target (≤ 60 ms for AoS on the baseline) is met**: {l6} ms",
        "{l6_by_thread} ms with each thread storing its own",
        "the wavefront loses on the baseline by {l6_vs_mega}×",
        "on the showcase (glass, mirrors, five materials) the megakernel runs {active_show} "
        "active threads per warp, and at 16 bounces the AoS wavefront is {wins_show16}× faster",
        "render the golden Cornell view at 640x640, {lab06_timed_spp} spp",
        "{warp_atomic} and {thread_atomic} ms against {cornell_aos} in the record's "
        "`wavefront.md`: {slow_reserve}× the reference's speed",
    ],
    "labs/05-cuda-mega/README.md": [
        "the reference {ref} ms and `general` (walls as convex quads) {general} ms",
        "with `--use_fast_math` {fast_ref} ms",
    ],
    "labs/06-cuda-split/README.md": [
        "the wavefront on the AoS pool takes {l6} ms on the baseline",
        "({l6_by_thread} ms when each pushing thread stores its own record",
        "lab 05's megakernel takes {l6_mega} ms in the same process (`lab06-bench`): the "
        "megakernel is {l6_vs_mega}× faster",
        "({show16_aos} against {show16_mega} ms; the handout's section 4)",
    ],
    "labs/07-soa/README.md": [
        "measured SoA at {l7} ms against AoS's {l7_aos_short} (the target, SoA faster than AoS, "
        "is met, by {l7_by}×",
        "lab 05's megakernel at {l7_mega} ms in the same process, {l7_vs_mega}× faster than SoA",
    ],
    "handouts/07-soa.md": [
        "at the baseline each camera path makes {queries} closest-hit queries and asks for "
        "{shadows} shadow rays",
        "**The bar (SoA faster than AoS on the baseline) is met**: {l7} against {l7_aos} ms, "
        "{l7_by}×",
        "it renders the same image in {l7_mega} ms, {l7_vs_mega}× faster than SoA",
        "render the golden Cornell view at 640x640, {lab07_timed_spp} spp",
    ],
}


# ---- checking and rewriting ---------------------------------------------------------------
def generated(text: str) -> dict:
    """Each generated table a text holds, by name: (the whole block, its body, the card whose
    record it is generated from)."""
    out = {}
    for m in re.finditer(r"<!-- GPU record table '([\w-]+)': generated from reference/gpu/"
                         r"(\w+)/.*?-->\n(.*?)\n<!-- end of GPU record table '\1' -->", text, re.S):
        out[m.group(1)] = (m.group(0), m.group(3), m.group(2))
    return out


def block(name: str, r: dict, card: str) -> str:
    begin, end = table_markers(name, card)
    return f"{begin}\n{TABLES[name](r)}\n{end}"


def read_card(card: str) -> dict:
    return rec.read(rec.record_of(card))


def phrases(name: str) -> list[tuple[str, str]]:
    """A file's PROSE phrases, each with the card whose record it quotes."""
    default = FILE_CARD.get(name, rec.CURRENT)
    return [p if isinstance(p, tuple) else (default, p) for p in PROSE.get(name, [])]


def without_tables(text: str) -> str:
    for whole, _, _ in generated(text).values():
        text = text.replace(whole, "")
    return text


def record_numbers(records=None) -> set[float]:
    """Every number the records' files hold, and each times 1000 (seconds as ms)."""
    found = set()
    files = [f for d in (records or [rec.record_of(c) for c in rec.CARDS]) if d.is_dir()
             for f in d.iterdir() if f.is_file()]
    for f in files:
        for m in re.finditer(r"-?\d[\d,]*\.?\d*(?:e[-+]?\d+)?", f.read_text()):
            try:
                x = float(m.group(0).replace(",", ""))
            except ValueError:
                continue
            found |= {x, x * 1000}
    return found


def times(text: str):
    """Each time the text gives as "N.NN ms", and each N.NN in a table whose header names ms,
    outside the generated tables: (as written, the number)."""
    text = without_tables(text)
    for m in re.finditer(r"(?<![\d.])(\d+\.\d+) ms\b", text):
        yield m.group(0), m.group(1)
    header = ""
    for line in text.splitlines():
        if not line.startswith("|"):
            header = ""
        elif not header:
            header = line
        elif re.search(r"\bms\b", header):
            for cell in re.findall(r"(?<![\d.e-])(\d+\.\d\d)(?![\d.e])", line):
                yield f"{cell} in a table of times", cell


def stale(text: str, numbers: set[float]) -> list[str]:
    """Each time of the text (times()) that no number of the record rounds to."""
    bad = []
    for shown, figure in times(text):
        places = len(figure.split(".")[1])
        if not any(round(x, places) == float(figure) for x in numbers):
            bad.append(shown)
    return bad


def problems(root=ROOT, records=None) -> list[str]:
    """Every figure of FILES that is not its record's, one line each. records: the folder of
    each card's record (by default reference/gpu/<card>/)."""
    folders = records or {c: rec.record_of(c) for c in rec.CARDS}
    out, read = [], {}

    def record(card: str) -> dict:
        if card not in read:
            read[card] = rec.read(folders[card])
        return read[card]

    numbers = record_numbers(list(folders.values()))
    for name in FILES:
        text = (root / name).read_text()
        for table, (whole, _, card) in generated(text).items():
            if table not in TABLES:
                out.append(f"{name}: no table '{table}' in tools/gpu/figures.py")
            elif card not in folders:
                out.append(f"{name}: table '{table}' names no record of a card: {card}")
            elif whole != block(table, record(card), card):
                out.append(f"{name}: table '{table}' is not the record's ({card})")
        flowing = " ".join(text.split())  # a phrase may break across lines
        for card, phrase in phrases(name):
            said = phrase.format(**figures(record(card)))
            if said not in flowing:
                out.append(f"{name}: not found as the record ({card}) gives it: \"{said}\"")
        out += [f"{name}: '{s}' is no figure of any record in reference/gpu/" for s in
                stale(text, numbers)]
    placed = {t for name in FILES for t in generated((root / name).read_text())}
    out += [f"table '{t}' stands in no file" for t in TABLES if t not in placed]
    for lab in registry.labs():
        if lab.gpu:
            want = derived_spp(record(rec.TIMED_SPP_CARD[lab.number]), lab.number)
            if lab.timed_spp != want:
                out.append(f"labs/labs.toml: lab {lab.number}'s timed_spp is {lab.timed_spp}; "
                           f"the record ({rec.TIMED_SPP_CARD[lab.number]}) gives {want}")
    return out


def derived_spp(r: dict, lab: str) -> int:
    from grading import grade  # the grader's timed size: its view, its scale, its seconds
    side = grade_view_side() * grade.GPU_TIMED_SCALE
    return rec.timed_spp(r, lab, side * side, grade.GPU_TIMED_SECONDS)


def grade_view_side() -> int:
    """The side of the golden Cornell view the grader times (reference/golden/cornell)."""
    return json.loads((ROOT / "reference/golden/cornell/meta.json").read_text())["width"]


def rewrite(root=ROOT) -> list[str]:
    changed = []
    for name in FILES:
        path = root / name
        text = new = path.read_text()
        for table, (whole, _, card) in generated(text).items():
            if table in TABLES:
                new = new.replace(whole, block(table, read_card(card), card))
        if new != text:
            path.write_text(new)
            changed.append(name)
    return changed


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--check", action="store_true", help="exit 1 naming the figures that differ")
    p.add_argument("--timed-spp", action="store_true",
                   help="the GPU labs' timed spp the record gives (labs/labs.toml's timed_spp)")
    a = p.parse_args(argv)
    if a.timed_spp:
        for lab in registry.labs():
            if lab.gpu:
                card = rec.TIMED_SPP_CARD[lab.number]
                print(f"lab {lab.number}: timed_spp = {derived_spp(read_card(card), lab.number)} "
                      f"(labs.toml: {lab.timed_spp}; the {card} record)")
        return 0
    if a.check:
        bad = problems()
        for line in bad:
            print(line, file=sys.stderr)
        return 1 if bad else 0
    for name in rewrite():
        print(f"rewrote the GPU record's tables in {name}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
