"""`make handin` and what the grader does with a hand-in (grading/handin.py): the zip holds
exactly the lab's files; a nested hand-in is found; an incomplete or doubled one is refused
in one line naming the files, with a results.json that says the same."""
import json
import subprocess
import sys
import zipfile

import pytest

from grading import handin
from grading.harness import ROOT


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
    assert handin.handin_files("02") == ["packet_tracer.h", "render.cpp", "render_avx2.cpp",
                                         "part-a/vec3.h"]


@pytest.mark.parametrize("where", ["", "lab01", "a/b/labs/01-serial/skeleton"])
def test_a_nested_hand_in_is_found(tmp_path, where):
    folder = tmp_path / "sub" / where if where else tmp_path / "sub"
    write_files(folder, "01")
    (tmp_path / "sub" / "notes.txt").write_text("hello")
    assert handin.locate("01", tmp_path / "sub") == (folder, [])


def test_a_missing_file_is_the_skeleton_s_and_named(tmp_path):
    """Never common/'s copy of a shared file: in the grader's repository that is the
    solution, which a hand-in of render.cpp alone would otherwise be graded with."""
    (tmp_path / "sub" / "inner").mkdir(parents=True)
    (tmp_path / "sub" / "inner" / "render.cpp").write_text("// mine\n")
    folder, note = handin.prepare("01", tmp_path / "sub", tmp_path / "work")
    assert folder == tmp_path / "work"
    assert (folder / "render.cpp").read_text() == "// mine\n"
    assert (folder / "path_tracer.h").read_bytes() == \
        (handin.skeleton("01") / "path_tracer.h").read_bytes()
    assert note.startswith("the hand-in lacks path_tracer.h: graded with the skeleton's")


def test_a_hand_in_without_any_file_is_refused_naming_them(tmp_path):
    (tmp_path / "sub" / "x").mkdir(parents=True)
    (tmp_path / "sub" / "x" / "main.cpp").write_text("")
    with pytest.raises(handin.HandinError, match=r"holds none of lab 01's files "
                                                 r"\(path_tracer.h, render.cpp;"):
        handin.prepare("01", tmp_path / "sub", tmp_path / "work")


def test_two_copies_are_refused(tmp_path):
    write_files(tmp_path / "sub" / "one", "03")
    write_files(tmp_path / "sub" / "two", "03")
    with pytest.raises(handin.HandinError, match="more than one folder"):
        handin.locate("03", tmp_path / "sub")


def test_the_grader_refuses_an_empty_hand_in_in_one_line(tmp_path):
    (tmp_path / "sub").mkdir()
    (tmp_path / "sub" / "README.txt").write_text("my lab")
    results = tmp_path / "results.json"
    p = subprocess.run([sys.executable, "-m", "grading.grade", "01", "--trusted", "--sources",
                        str(tmp_path / "sub"), "--results", str(results)], cwd=ROOT,
                       capture_output=True, text=True, timeout=600)
    assert p.returncode == 2, p.stdout + p.stderr
    assert p.stderr.strip().splitlines() == \
        ["error: the hand-in holds none of lab 01's files (path_tracer.h, render.cpp; "
         "make handin packs them)"]
    r = json.loads(results.read_text())
    assert r["score"] == 0 and "holds none of lab 01's files" in r["output"]


def test_make_handin_refuses_a_bad_lab():
    p = subprocess.run(["make", "-s", "-C", str(ROOT), "handin", "LAB=9"], capture_output=True,
                       text=True)
    assert p.returncode != 0 and "LAB must be one of" in p.stderr
