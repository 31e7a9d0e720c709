"""The autograder end to end: full marks for the reference, a clear zero-ish for the
skeleton, and a results.json in Gradescope's shape."""
import json
import subprocess
import sys

from grading.harness import ROOT


def grade(binary, tmp_path):
    results = tmp_path / "results.json"
    p = subprocess.run([sys.executable, "-m", "grading.grade", "01", "--binary", str(binary),
                        "--results", str(results), "--heatmaps", str(tmp_path / "maps")],
                       cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, p.stderr
    return json.loads(results.read_text()), p.stdout


def test_reference_gets_full_marks(lab01_ref, tmp_path):
    results, table = grade(lab01_ref, tmp_path)
    assert results["score"] == results["max_score"] == 100, table
    assert all({"name", "score", "max_score", "output"} <= t.keys() for t in results["tests"])
    assert not (tmp_path / "maps").exists()  # no failures, no heatmaps


def test_skeleton_gets_nothing_and_a_heatmap(lab01_pristine_skeleton, tmp_path):
    results, table = grade(lab01_pristine_skeleton, tmp_path)
    assert results["score"] == 0, table
    assert "FAIL" in table and "total" in table
    assert (tmp_path / "maps" / "cornell-diff.png").read_bytes().startswith(b"\x89PNG")
