"""tradeoff.json: everything a `make tradeoff` report is made from, written by every run.

Why: the GPU machine has numpy but no matplotlib and no package registry. A run there with
--no-plots writes the CSV, Markdown and this file; `python3 -m tools.tradeoff --replot DIR` on a
machine with matplotlib reads it back and writes the plots and the same Markdown a run with
plots would have written. The JSON is strict (no NaN literals): a float that is not finite
(an efficiency with no usable error, an infinite standard error) is written as the string
"nan", "inf" or "-inf", which float() reads back.
"""
from __future__ import annotations

import dataclasses
import json
import math
import pathlib

from tools.tradeoff.bias import BiasPoint
from tools.tradeoff.fit import Fit
from tools.tradeoff.report import Machine
from tools.tradeoff.sweep import Point, Sweep

FORMAT = "tradeoff record v1"  # load() refuses anything else
FILE = "tradeoff.json"


@dataclasses.dataclass
class Record:
    machine: Machine
    mode: str                # the plan's name
    note: str
    sweeps: list             # Sweep, each with its Points and Fit
    references: dict         # scene -> what its reference is
    unavailable: list        # [name, why it has no row]
    bias_points: list        # BiasPoint
    bias_setup: str          # the bias section's paragraph
    bias_ref_bounces: int
    interior: dict           # albedo, radius, intensity: the closed form's parameters
    failures: list           # one phrase per failed check


def _plain(value):
    """`value` with every non-finite float as a string, so json.dumps(allow_nan=False) takes it."""
    if isinstance(value, float) and not math.isfinite(value):
        return str(value)
    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    return value


def _make(cls, data: dict):
    """cls(**data), reading back the float fields written as strings by _plain."""
    floats = {f.name for f in dataclasses.fields(cls) if f.type in ("float", "float | None")}
    return cls(**{k: float(v) if k in floats and isinstance(v, str) else v
                  for k, v in data.items()})


def save(path: pathlib.Path, record: Record) -> None:
    data = {"format": FORMAT, **dataclasses.asdict(record)}
    path.write_text(json.dumps(_plain(data), indent=1, allow_nan=False) + "\n")


def load(path: pathlib.Path) -> Record:
    """The record in `path`; ValueError with one line when it is not one."""
    try:
        data = json.loads(path.read_text())
    except OSError as e:
        raise ValueError(f"{path}: cannot read it ({e.strerror or e}); every run of "
                         "python3 -m tools.tradeoff writes one") from None
    except json.JSONDecodeError as e:
        raise ValueError(f"{path}: not JSON ({e})") from None
    if not isinstance(data, dict) or data.get("format") != FORMAT:
        raise ValueError(f"{path}: not a record written by python3 -m tools.tradeoff "
                         f"(no \"format\": \"{FORMAT}\")")
    try:
        sweeps = [_make(Sweep, {**s, "points": [_make(Point, p) for p in s["points"]],
                                "fit": _make(Fit, s["fit"]) if s["fit"] else None})
                  for s in data["sweeps"]]
        return Record(
            machine=_make(Machine, data["machine"]), mode=data["mode"], note=data["note"],
            sweeps=sweeps, references=data["references"],
            unavailable=[tuple(u) for u in data["unavailable"]],
            bias_points=[_make(BiasPoint, b) for b in data["bias_points"]],
            bias_setup=data["bias_setup"], bias_ref_bounces=data["bias_ref_bounces"],
            interior=data["interior"], failures=data["failures"])
    except (KeyError, TypeError) as e:
        raise ValueError(f"{path}: a record of python3 -m tools.tradeoff lacks or mistypes "
                         f"{e}") from None
