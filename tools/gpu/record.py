"""The GPU records, one per card the course may get (reference/gpu/h100/, reference/gpu/h200/),
read as numbers: what `make gpu-check` wrote on that card (tools/gpu/check.sh) and what the
handouts, the README and the GPU labs' timed renders quote of it (tools/gpu/figures.py,
tests/tools/test_gpu_figures.py), and what the GPU tests' loose bars read on that card.

    bench-lab05.json, bench-lab05-fast-math.json   lab05-bench: the megakernel's shapes
    bench-lab06.json, bench-lab07.json              lab06-bench, lab07-bench: the wavefront's
    gpu-check.json                                  accuracy, process time, Nsight Compute
    wavefront.md                                    labs/06-cuda-split/measure.sh's scenes
    machine.txt, summary.md, tests.txt              the machine, the tables, the GPU tests

    python3 -m tools.gpu.record --install DIR       DIR (check.sh's output) becomes the record
                                                    of the card it ran on
"""
from __future__ import annotations

import argparse
import functools
import json
import pathlib
import re
import shutil
import sys

from labkit.harness import ROOT

RECORDS = ROOT / "reference" / "gpu"
# Each card's folder, by what its name holds ("NVIDIA H100 80GB HBM3").
CARDS = {"h100": "H100", "h200": "H200"}
# The card whose record is of the current code of every lab: the one the handouts' lab 05
# figures and lab 05's timed render come from (the H200's record is of the kernel before).
CURRENT = "h100"
RECORD = RECORDS / CURRENT
# The record each GPU lab's timed render is derived from (labs/labs.toml's timed_spp): lab 05's
# reference changed with the current record; labs 06 and 07 keep the spp of their record.
TIMED_SPP_CARD = {"05": CURRENT, "06": "h200", "07": "h200"}


def card_of(gpu_name: str) -> str | None:
    """The record folder of a GPU by its name, or None for a card the course has no record of."""
    for card, token in CARDS.items():
        if token in gpu_name:
            return card
    return None


def record_of(card: str) -> pathlib.Path:
    return RECORDS / card


def best_ms(card: str, bench: str, config: str) -> float | None:
    """A configuration's best kernel ms in a card's record (bench: "lab05", "lab06", "lab07"),
    or None when the card has no such record."""
    path = record_of(card) / f"bench-{bench}.json"
    if not path.exists():
        return None
    data = json.loads(path.read_text())
    for entry in data.get("variants", data.get("configs", [])):
        if entry["name"] == config:
            return entry["best_ms"]
    return None


# check.sh's output files, by the names the record gives them.
RECORD_FILES = {"bench.json": "bench-lab05.json",
                "bench-fast-math.json": "bench-lab05-fast-math.json",
                "bench-lab06.json": "bench-lab06.json", "bench-lab07.json": "bench-lab07.json",
                "gpu-check.json": "gpu-check.json", "summary.md": "summary.md",
                "wavefront.md": "wavefront.md", "machine.txt": "machine.txt"}


def install(out: pathlib.Path) -> pathlib.Path:
    """Copies a check.sh output folder into the record of the card it ran on (its bench.json's
    device); returns the record's folder."""
    device = json.loads((out / "bench.json").read_text())["device"]
    card = card_of(device)
    if card is None:
        raise SystemExit(f"gpu_record: no record folder for {device} (tools/gpu/record.py CARDS)")
    target = record_of(card)
    target.mkdir(parents=True, exist_ok=True)
    for name, recorded in RECORD_FILES.items():
        if (out / name).exists():
            shutil.copy(out / name, target / recorded)
    return target


def load(name: str, record: pathlib.Path = RECORD) -> dict:
    return json.loads((record / name).read_text())


@functools.lru_cache(maxsize=4)
def read(record: pathlib.Path = RECORD) -> dict:
    """Every figure of the record, by where it comes from:
    lab05[shape], lab05_fast[shape]: lab05-bench's variants (best_ms, registers, ...): since
    the small-scene kernel, "reference" is it and "kinds-kernel" the kernel for the scene's
    kinds; a record made before has no "kinds-kernel", and its "reference" is that kernel;
    lab06[config], lab07[config]: lab06-bench's and lab07-bench's, stage[kernel] each;
    scenes[bench][config]: measure.sh's best ms per scene (wavefront.md);
    accuracy[build], host_ms, process (list of process/kernel seconds), ncu[name], machine."""
    check = load("gpu-check.json", record)
    lab05, fast = load("bench-lab05.json", record), load("bench-lab05-fast-math.json", record)
    kinds_is_reference = all(v["name"] != "kinds-kernel" for v in lab05["variants"])
    out = {
        "lab05": {v["name"]: v for v in lab05["variants"]},
        "lab05_fast": {v["name"]: v for v in fast["variants"]},
        "baseline": {k: lab05[k] for k in ("width", "height", "spp", "bounces", "device")},
        "targets05": {t["config"]: t for t in lab05.get("targets", [])},
        "host_ms": lab05["host_ms"],
        "accuracy": check["accuracy"],
        "process": check["process_vs_kernel"],
        "ncu": ncu_by_shape(check["ncu"], kinds_is_reference),
        "scenes": wavefront_scenes((record / "wavefront.md").read_text()),
        "machine": (record / "machine.txt").read_text(),
    }
    for lab in ("06", "07"):
        bench = load(f"bench-lab{lab}.json", record)
        out[f"lab{lab}"] = {c["name"]: dict(c, stage={s["kernel"]: s for s in c.get("stages", [])})
                            for c in bench["configs"]}
    return out


# The Nsight Compute runs of tools/gpu/check.sh name a kernel, not a shape: which of
# lab05-bench's shapes each kernel is, by the run and the kernel's template arguments
# (render_kernel: threads a pixel, scene memory, block, path loop, register cap, materials,
# geometry, slabs; small_scene_kernel: spheres, rectangles, threads a pixel, block, register
# cap, shadow rays culled, surface by selects).
NCU_SHAPES = {
    # The small-scene kernel for the Cornell box's counts (small_scene.cuh): lab05-ref's kernel
    # on the baseline since it was chosen for small scenes, lab05-bench's "reference" (the
    # IEEE build's: 56 registers, the surface by index), and its small- shapes.
    ("cornell", "1, 5, 32, 64, 56, true, false"): "reference",
    ("cornell-1-bounce", "1, 5, 32, 64, 56, true, false"): "reference, 1 bounce",
    ("cornell", "1, 5, 32, 64, 56, true, true"): "small-selects",
    ("cornell", "1, 5, 32, 64, 56, false, false"): "small-no-cull",
    ("cornell", "1, 5, 32, 64, 64, true, false"): "small-regs-64",
    ("cornell", "1, 5, 32, 64, 255, true, false"): "small-no-register-cap",
    # The kernels since the rectangles' slabs (render_kernel's last argument, slabs or not, as
    # the demangler writes it: 1 or 0). The kernel for the Cornell box's kinds is
    # "kinds-kernel": a record made before the small-scene kernel, whose lab05-bench has no
    # such shape, calls it "reference" (read() renames it, KINDS_AS_REFERENCE).
    ("cornell", "32, 1, 64, 0, 56, Kinds<Diffuse>, Kinds<Sphere, AxisRect>, 1"): "kinds-kernel",
    ("cornell", "32, 1, 64, 0, 56, Kinds<Diffuse>, Kinds<Sphere, AxisRect>, 0"):
        "exact-rects",
    ("cornell", "32, 1, 64, 0, 56, Kinds<Diffuse>, Kinds<Sphere, Triangle, ConvexQuad>, 1"):
        "general",
    ("cornell", "32, 1, 64, 0, 56, Kinds<Diffuse>, Kinds<Sphere, ConvexQuad>, 1"): "quads",
    ("cornell", "32, 1, 64, 0, 56, Kinds<Diffuse>, Kinds<Sphere, Triangle>, 1"): "triangles",
    ("cornell", "32, 2, 64, 0, 56, Kinds<Diffuse>, Kinds<Sphere, AxisRect>, 1"): "scene-shared",
    ("cornell", "32, 1, 64, 2, 56, Kinds<Diffuse>, Kinds<Sphere, AxisRect>, 1"): "regenerate",
    ("cornell", "32, 1, 64, 1, 56, Kinds<Diffuse>, Kinds<Sphere, AxisRect>, 1"): "together",
    ("cornell", "32, 1, 64, 3, 56, Kinds<Diffuse>, Kinds<Sphere, AxisRect>, 1"): "claimed",
    ("cornell", "32, 1, 64, 0, 255, Kinds<Diffuse>, Kinds<Sphere, AxisRect>, 1"):
        "no-register-cap",
    ("cornell-1-bounce", "32, 1, 64, 0, 56, Kinds<Diffuse>, Kinds<Sphere, AxisRect>, 1"):
        "kinds-kernel, 1 bounce",
    ("showcase", "32, 1, 64, 0, 56, Kinds<Diffuse, Mirror, Glass>, "
                 "Kinds<Sphere, Triangle, ConvexQuad, AxisRect>, 1"): "showcase",
    # The kernels before (the H200's record).
    ("cornell", "32, 1, 64, 0, 56, Kinds<Diffuse>, Kinds<Sphere, AxisRect>"): "reference",
    ("cornell", "32, 1, 64, 0, 56, Kinds<Diffuse>, Kinds<Sphere, Triangle, ConvexQuad>"): "general",
    ("cornell", "32, 1, 64, 0, 56, Kinds<Diffuse>, Kinds<Sphere, ConvexQuad>"): "quads",
    ("cornell", "32, 1, 64, 0, 56, Kinds<Diffuse>, Kinds<Sphere, Triangle>"): "triangles",
    ("cornell", "32, 2, 64, 0, 56, Kinds<Diffuse>, Kinds<Sphere, AxisRect>"): "scene-shared",
    ("cornell", "32, 1, 64, 2, 56, Kinds<Diffuse>, Kinds<Sphere, AxisRect>"): "regenerate",
    ("cornell", "32, 1, 64, 1, 56, Kinds<Diffuse>, Kinds<Sphere, AxisRect>"): "together",
    ("cornell", "32, 1, 64, 0, 255, Kinds<Diffuse>, Kinds<Sphere, AxisRect>"): "no-register-cap",
    ("cornell", "plain_kernel"): "plain",
    ("cornell-1-bounce", "32, 1, 64, 0, 56, Kinds<Diffuse>, Kinds<Sphere, AxisRect>"):
        "reference, 1 bounce",
    ("showcase", "32, 1, 64, 0, 56, Kinds<Diffuse, Mirror, Glass>, "
                 "Kinds<Sphere, Triangle, ConvexQuad, AxisRect>"): "showcase",
}
NCU_PATHS = 600 * 600 * 64  # check.sh profiles the baseline's size at 64 spp
# The kinds kernel's profiles under the name they had while it was lab05-ref's kernel on the
# baseline: a record whose lab05-bench has no "kinds-kernel" shape (one made before the
# small-scene kernel) names them so, as its bench-lab05.json does.
KINDS_AS_REFERENCE = {"kinds-kernel": "reference", "kinds-kernel, 1 bounce": "reference, 1 bounce"}


def number(text: str) -> float:
    return float(text.replace(",", ""))


# The kind sets as the recorded profiles spell them, from when a set was a row of flags
# (GeometrySet<spheres, triangles, quads, rects>, MaterialSet<mirror, glass>), in the names
# the sources give them now (kinds.h).
OLD_SETS = {
    r"GeometrySet<([01, ]+)>": ("", ["Sphere", "Triangle", "ConvexQuad", "AxisRect"]),
    r"MaterialSet<([01, ]+)>": ("Diffuse", ["Mirror", "Glass"]),
}


def kinds_spelling(args: str) -> str:
    for pattern, (always, kinds) in OLD_SETS.items():
        def named(m, always=always, kinds=kinds):
            flags = [f.strip() == "1" for f in m.group(1).split(",")]
            return "Kinds<" + ", ".join([always] * bool(always)
                                        + [k for k, f in zip(kinds, flags) if f]) + ">"
        args = re.sub(pattern, named, args)
    return args


def ncu_by_shape(rows: list, kinds_is_reference: bool = False) -> dict:
    """Per shape: active threads per warp, issue slots used (%), thread instructions per
    path, and its integer and FP32 shares. kinds_is_reference: the record's lab05-bench
    has no "kinds-kernel" shape, so its kinds kernel is its "reference" (KINDS_AS_REFERENCE)."""
    rename = KINDS_AS_REFERENCE if kinds_is_reference else {}
    out = {}
    for r in rows:
        name = r["Kernel Name"]
        args = name[name.find("<") + 1:name.rfind(">")] if "<" in name else name.split("(")[0]
        args = kinds_spelling(args)
        shape = NCU_SHAPES.get((r["run"], args))
        if shape is None:
            continue
        shape = rename.get(shape, shape)
        out[shape] = {
            "active": number(r["smsp__thread_inst_executed_per_inst_executed.ratio"]),
            "issue": number(r["smsp__issue_active.avg.pct_of_peak_sustained_active"]),
            "per_path": number(r["smsp__thread_inst_executed.sum"]) / NCU_PATHS,
            "integer": number(r["smsp__sass_thread_inst_executed_op_integer_pred_on.sum"])
            / NCU_PATHS,
            "fp32": number(r["smsp__sass_thread_inst_executed_op_fp32_pred_on.sum"]) / NCU_PATHS,
        }
    return out


def wavefront_scenes(text: str) -> dict:
    """measure.sh's runs (wavefront.md): per `### bench-NAME` section, each configuration's
    best ms from its first table."""
    scenes = {}
    for section in re.split(r"^### ", text, flags=re.M)[1:]:
        name = section.split(":", 1)[0].strip()
        rows = {}
        for line in section.splitlines():
            cells = [c.strip() for c in line.strip().strip("|").split("|")]
            if len(cells) == 8 and re.fullmatch(r"[\d.]+", cells[2]):
                rows.setdefault(cells[0], float(cells[2]))
        scenes[name] = rows
    return scenes


def baseline_paths(record: dict) -> int:
    b = record["baseline"]
    return b["width"] * b["height"] * b["spp"]


def throughput(record: dict, lab: str) -> float:
    """Paths a second of lab `lab`'s reference on the baseline, kernel time only."""
    best_ms = {"05": record["lab05"]["reference"]["best_ms"],
               "06": record["lab06"]["AoS"]["best_ms"],
               "07": record["lab07"]["SoA"]["best_ms"]}[lab]
    return baseline_paths(record) / (best_ms / 1000)


# The timed render's spp is a multiple of this: whole waves of the wavefront's samples and a
# round number in the grader's output.
SPP_STEP = 256


def timed_spp(record: dict, lab: str, pixels: int, seconds: float) -> int:
    """The spp at which lab `lab`'s reference renders `pixels` pixels in `seconds` of kernel
    time on the record's GPU, to the nearest multiple of SPP_STEP."""
    exact = seconds * throughput(record, lab) / pixels
    return max(SPP_STEP, SPP_STEP * round(exact / SPP_STEP))


def timed_seconds(record: dict, lab: str, pixels: int, spp: int) -> float:
    return pixels * spp / throughput(record, lab)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description="the GPU records")
    p.add_argument("--install", metavar="DIR", required=True,
                   help="copy check.sh's output folder DIR into its card's record")
    a = p.parse_args(argv)
    print(f"gpu_record: {a.install} -> {install(pathlib.Path(a.install))}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
