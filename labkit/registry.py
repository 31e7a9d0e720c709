"""The labs of the course, as labs/labs.toml declares them: the one list every tool reads.

    from labkit import registry
    registry.lab("05").folder        -> "05-cuda-mega"
    registry.gpu_labs()              -> ("05", "06", "07")

For shell and make, `python3 -m labkit.registry QUERY` prints one answer:

    numbers | folders | gpu-labs | cpu-labs    the labs, one per line
    folder NN | kind NN                        one field of lab NN
    targets [NN] | references [NN] | ships [NN] | student [NN]   make targets, one per line
    make                                       the Makefile's fragment (build/labs.mk)

A broken registry (a missing field, a lab declared twice, an unknown kind) is one error line
and exit status 2, here and in every program that reads it.
"""
from __future__ import annotations

import ast
import dataclasses
import functools
import pathlib
import re
import sys

try:
    import tomllib
except ModuleNotFoundError:  # Python 3.10 (Ubuntu 22.04, Gradescope's image): loads_subset()
    tomllib = None

ROOT = pathlib.Path(__file__).resolve().parent.parent
REGISTRY = ROOT / "labs" / "labs.toml"
KINDS = ("cpu", "mpi", "gpu")
RUBRICS = ("serial", "simd", "openmp", "mpi", "gpu", "gpu-soa")


class RegistryError(Exception):
    """What is wrong with labs/labs.toml: one line."""


@dataclasses.dataclass(frozen=True)
class Lab:
    number: str                  # "01"
    folder: str                  # "01-serial"
    kind: str                    # "cpu" | "mpi" | "gpu"
    student: tuple[str, ...]     # make targets built from skeleton/
    reference: tuple[str, ...]   # make targets built from solution/
    extras: tuple[str, ...]      # variants and benchmarks
    ships: tuple[str, ...]       # prebuilt in a release of this lab or an earlier one
    handin: tuple[str, ...]      # skeleton/ files students hand in
    handin_kib: int              # the most its hand-in's sources may hold together
    shared: tuple[str, ...]      # shared files whose solution regions are this lab's
    rubric: str
    try_command: str
    timed_spp: int | None = None
    speed_bar: float | None = None  # a GPU lab's speed bar, where it is not the grader's

    @property
    def path(self) -> pathlib.Path:
        return ROOT / "labs" / self.folder

    @property
    def targets(self) -> tuple[str, ...]:
        """Every make target of the lab."""
        return self.student + self.reference + self.extras

    @property
    def gpu(self) -> bool:
        return self.kind == "gpu"

    @property
    def handout(self) -> pathlib.Path:
        return ROOT / "handouts" / f"{self.folder}.md"


FIELDS = {"number": str, "folder": str, "kind": str, "student": list, "reference": list,
          "extras": list, "ships": list, "handin": list, "handin_kib": int, "shared": list,
          "rubric": str, "try": str}
OPTIONAL = {"timed_spp": int, "speed_bar": float}
TARGET = re.compile(r"^lab(\d\d)[a-z0-9-]*$")


def loads_subset(text: str) -> dict:
    """The TOML that labs.toml is written in, for a Python without tomllib: comments, [[name]]
    tables, and keys whose values are strings, integers or arrays of them, an array possibly
    over several lines. Such values are Python literals too (a trailing comment included)."""
    data: dict = {}
    table: dict = data
    key, value, start = None, "", 0
    for number, line in enumerate(text.splitlines(), 1):
        if key is None:
            bare = line.split("#", 1)[0].strip()
            if not bare:
                continue
            if m := re.fullmatch(r"\[\[\s*([A-Za-z0-9_-]+)\s*\]\]", bare):
                table = {}
                data.setdefault(m.group(1), []).append(table)
                continue
            if not (m := re.match(r"\s*([A-Za-z0-9_-]+)\s*=(.*)$", line)):
                raise ValueError(f"line {number}: expected key = value or [[table]]")
            key, value, start = m.group(1), m.group(2), number
        else:
            value += "\n" + line
        try:
            parsed = ast.literal_eval(value.strip())
        except (ValueError, SyntaxError):
            if value.count("[") > value.count("]"):
                continue  # an array that goes on over the next line
            raise ValueError(f"line {start}: {key}'s value is not a string, integer or "
                             f"array") from None
        if key in table:
            raise ValueError(f"line {start}: {key} given twice")
        table[key], key = (list(parsed) if isinstance(parsed, (list, tuple)) else parsed), None
    if key is not None:
        raise ValueError(f"line {start}: {key}'s array is not closed")
    return data


def parse(text: str, where: str = "labs/labs.toml") -> tuple[Lab, ...]:
    """The labs `text` declares, checked; RegistryError says what is wrong."""
    try:
        data = tomllib.loads(text) if tomllib else loads_subset(text)
    except (ValueError, SyntaxError) as e:  # tomllib.TOMLDecodeError is a ValueError
        raise RegistryError(f"{where}: not TOML: {e}") from None
    unknown_top = set(data) - {"lab"}
    if unknown_top or not isinstance(data.get("lab"), list) or not data["lab"]:
        raise RegistryError(f"{where}: expected [[lab]] tables and nothing else")
    labs: list[Lab] = []
    for index, entry in enumerate(data["lab"], 1):
        name = f"{where}: lab #{index} ({entry.get('folder', '?')})"
        for key, kind in FIELDS.items():
            if not isinstance(entry.get(key), kind):
                raise RegistryError(f"{name}: needs {key} ({kind.__name__})")
        for key in set(entry) - set(FIELDS) - set(OPTIONAL):
            raise RegistryError(f"{name}: unknown field {key!r}")
        for key in ("student", "reference", "extras", "ships", "handin", "shared"):
            if not all(isinstance(v, str) and v for v in entry[key]):
                raise RegistryError(f"{name}: {key} must list strings")
        number, folder = entry["number"], entry["folder"]
        if not re.fullmatch(r"\d\d", number) or not folder.startswith(f"{number}-"):
            raise RegistryError(f"{name}: number must be two digits and the folder start with "
                                f"them ({number!r}, {folder!r})")
        if entry["kind"] not in KINDS:
            raise RegistryError(f"{name}: kind must be one of {', '.join(KINDS)}")
        if entry["rubric"] not in RUBRICS:
            raise RegistryError(f"{name}: rubric must be one of {', '.join(RUBRICS)}")
        if entry["rubric"].startswith("gpu") != (entry["kind"] == "gpu"):
            raise RegistryError(f"{name}: a gpu rubric is for a gpu lab, and only for one")
        if entry["rubric"].startswith("gpu") and not isinstance(entry.get("timed_spp"), int):
            raise RegistryError(f"{name}: a gpu rubric needs timed_spp (int)")
        bar = entry.get("speed_bar")
        if bar is not None and not (entry["kind"] == "gpu" and isinstance(bar, float)
                                    and 0 < bar <= 1):
            raise RegistryError(f"{name}: speed_bar is a gpu lab's, a fraction in (0, 1]")
        targets = entry["student"] + entry["reference"] + entry["extras"]
        bad = [t for t in targets if not (m := TARGET.match(t)) or m.group(1) != number]
        if bad or not entry["student"] or not entry["reference"]:
            raise RegistryError(f"{name}: needs student and reference targets, each named "
                                f"lab{number}...{f' (not {bad[0]!r})' if bad else ''}")
        if f"lab{number}" not in entry["student"] or f"lab{number}-ref" not in entry["reference"]:
            raise RegistryError(f"{name}: student must hold lab{number} and reference "
                                f"lab{number}-ref")
        if len(set(targets)) != len(targets):
            raise RegistryError(f"{name}: a make target is listed twice")
        if not set(entry["ships"]) <= set(entry["reference"] + entry["extras"]):
            raise RegistryError(f"{name}: ships only what its solution builds (reference, extras)")
        labs.append(Lab(number=number, folder=folder, kind=entry["kind"],
                        student=tuple(entry["student"]), reference=tuple(entry["reference"]),
                        extras=tuple(entry["extras"]), ships=tuple(entry["ships"]),
                        handin=tuple(entry["handin"]), handin_kib=entry["handin_kib"],
                        shared=tuple(entry["shared"]),
                        rubric=entry["rubric"], try_command=entry["try"],
                        timed_spp=entry.get("timed_spp"), speed_bar=entry.get("speed_bar")))
    numbers = [lab.number for lab in labs]
    if numbers != sorted(set(numbers)):
        raise RegistryError(f"{where}: labs must be declared once each, in order ({numbers})")
    return tuple(labs)


@functools.lru_cache(maxsize=None)
def labs() -> tuple[Lab, ...]:
    """Every lab, in course order. Every entry point needs them (the grader's rubrics are
    made when it starts), so an unreadable or broken registry ends the program here: one
    error line and exit status 2, not a traceback from wherever it was first asked."""
    try:
        return parse(REGISTRY.read_text())
    except (OSError, RegistryError) as e:
        print(f"error: registry: {e}", file=sys.stderr)
        raise SystemExit(2) from None


def lab(number: str) -> Lab:
    """Lab `number` ("01"); RegistryError names the labs there are."""
    for entry in labs():
        if entry.number == number:
            return entry
    raise RegistryError(f"no lab {number!r}: the labs are {', '.join(numbers())}")


def numbers() -> tuple[str, ...]:
    return tuple(entry.number for entry in labs())


def folders() -> dict[str, str]:
    """Lab number -> folder name: {"01": "01-serial", ...}."""
    return {entry.number: entry.folder for entry in labs()}


def gpu_labs() -> tuple[str, ...]:
    return tuple(entry.number for entry in labs() if entry.gpu)


def is_gpu_lab(number: str) -> bool:
    return number in gpu_labs()


def shared_sources() -> dict[str, list[str]]:
    """Lab folder -> the shared files its students write (the skeleton generator's input)."""
    return {entry.folder: list(entry.shared) for entry in labs() if entry.shared}


def owner(target: str) -> Lab:
    """The lab whose make target `target` is ("lab05-ref" -> lab 05)."""
    for entry in labs():
        if target in entry.targets:
            return entry
    raise RegistryError(f"no lab declares the make target {target!r} (labs/labs.toml)")


def all_targets() -> tuple[str, ...]:
    """Every make target of every lab, in course order."""
    return tuple(t for entry in labs() for t in entry.targets)


def make_fragment() -> str:
    """build/labs.mk: what the Makefile knows of the registry."""
    lines = ["# Written by `python3 -m labkit.registry make` from labs/labs.toml: do not edit.",
             f"LABS := {' '.join(numbers())}",
             f"GPU_LABS := {' '.join(gpu_labs())}",
             f"REGISTERED_TARGETS := {' '.join(all_targets())}"]
    for entry in labs():
        n = entry.number
        lines += [f"LAB_FOLDER_{n} := {entry.folder}",
                  f"LAB_KIND_{n} := {entry.kind}",
                  f"LAB_STUDENT_{n} := {' '.join(entry.student)}",
                  f"LAB_REFERENCE_{n} := {' '.join(entry.reference)}",
                  f"LAB_EXTRAS_{n} := {' '.join(entry.extras)}",
                  f"LAB_TARGETS_{n} := {' '.join(entry.targets)}"]
    return "".join(f"{line.rstrip()}\n" for line in lines)


def _targets_of(args: list[str], field: str) -> list[str]:
    chosen = [lab(args[0])] if args else labs()
    return [t for entry in chosen for t in getattr(entry, field)]


QUERIES = {
    "numbers": lambda args: list(numbers()),
    "folders": lambda args: [entry.folder for entry in labs()],
    "gpu-labs": lambda args: list(gpu_labs()),
    "cpu-labs": lambda args: [entry.number for entry in labs() if not entry.gpu],
    "folder": lambda args: [lab(args[0]).folder],
    "kind": lambda args: [lab(args[0]).kind],
    "targets": lambda args: _targets_of(args, "targets"),
    "student": lambda args: _targets_of(args, "student"),
    "references": lambda args: _targets_of(args, "reference"),
    "ships": lambda args: _targets_of(args, "ships"),
    "make": lambda args: [make_fragment().rstrip("\n")],
}
# How many lab numbers each query takes: folder and kind one, the target lists none (every
# lab) or one.
LAB_ARGUMENTS = {"folder": (1,), "kind": (1,), "targets": (0, 1), "student": (0, 1),
                 "references": (0, 1), "ships": (0, 1)}


def main(argv: list[str] | None = None) -> int:
    args = sys.argv[1:] if argv is None else argv
    if not args or args[0] not in QUERIES \
            or len(args) - 1 not in LAB_ARGUMENTS.get(args[0], (0,)):
        print(f"error: registry: usage: python3 -m labkit.registry "
              f"{{{'|'.join(QUERIES)}}} [NN]", file=sys.stderr)
        return 2
    try:
        answer = QUERIES[args[0]](args[1:])
    except RegistryError as e:
        print(f"error: registry: {e}", file=sys.stderr)
        return 2
    sys.stdout.write("".join(f"{line}\n" for line in answer))
    return 0


if __name__ == "__main__":
    sys.exit(main())
