"""The handouts, the README and the GPU labs' timed renders quote the GPU records (one per
card, reference/gpu/<card>/) as they are: every generated table is what tools/gpu/figures.py
makes of the record its marker names, every phrase of PROSE stands in its file as its
record renders it, no "N.NN ms" is a number no record holds, and labs.toml's timed_spp is
what the record gives for the grader's timed render. A figure edited away from its record,
or a record changed without the text, fails here. Reads files only: well under a second."""
import dataclasses
import re
import shutil

import pytest

from grading import grade
from labkit import registry
from tools.gpu import figures
from tools.gpu import record as rec


def test_every_figure_is_the_records():
    assert figures.problems() == [], "regenerate with python3 -m tools.gpu.figures"


@pytest.fixture
def copy(tmp_path):
    """The files that quote the record, copied, for problems(root=...)."""
    for name in figures.FILES:
        (tmp_path / name).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy(figures.ROOT / name, tmp_path / name)
    return tmp_path


def edit(path, old, new):
    text = path.read_text()
    assert old in text, old
    path.write_text(text.replace(old, new, 1))


def nudge(path, pattern):
    """Changes the figure that `pattern`'s group 1 finds first in `path` (whatever the record
    now gives) to another figure of the same form."""
    text = path.read_text()
    m = re.search(pattern, text)
    assert m, pattern
    figure = m[1]
    decimals = len(figure.partition(".")[2])
    other = f"{float(figure) + 0.09:.{decimals}f}" if decimals else str(int(figure) + 9)
    path.write_text(text[:m.start(1)] + other + text[m.end(1):])


@pytest.mark.parametrize("where, pattern", [
    # a cell of a generated table
    ("handouts/06-cuda-split.md", r"\| generate_camera_paths \| (\d+\.\d+) \|"),
    # a figure in the prose, checked phrase by phrase
    ("handouts/05-cuda-mega.md", r"takes \*\*(\d+\.\d+) ms\*\* for the baseline"),
    ("README.md", r"ready; (\d+\.\d) ms for the baseline"),
    ("handouts/07-soa.md", r"is met\*\*: [\d.]+ against [\d.]+ ms, (\d\.\d+)×"),
])
def test_a_figure_edited_away_from_the_record_fails(copy, where, pattern):
    nudge(copy / where, pattern)
    found = figures.problems(root=copy)
    assert found and all(line.startswith(f"{where}:") for line in found), found


@pytest.mark.parametrize("where, old, new", [
    # a figure no phrase names: an earlier record's time left in the text
    ("handouts/06-cuda-split.md", "its margin grows with depth",
     "its margin (39.91 ms on the baseline) grows with depth"),
    # or a hand-written table of times holding one
    ("handouts/07-soa.md", "Reading the table:",
     "| layout | kernel ms |\n|---|---:|\n| AoS | 74.05 |\n\nReading the table:"),
])
def test_a_figure_the_record_does_not_hold_fails(copy, where, old, new):
    edit(copy / where, old, new)
    found = figures.problems(root=copy)
    assert found and all(line.startswith(f"{where}:") for line in found), found


def test_a_record_changed_without_the_text_fails(copy, tmp_path_factory):
    record = tmp_path_factory.mktemp("record")
    for f in rec.RECORD.iterdir():
        shutil.copy(f, record / f.name)
    bench = record / "bench-lab05.json"
    best = rec.read()["lab05"]["reference"]["best_ms"]
    faster = round(best - 1.0, 3)
    text = bench.read_text()
    assert f'"best_ms": {best}' in text
    bench.write_text(text.replace(f'"best_ms": {best}', f'"best_ms": {faster}', 1))
    records = {card: rec.record_of(card) for card in rec.CARDS} | {rec.CURRENT: record}
    found = figures.problems(root=copy, records=records)
    assert any("table 'lab05-targets'" in line for line in found), found
    assert any(f"the reference {faster:.2f} ms" in line for line in found), found


def test_every_table_names_a_card_with_a_record():
    """Each generated table's marker names the record it comes from, one of the cards'."""
    cards = {card for name in figures.FILES
             for _, _, card in figures.generated((figures.ROOT / name).read_text()).values()}
    assert cards and cards <= set(rec.CARDS), cards
    assert all((rec.record_of(card) / "bench-lab05.json").exists() for card in cards)


def test_a_table_of_another_cards_record_fails(copy):
    """A table whose marker names the other card's record is not that record's table."""
    path = copy / "handouts/05-cuda-mega.md"
    text = path.read_text()
    other = next(card for card in rec.CARDS if card != rec.CURRENT)
    path.write_text(text.replace(f"'lab05-targets': generated from reference/gpu/{rec.CURRENT}/",
                                 f"'lab05-targets': generated from reference/gpu/{other}/", 1))
    found = figures.problems(root=copy)
    assert any(f"table 'lab05-targets' is not the record's ({other})" in line
               for line in found), found


def test_cards_are_told_by_name():
    assert rec.card_of("NVIDIA H100 80GB HBM3") == "h100"
    assert rec.card_of("NVIDIA H200") == "h200"
    assert rec.card_of("NVIDIA A100-SXM4-80GB") is None


def test_the_timed_renders_are_sized_from_the_record():
    """Each GPU lab's timed render takes the grader's GPU_TIMED_SECONDS of its reference's
    kernel time at the record's throughput, to within the spp's rounding."""
    side = figures.grade_view_side() * grade.GPU_TIMED_SCALE
    for lab in registry.labs():
        if not lab.gpu:
            continue
        r = figures.read_card(rec.TIMED_SPP_CARD[lab.number])
        assert lab.timed_spp == figures.derived_spp(r, lab.number), lab.number
        seconds = rec.timed_seconds(r, lab.number, side * side, lab.timed_spp)
        step = rec.timed_seconds(r, lab.number, side * side, rec.SPP_STEP)
        assert abs(seconds - grade.GPU_TIMED_SECONDS) <= step / 2, (lab.number, seconds)


def test_a_timed_spp_the_record_does_not_give_fails(monkeypatch):
    labs = tuple(dataclasses.replace(lab, timed_spp=4096) if lab.number == "05" else lab
                 for lab in registry.labs())
    monkeypatch.setattr(registry, "labs", lambda: labs)
    found = [line for line in figures.problems() if line.startswith("labs/labs.toml")]
    assert found and re.search(r"lab 05's timed_spp is 4096; the record \(h100\) gives \d+",
                               found[0])


@pytest.mark.parametrize("card", list(rec.CARDS))
def test_the_ncu_rows_name_the_shapes_the_handout_quotes(card):
    """The handout's counters are of the kinds kernel: "kinds-kernel" in a record made since the
    small-scene kernel, "reference" in one made before it (figures.kinds_shape)."""
    r = figures.read_card(card)
    kinds, shapes = figures.kinds_shape(r), r["ncu"]
    assert {kinds, "plain", "showcase", f"{kinds}, 1 bounce"} <= set(shapes)
    assert 1 <= shapes[kinds]["active"] <= 32


def absolute_paths(value) -> list[str]:
    """Every string in a JSON value that names a path from the root of a file system."""
    if isinstance(value, dict):
        return [p for v in value.values() for p in absolute_paths(v)]
    if isinstance(value, list):
        return [p for v in value for p in absolute_paths(v)]
    return [value] if isinstance(value, str) and value.startswith("/") else []


def test_the_record_names_no_machines_paths():
    """A record is read on other machines: it names a scene as the repository does."""
    import json
    found = {str(path): absolute_paths(json.loads(path.read_text()))
             for path in sorted(rec.RECORDS.glob("*/*.json"))}
    assert found and all(paths == [] for paths in found.values()), found
    assert absolute_paths({"scene": ["/work/scene.json"]}) == ["/work/scene.json"]


BEFORE_SMALL = "h200"  # a card whose record was made before the small-scene kernel


def record_with_small_reference(folder):
    """The H200 record (made before the small-scene kernel) as a record made since would be:
    its kinds kernel renamed `kinds-kernel`, a made-up `reference` (the small-scene kernel) a
    quarter faster, and a profile of that kernel beside the kinds kernel's."""
    import json
    for f in rec.record_of(BEFORE_SMALL).iterdir():
        shutil.copy(f, folder / f.name)
    for name, factor in (("bench-lab05.json", 0.75), ("bench-lab05-fast-math.json", 0.8)):
        bench = json.loads((folder / name).read_text())
        kinds = next(v for v in bench["variants"] if v["name"] == "reference")
        kinds["name"] = "kinds-kernel"
        small = dict(kinds, name="reference", max_registers=56, registers=56, local_bytes=116,
                     best_ms=round(kinds["best_ms"] * factor, 3))
        bench["variants"].insert(0, small)
        (folder / name).write_text(json.dumps(bench))
    check = json.loads((folder / "gpu-check.json").read_text())
    for r in check["ncu"]:  # the H200's kernel had no rect-test argument: spell it as now
        r["Kernel Name"] = r["Kernel Name"].replace("Kinds<Sphere, AxisRect>>",
                                                    "Kinds<Sphere, AxisRect>, 1>")
    row = next(r for r in check["ncu"] if r["run"] == "cornell"
               and "Kinds<Sphere, AxisRect>, 1>" in r["Kernel Name"])
    check["ncu"].append(dict(row, **{
        "Kernel Name": "void small_scene_kernel<1, 5, 32, 64, 56, true, false>(KernelArgs)",
        "smsp__thread_inst_executed_per_inst_executed.ratio": "27.5"}))
    (folder / "gpu-check.json").write_text(json.dumps(check))
    return rec.read(folder)


def test_a_record_with_the_small_scene_reference_compares_shapes_with_the_kinds_kernel(tmp_path):
    """Where the record has both kernels, the tables of the shapes that change the kinds kernel
    compare them with `kinds-kernel`, not with the small-scene `reference`; the small-scene
    table shows the gain; the prose's counters are the kinds kernel's."""
    old = rec.read(rec.record_of(BEFORE_SMALL))
    r = record_with_small_reference(tmp_path)
    kinds, small = r["lab05"]["kinds-kernel"]["best_ms"], r["lab05"]["reference"]["best_ms"]
    assert kinds == old["lab05"]["reference"]["best_ms"] and small < kinds
    assert r["ncu"]["reference"]["active"] == 27.5
    assert r["ncu"]["kinds-kernel"] == old["ncu"]["reference"]
    assert r["ncu"]["kinds-kernel, 1 bounce"] == old["ncu"]["reference, 1 bounce"]
    for table in ("lab05-split", "lab05-scene-memory", "lab05-blocks", "lab05-registers",
                  "lab05-materials", "lab05-geometry", "lab05-path-loops"):
        text = figures.TABLES[table](r)
        assert f"| {figures.ms(kinds)} |" in text, (table, text)
        assert f"| {figures.ms(small)} |" not in text, (table, text)
    for table in ("lab05-scene-memory", "lab05-registers", "lab05-materials", "lab05-path-loops"):
        text = figures.TABLES[table](r)
        assert "`kinds-kernel`" in text and "`reference`" not in text, (table, text)
    divergence = figures.TABLES["lab05-divergence"](r)
    active = f'{old["ncu"]["reference"]["active"]:.1f}'
    assert f"| `kinds-kernel` | Cornell, 4 | {active} |" in divergence, divergence
    assert "| `reference` (the small-scene kernel) | Cornell, 4 | 27.5 |" in divergence
    gain = figures.TABLES["lab05-small-scene"](r)
    assert f"| {figures.ms(small)} | -25% |" in gain, gain
    assert f"| {figures.ms(kinds)} | — |" in gain, gain
    said = figures.figures(r)
    assert said["kinds"] == figures.ms(kinds) and said["ref"] == figures.ms(small)
    assert said["active"] == active
    targets = figures.TABLES["lab05-targets"](r)
    assert f"| `reference` (the small-scene kernel) | {figures.ms(small)} |" in targets
    assert f"| `kinds-kernel` (the kernel you write) | {figures.ms(kinds)} |" in targets


def test_a_record_before_the_small_scene_kernel_keeps_reference_as_the_kinds_kernel():
    r = figures.read_card(BEFORE_SMALL)
    assert "kinds-kernel" not in r["lab05"] and figures.kinds_shape(r) == "reference"
    assert "kinds-kernel" not in r["ncu"] and "reference, 1 bounce" in r["ncu"]
    assert "made before" in figures.TABLES["lab05-small-scene"](r)
