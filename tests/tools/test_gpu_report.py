"""tools/gpu/report.py's summary, on the CPU: the tables it makes of a recorded gpu-check.json
(the H200 record in reference/gpu/h200), and its one-line error.

That record holds no test results (its `tests` entry is the error of a missing junit file)
and every benchmark in it has speed targets, so the tests that count passes and failures,
and that a run without targets prints no targets table, read fixtures/gpu-check-h200.json:
an earlier H200 run's gpu-check.json (77 GPU tests passed, 1 failed; no targets), from
`reference/gpu/` at commit `1fdebed`."""
import copy
import json
import pathlib
import subprocess
import sys

from labkit.harness import ROOT
from tools.gpu import report as gpu_report

RECORDED = ROOT / "reference" / "gpu" / "h200"
WITH_TESTS = pathlib.Path(__file__).resolve().parent / "fixtures" / "gpu-check-h200.json"


def recorded() -> dict:
    return json.loads((RECORDED / "gpu-check.json").read_text())


def recorded_with_tests() -> dict:
    return json.loads(WITH_TESTS.read_text())


def test_summary_of_a_recorded_call_is_the_recorded_summary():
    assert gpu_report.summary(recorded()) == (RECORDED / "summary.md").read_text()


def test_summary_counts_tests_and_names_each_failure():
    result = recorded_with_tests()
    text = gpu_report.summary(result)
    assert "Tests: 77 passed, 1 failed, 0 errors, 0 skipped" in text
    assert "- test_h200_bar: failure" in text
    result = copy.deepcopy(result)
    result["tests"][0]["result"] = "failure: planted"
    text = gpu_report.summary(result)
    assert "Tests: 76 passed, 2 failed" in text
    assert f"- {result['tests'][0]['test']}: failure: planted" in text


def test_summary_lists_every_benchmark_shape_with_its_time():
    result = recorded()
    text = gpu_report.summary(result)
    for v in result["bench"]["variants"]:
        assert f"| {v['name']} | {v['change']} |" in text
        assert f"| {v['best_ms']:.2f} |" in text


def test_speed_targets_are_tabulated_with_their_verdict():
    result = recorded()
    result["bench"]["targets"] = [
        {
            "config": "reference",
            "bar": "at most 13 ms on an NVIDIA H200, the baseline",
            "best_ms": 39.9,
            "met": False,
        }
    ]
    result["bench_lab07"] = {
        "targets": [
            {
                "config": "SoA",
                "bar": "faster than AoS on an NVIDIA H200, the baseline",
                "best_ms": 67.6,
                "met": None,
                "why_not": "not this GPU",
            }
        ]
    }
    text = gpu_report.summary(result)
    assert (
        "| lab05-bench | reference | at most 13 ms on an NVIDIA H200, the baseline"
        " | 39.90 | **no** |" in text
    )
    assert (
        "| lab07-bench | SoA | faster than AoS on an NVIDIA H200, the baseline"
        " | 67.60 | not judged (not this GPU) |" in text
    )
    assert "Speed targets" not in gpu_report.summary(recorded_with_tests())


def test_missing_steps_are_said_not_crashed_on():
    result = recorded()
    result["bench"] = {"error": "bench.json: no such file"}
    result["ncu"] = [{"run": "cornell", "error": "no CSV"}]
    text = gpu_report.summary(result)
    assert "| shape | change |" not in text
    assert "| cornell | error: no CSV |" in text


def test_unreadable_json_is_one_line_and_status_2(tmp_path):
    bad = tmp_path / "gpu-check.json"
    bad.write_text("{not json")
    p = subprocess.run(
        [sys.executable, "-m", "tools.gpu.report", "--summary", str(bad)],
        cwd=ROOT,
        capture_output=True,
        text=True,
    )
    assert p.returncode == 2
    assert len(p.stderr.strip().splitlines()) == 1 and "cannot read" in p.stderr
