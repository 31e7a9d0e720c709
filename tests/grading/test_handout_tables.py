"""Handouts say what the grader does: each grading table is the one
grading/releases/handout_tables.py makes of the rubric, and a table edited away from it, or a
rubric changed without regenerating the tables, fails here. Every handout ends with its hand-in
section."""
import dataclasses
import re
import shutil

import pytest

from grading import grade
from grading.releases import handin, handout_tables


def test_every_handout_holds_its_generated_table():
    assert handout_tables.differing() == [], \
        "regenerate with python3 -m grading.releases.handout_tables"


def copy_handouts(tmp_path, monkeypatch):
    shutil.copytree(handout_tables.HANDOUTS, tmp_path / "handouts")
    monkeypatch.setattr(handout_tables, "HANDOUTS", tmp_path / "handouts")
    monkeypatch.setattr(handout_tables, "ROOT", tmp_path)
    return tmp_path / "handouts"


@pytest.mark.parametrize("edit", ["points", "threshold", "gate"])
def test_a_table_edited_away_from_the_rubric_fails(tmp_path, monkeypatch, edit):
    handouts = copy_handouts(tmp_path, monkeypatch)
    path = next(handouts.glob("03-*.md"))
    text = path.read_text()
    table = handout_tables.current(text)
    changed = {
        "points": lambda t: t.replace("| parallel speedup | 30 |", "| parallel speedup | 45 |"),
        "threshold": lambda t: t.replace("0.75 x the capacity", "0.5 x the capacity"),
        "gate": lambda t: t.replace("| 30 | parallel speedup passes |", "| 30 | always |"),
    }[edit](table)
    assert changed != table
    path.write_text(text.replace(table, changed))
    assert handout_tables.differing() == ["handouts/03-openmp.md"]
    assert handout_tables.main(["--check"]) == 1
    handout_tables.rewrite()
    assert handout_tables.differing() == []


def test_a_rubric_changed_without_the_tables_fails(monkeypatch):
    rubric = [dataclasses.replace(i, points=i.points + 5) if i.id == "reproducible" else i
              for i in grade.RUBRICS["01"]]
    monkeypatch.setitem(grade.RUBRICS, "01", rubric)
    assert handout_tables.differing() == ["handouts/01-serial.md"]


def test_tables_total_the_rubric_and_name_every_check():
    for lab, rubric in grade.RUBRICS.items():
        table = handout_tables.table(lab)
        assert f"| **total** | **{sum(i.points for i in rubric)}** |" in table
        rows = [line for line in table.splitlines() if line.startswith("| ")][1:-1]
        assert [r.split(" | ")[0][2:] for r in rows] == [i.label for i in rubric]


@pytest.mark.parametrize("lab", sorted(handin.LAB_FOLDERS))
def test_every_handout_ends_with_its_hand_in(lab):
    text = next(handout_tables.HANDOUTS.glob(f"{lab}-*.md")).read_text()
    sections = re.findall(r"^## (.+)$", text, re.M)
    assert sections[-1] == "Hand in", sections[-3:]
    last = text[text.rindex("## Hand in"):]
    assert "make handin" in last and f"handin-lab{lab}.zip" in last
    for f in handin.handin_files(lab):
        assert f"`{f}`" in last, f
