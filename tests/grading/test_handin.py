"""`make handin` and what the grader does with a hand-in (grading/releases/handin.py): the zip holds
exactly the lab's files; the grader finds a nested hand-in, names a missing file, and refuses
an empty one in one line, with a results.json that says the same."""
import json
import subprocess
import sys
import zipfile

import pytest

from grading import students_tree
from grading.releases import handin
from labkit.harness import ROOT


def write_files(folder, lab, skip=()):
    folder.mkdir(parents=True, exist_ok=True)
    for f in handin.handin_files(lab):
        if f not in skip:
            (folder / f).parent.mkdir(parents=True, exist_ok=True)
            (folder / f).write_text((handin.skeleton(lab) / f).read_text())


@pytest.mark.parametrize("lab", sorted(handin.LAB_FOLDERS))
def test_the_zip_holds_exactly_the_lab_files(tmp_path, lab):
    out = tmp_path / "h.zip"
    handin.pack(lab, out)
    with zipfile.ZipFile(out) as z:
        assert sorted(z.namelist()) == sorted(handin.handin_files(lab))
    assert handin.graded_files(lab) and all("/" not in f for f in handin.graded_files(lab))
    assert not list(tmp_path.glob(".*partial*"))


def test_lab02_hands_in_part_a_in_its_folder():
    assert handin.handin_files("02") == ["packet_hits.h", "render.cpp", "render_avx2.cpp",
                                         "part-a/vec3.h"]


@pytest.mark.parametrize("where", ["", "lab01", "a/b/labs/01-serial/skeleton"])
def test_a_nested_hand_in_is_found(tmp_path, where):
    """What `make handin` packs, unzipped as it is or inside a folder, is what the grader
    builds (grading/students_tree.py)."""
    folder = tmp_path / "sub" / where if where else tmp_path / "sub"
    write_files(folder, "01")
    (tmp_path / "sub" / "notes.txt").write_text("hello")
    files, missing = students_tree.collect(tmp_path / "sub", "01-serial")
    assert sorted(files) == handin.graded_files("01") and missing == []


def test_a_missing_file_is_named(tmp_path):
    """A graded file the hand-in lacks is named; the grader then uses the skeleton's stub,
    never common/'s copy (in the grader's repository, the solution)."""
    (tmp_path / "sub" / "inner").mkdir(parents=True)
    (tmp_path / "sub" / "inner" / "render.cpp").write_text("// mine\n")
    files, missing = students_tree.collect(tmp_path / "sub", "01-serial")
    assert files == {"render.cpp": b"// mine\n"} and missing == ["path_steps.h"]


def test_the_grader_refuses_an_empty_hand_in_in_one_line(tmp_path):
    (tmp_path / "sub").mkdir()
    (tmp_path / "sub" / "README.txt").write_text("my lab")
    results = tmp_path / "results.json"
    p = subprocess.run([sys.executable, "-m", "grading.grade", "01", "--trusted", "--sources",
                        str(tmp_path / "sub"), "--results", str(results)], cwd=ROOT,
                       capture_output=True, text=True, timeout=600)
    assert p.returncode != 0, p.stdout + p.stderr
    assert p.stderr.strip().splitlines() == \
        ["error: the hand-in was refused: no file of lab 01 was handed in: "
         "expected path_steps.h, render.cpp"]
    r = json.loads(results.read_text())
    assert r["score"] == 0 and "no file of lab 01 was handed in" in r["output"]


def test_make_handin_refuses_a_bad_lab():
    p = subprocess.run(["make", "-s", "-C", str(ROOT), "handin", "LAB=9"], capture_output=True,
                       text=True)
    assert p.returncode != 0 and "LAB must be one of" in p.stderr


def test_what_is_not_a_source_is_named_once_programs_first(tmp_path):
    """A program (by its mode, or by its first bytes: a zip keeps no mode) and other files are
    named in one line; sources, hidden and build folders are not."""
    folder = tmp_path / "sub"
    write_files(folder, "01")
    (folder / "lab").write_bytes(b"\x7fELF\x02\x01\x01" + bytes(64))  # no executable bit
    (folder / "run.sh").write_text("#!/bin/sh\n")
    (folder / "notes.txt").write_text("hello")
    for skipped in (".git/config", "build/x.o"):
        (folder / skipped).parent.mkdir(parents=True, exist_ok=True)
        (folder / skipped).write_text("x")
    line = students_tree.ignored(folder)
    assert line == ("ignored, graded from its sources: 2 program(s), never run: lab, run.sh; "
                    "1 other file(s), not sources: notes.txt"), line
    clean = tmp_path / "clean"
    write_files(clean, "01")
    assert students_tree.ignored(clean) == ""


@pytest.mark.parametrize("name", ["a;b.cpp", "a b.cpp", "$(x).h", "a\x1b[2J.cpp", "ü.cpp"])
def test_a_source_name_outside_the_plain_set_is_refused_naming_it(tmp_path, name):
    folder = tmp_path / "sub"
    write_files(folder, "01")
    (folder / name).write_text("int x;\n")
    with pytest.raises(students_tree.HandInError) as e:
        students_tree.collect(folder, "01-serial")
    assert "may hold only letters, digits and _ . + -" in str(e.value)
    assert "\x1b" not in str(e.value) and "\n" not in str(e.value)
