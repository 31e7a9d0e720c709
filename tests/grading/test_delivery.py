"""Grading a class (grading/classes/batch.py) and the Gradescope bundle
(grading/releases/gradescope.py), run in a scratch /autograder layout."""
import csv
import json
import os
import pathlib
import shutil
import subprocess
import sys
import tempfile
import time
import zipfile

import pytest

from labkit import sandbox
from labkit.harness import ROOT
from tests.grading import submissions as sub


@pytest.fixture(autouse=True)
def needs_sandbox():
    reason = sandbox.probe()
    if reason:
        pytest.fail(f"the grader's sandbox is not available here: {reason}")


def test_batch_grades_each_student_into_csv_and_html(tmp_path):
    subs = tmp_path / "submissions"
    for student in ("alice", "bob", "carol"):
        (subs / student).mkdir(parents=True)
    for name in ("render.cpp", "path_steps.h"):               # correct sources
        shutil.copy2(ROOT / "labs/01-serial/solution" / name if name == "render.cpp"
                     else ROOT / "common/core" / name, subs / "alice" / name)
    sub.exec_reference(subs / "bob")          # a program only: never run, nothing to build
    (subs / "carol" / "render.cpp").write_text("int broken( {\n")  # does not compile
    report = tmp_path / "report"
    p = subprocess.run([sys.executable, "-m", "grading.classes.batch", "01", str(subs), "--out",
                        str(report)], cwd=ROOT, capture_output=True, text=True, timeout=600)
    assert p.returncode == 0, p.stdout + p.stderr
    rows = {r["student"]: r for r in csv.DictReader((report / "grades.csv").open())}
    assert rows.pop("(class: 3 students)")["flagged"] == "0 flagged"
    assert rows["carol"]["cause"].startswith("compile error:"), rows["carol"]
    assert {s: int(r["score"]) for s, r in rows.items()} == {"alice": 100, "bob": 0, "carol": 0}
    carol = json.loads((report / "carol" / "results.json").read_text())
    assert "does not compile" in carol["output"]
    page = (report / "report.html").read_text()
    assert all(s in page for s in rows) and page.count("<tr>") == 4


def test_gradescope_bundle_grades_a_submission(tmp_path, request):
    """The zip, unpacked where Gradescope unpacks it, grades lab 01's solution handed in as a
    student's render.cpp and path_steps.h: 100 points in /autograder/results/results.json.
    The render.cpp alone is built against the skeleton's path_steps.h (the students' tree),
    as a student's own would be, and scores what the skeleton scores."""
    from grading.releases.gradescope import bundle
    # Gradescope's /autograder is open to all; pytest's tmp_path is not (0700 above it), and
    # the sandboxed build runs as an unprivileged user that must read the unpacked tree.
    scratch = pathlib.Path(tempfile.mkdtemp(prefix="autograder-test-"))
    scratch.chmod(0o755)
    request.addfinalizer(lambda: shutil.rmtree(scratch, ignore_errors=True))
    root = scratch / "autograder"
    zip_path = bundle("01", tmp_path / "lab01.zip")
    with zipfile.ZipFile(zip_path) as z:
        z.extractall(root / "source")
        for info in z.infolist():  # as unzip does (extractall does not): files keep their times
            stamp = time.mktime(info.date_time + (0, 0, -1))
            os.utime(root / "source" / info.filename, (stamp, stamp))
        mode = z.getinfo("run_autograder").external_attr >> 16
    assert mode & 0o111, "run_autograder must be executable"
    assert "grading/grade.py" in zipfile.ZipFile(zip_path).namelist()
    # setup.sh would install packages and build the references; here they are already built,
    # so copy them (with their times, so make sees them up to date) instead of building.
    for built in ("lab01-ref", "build"):
        src, dst = ROOT / built, root / "source" / built
        shutil.copytree(src, dst) if src.is_dir() else shutil.copy2(src, dst)
    (root / "submission").mkdir()
    shutil.copy(ROOT / "labs" / "01-serial" / "solution" / "render.cpp", root / "submission")

    def run_autograder() -> dict:
        p = subprocess.run(["bash", str(root / "source" / "run_autograder")],
                           capture_output=True, text=True, timeout=900,
                           env={**os.environ, "AUTOGRADER_ROOT": str(root)})
        assert p.returncode == 0, p.stdout + p.stderr
        return json.loads((root / "results" / "results.json").read_text())

    alone = run_autograder()
    assert alone["score"] <= 10, json.dumps(alone, indent=1)[:3000]
    assert "not handed in, the skeleton's copy used: path_steps.h" in alone["output"]
    shutil.copy(ROOT / "common" / "core" / "path_steps.h", root / "submission")
    results = run_autograder()
    assert results["score"] == 100, json.dumps(results, indent=1)[:3000]


def test_gradescope_bundle_says_its_settings(tmp_path, capsys):
    """`make gradescope` prints, and the zip's own README.md carries at its top, what to choose
    on Gradescope: labs 03 and 04 need 2 CPUs, and the default's consequence is said."""
    from grading.releases import gradescope
    assert gradescope.main(["03", "--out", str(tmp_path / "lab03.zip")]) == 0
    printed = capsys.readouterr().out
    with zipfile.ZipFile(tmp_path / "lab03.zip") as z:
        readme = z.read("README.md").decode()
        assert "COURSE-README.md" in z.namelist()
    for text in (printed, readme):
        assert "Base image:" in text and "Memory:" in text and "timeout:" in text
        assert "Autograder CPUs:     2.0 or more" in text, text
        assert "default of 0.5" in text and "regrade" in text, text
    lab01 = gradescope.settings("01")
    assert "0.5 (the default)" in lab01
