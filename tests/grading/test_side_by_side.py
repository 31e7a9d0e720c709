"""Graders side by side in one checkout: a reference is never rewritten under a grade that runs
it, and a reference that cannot run is a refusal marked for regrade, never a score."""
import json
import os
import subprocess
import sys
import time

from grading import grade as grader
from grading import references
from grading.checks.check_result import CheckResult
from grading.results import Results, Test
from labkit.harness import ROOT, RunPolicy, build, policy, run_lab
from labkit.sandbox import Limits


def relinking(seconds: float):
    """Another process running `make lab01-ref` again and again, each time after making one of
    its objects newer (as an edit would), for `seconds`."""
    obj = ROOT / "build" / "common" / "host" / "image.o"
    script = (f"end=$((SECONDS+{int(seconds)})); n=0; while [ $SECONDS -lt $end ]; do "
              f"touch {obj}; make -s -C {ROOT} lab01-ref >/dev/null || exit 1; n=$((n+1)); "
              f"done; echo $n")
    return subprocess.Popen(["bash", "-c", script], stdout=subprocess.PIPE, text=True)


def test_a_reference_runs_while_make_relinks_it(lab01_ref):
    before = os.stat(lab01_ref).st_ino
    make = relinking(6)
    failures, runs = [], 0
    with policy(RunPolicy(trusted=True)):
        while make.poll() is None:
            run = run_lab(lab01_ref, width=2, height=2, spp=1, check=False)
            runs += 1
            if run.returncode != 0:
                failures.append(run.stderr.strip()[-200:])
    relinks = int(make.communicate()[0] or 0)
    assert make.returncode == 0
    # At least one relink while runs went on (a busy two-core machine may fit only one).
    assert relinks >= 1 and os.stat(lab01_ref).st_ino != before, "make never relinked"
    assert not failures, f"{len(failures)} of {runs} runs failed: {failures[:3]}"


def test_graders_started_together_grade_alike(lab01_ref, tmp_path):
    """Two graders start together in this checkout (each asking make for its references, as
    `make grade` does) while a third process relinks lab01-ref; each grades lab01-ref on the
    hidden scene alone (its golden data rendered by lab01-ref): both pass."""
    code = ("import sys; from grading import grade as g; g.RUBRICS['01'] = [g.hidden_scene()]; "
            "sys.exit(g.main(sys.argv[1:]))")
    make = relinking(3)
    graders = [subprocess.Popen([sys.executable, "-c", code, "01", "--binary", str(lab01_ref),
                                 "--trusted", "--results", str(tmp_path / f"{n}.json"),
                                 "--heatmaps", str(tmp_path / n)],
                                cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                text=True)
               for n in ("a", "b")]
    outputs = [g.communicate(timeout=600)[0] for g in graders]
    make.wait()
    for n, out in zip(("a", "b"), outputs):
        results = json.loads((tmp_path / f"{n}.json").read_text())
        assert [t["status"] for t in results["tests"]] == ["passed"], out


def test_a_reference_that_cannot_run_is_marked_for_regrade(tmp_path, monkeypatch):
    broken = tmp_path / "lab01-ref"
    broken.write_text("not a program")
    broken.chmod(0o644)  # as a linker leaves it while it writes
    monkeypatch.setattr(references, "ROOT", tmp_path)
    line = references.problem("01")
    assert line and "lab01-ref" in line and "regrade" in line
    results = grader.grade("01", build("lab01-ref")[0], tmp_path / "maps", trusted=True)
    assert results["score"] == 0
    assert all(t["extra_data"]["regrade"] for t in results["tests"]), results


def test_a_check_that_failed_while_a_reference_could_not_run_is_not_a_score(tmp_path):
    item = grader.Item("probe", "probe", 10,
                       lambda b: CheckResult("probe", False, "exited with status 126"))
    results = Results()
    results.add(Test(item.id, item.label, item.points))
    limits = Limits(wall_seconds=5)
    grader.grade_items([item], ROOT / "lab01-ref", tmp_path, "", results, RunPolicy(),
                       limits, 60, time.perf_counter(),
                       reference_problem=lambda: "the reference lab01-ref cannot run")
    test = results.test("probe")
    assert test.regrade and test.score == 0 and "cannot run" in test.output
