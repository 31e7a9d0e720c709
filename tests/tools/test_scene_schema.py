"""A kind's scene-file form is declared once, in C++: every lab binary prints it with
`--scene-schema` (common/host/scene_schema.h), labkit/scenes.py moves and scales scenes by it,
and DESIGN.md section 5's table is generated from it (labkit/scene_schema.py). A table edited
away from the schema, or a kind added without regenerating it, fails here."""
import json
import shutil
import subprocess

import numpy as np
import pytest

from labkit import harness, scene_schema, scenes


@pytest.fixture(scope="module", autouse=True)
def binary():
    """lab01-ref as the sources are now, and its schema read afresh."""
    built = harness.build(scene_schema.BINARY)[0]
    scene_schema.schema.cache_clear()
    return built


def test_design_holds_the_generated_table():
    assert not scene_schema.stale(), "regenerate with python3 -m labkit.scene_schema --write"
    assert scene_schema.main(["--check"]) == 0


def test_the_flag_prints_one_json_line_and_renders_nothing(binary, tmp_path):
    out = tmp_path / "never.pfm"
    p = subprocess.run([str(binary), "--scene-schema", "--pfm", str(out), "--width", "0"],
                       capture_output=True, text=True, timeout=60)
    assert p.returncode == 0 and p.stderr == "", p.stderr
    assert len(p.stdout.splitlines()) == 1
    assert json.loads(p.stdout) == scene_schema.schema()
    assert not out.exists()
    # A bad flag before it is the usual one-line error, as before --help.
    p = subprocess.run([str(binary), "--width", "0", "--scene-schema"], capture_output=True,
                       text=True, timeout=60)
    assert p.returncode == 2 and p.stdout == ""
    assert p.stderr.startswith("error: --width") and p.stderr.count("\n") == 1, p.stderr
    usage = subprocess.run([str(binary), "--help"], capture_output=True, text=True).stdout
    assert "--scene-schema" in usage


def test_the_schema_gives_each_field_a_role_scenes_knows():
    fields = scene_schema.primitive_fields()
    assert fields["spheres"] == {"center": "point", "radius": "length"}
    assert fields["triangles"] == fields["quads"] == {"vertices": "points"}
    assert {role for f in fields.values() for role in f.values()} <= {
        "point", "points", "length", "direction"}
    types = [m["type"] for m in scene_schema.schema()["materials"]]
    assert types[:3] == ["diffuse", "mirror", "glass"]


# A disk as tests/tools/new_kind/disk.diff declares one: added to the schema, it makes the
# table stale, gets a row, and scenes.py moves its centre, turns its normal, scales its radius.
DISK = {"key": "disks", "fields": [{"key": "center", "role": "point"},
                                   {"key": "normal", "role": "direction"},
                                   {"key": "radius", "role": "length"}]}


@pytest.fixture
def with_disk(monkeypatch):
    value = json.loads(json.dumps(scene_schema.schema()))
    value["primitives"].insert(1, DISK)
    monkeypatch.setattr(scene_schema, "schema", lambda: value)
    return value


def test_a_kind_added_without_the_table_fails(with_disk):
    assert scene_schema.stale()
    assert ("| `disks` | `center`: a point [x, y, z]; `normal`: a direction [x, y, z], not "
            "zero, normalised when read; `radius`: a length > 0; `material`: a name from "
            "`materials` |") in scene_schema.table()


def test_scenes_move_a_kind_by_its_fields_roles(with_disk):
    scene = {"camera": {"position": [0, 0, 5], "look_at": [0, 0, 0], "up": [0, 1, 0]},
             "disks": [{"center": [1, 0, 0], "normal": [0, 1, 0], "radius": 0.5,
                        "material": "m"}]}
    quarter = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])  # z by 90 degrees
    disk = scenes.transformed(scene, quarter, offset=(0, 0, 1), scale=2.0)["disks"][0]
    assert np.allclose(disk["center"], [0, 2, 1])
    assert np.allclose(disk["normal"], [-1, 0, 0])
    assert disk["radius"] == 1.0
    assert scenes.translated(scene, (1, 2, 3))["disks"][0]["normal"] == [0, 1, 0]


@pytest.mark.parametrize("edit", ["row", "range"])
def test_a_table_edited_away_from_the_schema_fails(tmp_path, monkeypatch, edit):
    design = tmp_path / "DESIGN.md"
    shutil.copy2(scene_schema.DESIGN, design)
    monkeypatch.setattr(scene_schema, "DESIGN", design)
    text = design.read_text()
    table = scene_schema.current(text)
    changed = {"row": lambda t: t.replace("| `spheres` |", "| `balls` |"),
               "range": lambda t: t.replace("in [1, 5]", "in [1, 4]")}[edit](table)
    assert changed != table
    design.write_text(text.replace(table, changed))
    assert scene_schema.stale()
    assert scene_schema.main(["--check"]) == 1
    assert scene_schema.main(["--write"]) == 0
    assert not scene_schema.stale()
    assert design.read_text() == text


def test_no_binary_is_a_clear_error(monkeypatch):
    """A binary that is missing is built first; where make fails, the error says so."""
    def fails(*targets):
        raise subprocess.CalledProcessError(2, ["make", *targets])
    monkeypatch.setattr(harness, "build", fails)
    monkeypatch.setattr(scene_schema, "BINARY", "lab01-ref-missing")
    scene_schema.schema.cache_clear()
    try:
        with pytest.raises(scene_schema.SchemaError, match="make lab01-ref-missing` failed"):
            scene_schema.schema()
        assert scene_schema.main(["--check"]) == 2
    finally:
        monkeypatch.undo()
        scene_schema.schema.cache_clear()


def test_a_binary_built_before_the_flag_is_rebuilt_first(tmp_path, monkeypatch):
    stale = tmp_path / scene_schema.BINARY
    stale.write_text("#!/bin/sh\necho 'error: --scene-schema: unknown option' >&2; exit 2\n")
    stale.chmod(0o755)
    fresh = json.dumps(scene_schema.schema())

    def rebuild(*targets):
        stale.write_text(f"#!/bin/sh\necho '{fresh}'\n")
        return [tmp_path / t for t in targets]
    monkeypatch.setattr(scene_schema, "ROOT", tmp_path)
    monkeypatch.setattr(harness, "build", rebuild)
    scene_schema.schema.cache_clear()
    try:
        assert scene_schema.schema() == json.loads(fresh)
    finally:
        monkeypatch.undo()
        scene_schema.schema.cache_clear()
