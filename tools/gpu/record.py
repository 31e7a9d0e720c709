"""The GPU record, reference/gpu/h200/, read as numbers: what `make gpu-check` wrote on the
H200 (tools/gpu/check.sh) and what the handouts, the README and the GPU labs' timed renders
quote of it (tools/gpu/figures.py, tests/tools/test_gpu_figures.py).

    bench-lab05.json, bench-lab05-fast-math.json   lab05-bench: the megakernel's shapes
    bench-lab06.json, bench-lab07.json              lab06-bench, lab07-bench: the wavefront's
    gpu-check.json                                  accuracy, process time, Nsight Compute
    wavefront.md                                    labs/06-cuda-split/measure.sh's scenes
"""
from __future__ import annotations

import functools
import json
import pathlib
import re

from labkit.harness import ROOT

RECORD = ROOT / "reference" / "gpu" / "h200"


def load(name: str, record: pathlib.Path = RECORD) -> dict:
    return json.loads((record / name).read_text())


@functools.lru_cache(maxsize=4)
def read(record: pathlib.Path = RECORD) -> dict:
    """Every figure of the record, by where it comes from:
    lab05[shape], lab05_fast[shape]: lab05-bench's variants (best_ms, registers, ...);
    lab06[config], lab07[config]: lab06-bench's and lab07-bench's, stage[kernel] each;
    scenes[bench][config]: measure.sh's best ms per scene (wavefront.md);
    accuracy[build], host_ms, process (list of process/kernel seconds), ncu[name], machine."""
    check = load("gpu-check.json", record)
    lab05, fast = load("bench-lab05.json", record), load("bench-lab05-fast-math.json", record)
    out = {
        "lab05": {v["name"]: v for v in lab05["variants"]},
        "lab05_fast": {v["name"]: v for v in fast["variants"]},
        "baseline": {k: lab05[k] for k in ("width", "height", "spp", "bounces", "device")},
        "host_ms": lab05["host_ms"],
        "accuracy": check["accuracy"],
        "process": check["process_vs_kernel"],
        "ncu": ncu_by_shape(check["ncu"]),
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
# (threads a pixel, scene memory, block, path loop, register cap, materials, geometry).
NCU_SHAPES = {
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


def ncu_by_shape(rows: list) -> dict:
    """Per shape: active threads per warp, issue slots used (%), thread instructions per
    path, and its integer and FP32 shares."""
    out = {}
    for r in rows:
        name = r["Kernel Name"]
        args = name[name.find("<") + 1:name.rfind(">")] if "<" in name else name.split("(")[0]
        args = kinds_spelling(args)
        shape = NCU_SHAPES.get((r["run"], args))
        if shape is None:
            continue
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
