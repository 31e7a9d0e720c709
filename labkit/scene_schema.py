"""The scene file's primitive lists and material types as the renderer declares them, read
from a lab binary's `--scene-schema` (common/host/scene_schema.h), and DESIGN.md section 5's
table of them. A kind declares its file form once, in C++ (core/file_fields.h, material.h):
scenes.py moves, rotates and scales every field by its role, and the table says what the
loader reads, without a second list of either to keep in step.

    python3 -m labkit.scene_schema           print the table
    python3 -m labkit.scene_schema --write   rewrite DESIGN.md's table
    python3 -m labkit.scene_schema --check   exit 1 when DESIGN.md's table is not the schema's

DESIGN.md holds the table between the marker lines BEGIN and END below; everything between
them is generated. tests/tools/test_scene_schema.py fails when it is stale.
"""
from __future__ import annotations

import argparse
import functools
import json
import subprocess
import sys

from labkit import harness
from labkit.harness import ROOT

# The binary whose schema is read: built in the course repository and in every student
# release (from the shipped solution, or prebuilt: grading/releases/reference_bins.py). Every lab
# binary prints the same schema, the kinds being common/core's; a reference is trusted, so
# it runs outside the sandbox.
BINARY = "lab01-ref"
DESIGN = ROOT / "DESIGN.md"
BEGIN = ("<!-- scene-file lists and types: generated from the renderer's --scene-schema by "
         "`python3 -m labkit.scene_schema --write`; declare a kind in common/core/, "
         "not here -->")
END = "<!-- end of the generated scene-file lists and types -->"


class SchemaError(RuntimeError):
    """No schema could be read: the binary did not build or did not print one."""


def build() -> None:
    """`make lab01-ref` (once per process): the binary up to date with the kinds."""
    try:
        harness.build(BINARY)
    except (subprocess.CalledProcessError, OSError) as e:
        raise SchemaError(f"the scene file's schema comes from `./{BINARY} --scene-schema`, "
                          f"and `make {BINARY}` failed ({e}); build it and try again") from None


def read(binary) -> dict:
    """What `binary --scene-schema` prints."""
    try:
        out = subprocess.run([str(binary), "--scene-schema"], capture_output=True, text=True,
                             timeout=60)
    except (OSError, subprocess.TimeoutExpired) as e:
        raise SchemaError(f"cannot run ./{BINARY} --scene-schema: {e}") from None
    try:
        value = json.loads(out.stdout) if out.returncode == 0 else None
    except ValueError:
        value = None
    if not isinstance(value, dict) or "primitives" not in value:
        said = (out.stderr or out.stdout).strip()[-500:]
        raise SchemaError(f"`./{BINARY} --scene-schema` exited {out.returncode} without a "
                          f"schema" + (f": {said}" if said else ""))
    return value


@functools.lru_cache(maxsize=None)
def schema() -> dict:
    """The schema `./lab01-ref --scene-schema` prints, read once per process. The binary is
    read as built, as the grader runs its references (a grade with --no-build runs no make:
    grading/references.py); `make lab01-ref`, which the tests' fixtures and --write and
    --check here run, brings it up to date with the kinds. One that is missing (a fresh
    release) or prints no schema (built before the flag) is built first."""
    binary = ROOT / BINARY
    if binary.is_file():
        try:
            return read(binary)
        except SchemaError:
            pass
    build()
    return read(binary)


def primitive_fields() -> dict[str, dict[str, str]]:
    """Each primitive list's key -> its fields' roles: {"spheres": {"center": "point",
    "radius": "length"}, "triangles": {"vertices": "points"}, ...}."""
    return {p["key"]: {f["key"]: f["role"] for f in p["fields"]}
            for p in schema()["primitives"]}


# What each role asks of a value, in the table's words (the loader's checks).
ROLES = {
    "point": "a point [x, y, z]",
    "length": "a length > 0",
    "direction": "a direction [x, y, z], not zero, normalised when read",
    "albedo": "RGB, each in [0, 1]",
}


def field_text(field: dict) -> str:
    role = field["role"]
    if role == "points":
        return f"`{field['key']}`: {field['count']} points"
    if role == "number":
        return f"`{field['key']}`: {field['what']} in [{field['min']:g}, {field['max']:g}]"
    return f"`{field['key']}`: {ROLES[role]}"


def table(value: dict | None = None) -> str:
    """The markdown DESIGN.md holds between BEGIN and END, markers included."""
    value = value if value is not None else schema()
    lines = [BEGIN, "", "| primitive list | an entry's keys, all required |", "|---|---|"]
    for p in value["primitives"]:
        keys = [field_text(f) for f in p["fields"]] + ["`material`: a name from `materials`"]
        lines.append(f"| `{p['key']}` | {'; '.join(keys)} |")
    lines += ["", "| material `type` | its keys beside `type`, all required |", "|---|---|"]
    for m in value["materials"]:
        keys = [field_text(f) for f in m["fields"]] or ["none"]
        lines.append(f"| `{m['type']}` | {'; '.join(keys)} |")
    return "\n".join(lines + ["", END])


def current(text: str) -> str | None:
    """The table a text holds now, markers included, or None."""
    start = text.find(BEGIN)
    end = text.find(END, start)
    return text[start:end + len(END)] if start >= 0 and end >= 0 else None


def stale() -> bool:
    """Whether DESIGN.md's table is not the one the schema makes (or is missing)."""
    return current(DESIGN.read_text()) != table()


def rewrite() -> bool:
    """Replace DESIGN.md's table with the generated one; whether it changed. Without the
    markers it is left alone (and --check fails)."""
    text = DESIGN.read_text()
    old = current(text)
    if old is None or old == table():
        return False
    DESIGN.write_text(text.replace(old, table()))
    return True


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    group = p.add_mutually_exclusive_group()
    group.add_argument("--write", action="store_true", help="rewrite DESIGN.md's table")
    group.add_argument("--check", action="store_true",
                       help="exit 1 when DESIGN.md's table is not the schema's")
    a = p.parse_args(argv)
    try:
        build()  # the table of the kinds as the sources declare them now
        schema.cache_clear()
        if a.check:
            if stale():
                print("DESIGN.md's table of scene-file lists and types is out of date "
                      "(python3 -m labkit.scene_schema --write)", file=sys.stderr)
                return 1
        elif a.write:
            if current(DESIGN.read_text()) is None:
                print(f"{DESIGN.name} has no table markers ({BEGIN})", file=sys.stderr)
                return 1
            if rewrite():
                print(f"rewrote the scene-file table of {DESIGN.name}")
        else:
            print(table())
    except SchemaError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
