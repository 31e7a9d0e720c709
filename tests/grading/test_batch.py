"""`make grade-batch` for instructors (grading/classes/batch.py): grades.csv carries per student the
points, provisional points apart, times, speedup, capacity and the cause of a failure, then
a class row with the flagged count; progress is `[k/N] name ...`; hand-in zips are graded
as folders; ONLY=flagged regrades only the flagged, with the batch's saved secret, and
merges them. The grader itself is replaced here by recorded results (test_delivery.py grades
real submissions)."""
import csv
import json
import zipfile

import pytest

from grading.classes import batch


def result_test(check, name, score, max_score, output, passed=None, regrade=False,
                provisional=0):
    return {"name": name, "score": score, "max_score": max_score,
            "status": "passed" if (passed if passed is not None else score == max_score)
            else "failed", "output": output,
            "extra_data": {"check": check, "regrade": regrade, "provisional": provisional}}


FAST = {"score": 100, "max_score": 100, "output": "", "tests": [
    result_test("bitwise", "bit-identical to lab 01", 30, 30, "identical for 1 threads"),
    result_test("parallel-speedup", "parallel speedup", 40, 40,
         "yours 1.91x over the serial reference (0.611 s -> 0.320 s) on 2 cores giving 1.97x "
         "capacity; needs >= 1.48x")]}
# As results.json holds it: the points a regrade may add apart, never in the score.
BUSY = {"score": 30, "max_score": 100, "output": "marked for regrade", "tests": [
    result_test("bitwise", "bit-identical to lab 01", 30, 30, "identical"),
    result_test("parallel-speedup", "parallel speedup", 0, 40,
         "not measurable: the machine gave only 1.12 cores' worth of throughput in 3 "
         "attempts (+40 if the regrade confirms)", regrade=True, provisional=40)]}
RACY = {
    "score": 0,
    "max_score": 100,
    "output": "",
    "tests": [
        result_test(
            "bitwise",
            "bit-identical to lab 01",
            0,
            30,
            "not graded until the parallel speedup passes",
        ),
        result_test(
            "parallel-speedup",
            "parallel speedup",
            0,
            40,
            "the timed render differs from the "
            "serial reference's image: speed is graded only for a correct image",
        ),
    ],
}
BROKEN = {
    "score": 0,
    "max_score": 100,
    "output": "the code does not compile:\nsrc/render.cpp:3:1: error: expected ';'",
    "tests": [
        result_test(
            "bitwise", "bit-identical to lab 01", 0, 30, "not graded: the code does not compile"
        ),
        result_test("parallel-speedup", "parallel speedup", 0, 40, "not graded"),
    ],
}


def rows_of(path):
    return list(csv.DictReader(path.open()))


def test_csv_columns_numbers_causes_and_class_row(tmp_path, monkeypatch):
    monkeypatch.setitem(batch.RUBRICS, "03", [type("I", (), {"label": t["name"]})()
                                              for t in FAST["tests"]])
    batch.write_csv(tmp_path / "g.csv", "03",
                    {"fast": FAST, "busy": BUSY, "racy": RACY, "broken": BROKEN})
    rows = {r["student"]: r for r in rows_of(tmp_path / "g.csv")}
    fast, busy, racy, broken = rows["fast"], rows["busy"], rows["racy"], rows["broken"]
    assert (fast["reference_s"], fast["yours_s"], fast["speedup"], fast["capacity"]) == \
        ("0.611", "0.320", "1.91", "1.97")
    assert fast["cause"] == "" and fast["flagged"] == "" and fast["provisional_points"] == "0"
    assert busy["provisional_points"] == "40" and busy["flagged"] == "yes"
    assert busy["capacity"] == "1.12"
    assert racy["cause"].startswith("race: parallel speedup: the timed render differs")
    assert broken["cause"] == "compile error: src/render.cpp:3:1: error: expected ';'"
    summary = rows["(class: 4 students)"]
    assert summary["score"] == "mean 32.5" and summary["flagged"] == "1 flagged"
    assert summary["provisional_points"] == "40"


def fake_grader(calls, results):
    def grade_one(lab, folder, out, extra, env):
        calls.append((folder.name, env["GRADING_SECRET"], sorted(
            p.name for p in folder.rglob("*") if p.is_file())))
        out.mkdir(parents=True, exist_ok=True)
        r = results[folder.name]
        (out / "results.json").write_text(json.dumps(r))
        return r
    return grade_one


def test_progress_zips_secret_and_only_flagged(tmp_path, monkeypatch, capsys):
    subs, report = tmp_path / "subs", tmp_path / "report"
    (subs / "ann").mkdir(parents=True)
    (subs / "ann" / "render.cpp").write_text("x")
    with zipfile.ZipFile(subs / "ben.zip", "w") as z:
        z.writestr("ben-lab03/render.cpp", "y")
        z.writestr("../escape.cpp", "z")  # never written outside the unpacked folder
    calls = []
    monkeypatch.setattr(batch, "grade_one", fake_grader(calls, {"ann": FAST, "ben-lab03": BUSY,
                                                                "ben": BUSY}))
    monkeypatch.delenv("GRADING_SECRET", raising=False)
    assert batch.main(["03", str(subs), "--out", str(report)]) == 0
    out = capsys.readouterr().out
    assert "[1/2] ann ..." in out and "[2/2] ben ..." in out and "left" in out
    assert "1 flagged" in out
    secret = (report / batch.SECRET_FILE).read_text().strip()
    assert (report / batch.SECRET_FILE).stat().st_mode & 0o077 == 0
    assert [c[0] for c in calls] == ["ann", "ben"] and {c[1] for c in calls} == {secret}
    assert calls[1][2] == ["render.cpp"] and not (tmp_path / "escape.cpp").exists()
    # the regrade: only ben, with the same secret, merged with ann's first grade
    calls.clear()
    monkeypatch.setenv("GRADING_SECRET", "another")
    assert batch.main(["03", str(subs), "--out", str(report), "--only", "flagged"]) == 0
    assert [(c[0], c[1]) for c in calls] == [("ben", secret)]
    assert {r["student"] for r in rows_of(report / "grades.csv")} >= {"ann", "ben"}


def test_only_flagged_needs_an_earlier_report(tmp_path, capsys):
    (tmp_path / "subs").mkdir()
    assert batch.main(["03", str(tmp_path / "subs"), "--out", str(tmp_path / "r"),
                       "--only", "flagged"]) == 2
    assert "needs an earlier batch's report" in capsys.readouterr().err


@pytest.mark.parametrize("seconds,text", [(30, "about 30 s left"), (600, "about 10 min left")])
def test_estimate(seconds, text):
    assert batch.eta(1, 2, seconds) == f", {text}"


EXPORT_METADATA = """\
---
submission_123456:
  :submitters:
  - :name: Ada Lovelace
    :sid: '1815'
    :email: ada@example.edu
  :created_at: 2026-11-30 10:00:00.000000000 -08:00
  :score: 0.0
submission_123457:
  :submitters:
  - :name: Alan Turing
    :sid: '1912'
    :email: alan@example.edu
  - :name: Grace Hopper
    :sid: '1906'
    :email: grace@example.edu
"""


@pytest.mark.parametrize("with_yaml", [True, False])
def test_export_metadata_parses_with_and_without_pyyaml(monkeypatch, with_yaml):
    if not with_yaml:
        import builtins
        real = builtins.__import__

        def no_yaml(name, *args, **kwargs):
            if name == "yaml":
                raise ImportError(name)
            return real(name, *args, **kwargs)
        monkeypatch.setattr(builtins, "__import__", no_yaml)
    parsed = batch.parse_export_metadata(EXPORT_METADATA)
    assert parsed["submission_123456"] == [
        {"name": "Ada Lovelace", "sid": "1815", "email": "ada@example.edu"}]
    assert [p["name"] for p in parsed["submission_123457"]] == ["Alan Turing", "Grace Hopper"]


def test_a_gradescope_export_is_graded_and_keyed_by_submission_id(tmp_path, monkeypatch):
    export, report = tmp_path / "assignment_99_export", tmp_path / "report"
    for folder in ("submission_123456", "submission_123457"):
        (export / folder).mkdir(parents=True)
        (export / folder / "render.cpp").write_text("x")
    (export / "submission_metadata.yml").write_text(EXPORT_METADATA)
    calls = []
    monkeypatch.setattr(batch, "grade_one", fake_grader(
        calls, {"submission_123456": FAST, "submission_123457": RACY}))
    assert batch.main(["03", str(export), "--out", str(report)]) == 0
    rows = {r["submission_id"]: r for r in rows_of(report / "grades.csv") if r["submission_id"]}
    assert rows["123456"]["submitters"] == "Ada Lovelace <ada@example.edu> (1815)"
    assert rows["123457"]["submitters"].count("<") == 2 and rows["123457"]["score"] == "0"
    assert rows["123456"]["speedup"] == "1.91"


def test_a_gpu_lab_grades_one_submission_per_gpu_at_once(tmp_path, monkeypatch):
    subs = tmp_path / "subs"
    for student in ("a", "b", "c", "d"):
        (subs / student).mkdir(parents=True)
    monkeypatch.setenv("CUDA_VISIBLE_DEVICES", "0,1")
    import threading
    running, most, seen, lock = [0], [0], [], threading.Lock()

    def grade_one(lab, folder, out, extra, env):
        with lock:
            running[0] += 1
            most[0] = max(most[0], running[0])
            seen.append(env["CUDA_VISIBLE_DEVICES"])
            if lab == "05":  # a GPU's index counted as nvidia-smi counts it
                assert env["CUDA_DEVICE_ORDER"] == "PCI_BUS_ID"
        import time
        time.sleep(0.3)
        with lock:
            running[0] -= 1
        out.mkdir(parents=True, exist_ok=True)
        return FAST
    monkeypatch.setattr(batch, "grade_one", grade_one)
    assert batch.main(["05", str(subs), "--out", str(tmp_path / "r")]) == 0
    assert most[0] == 2 and sorted(seen) == ["0", "0", "1", "1"]
    seen.clear()
    most[0] = 0
    assert batch.main(["03", str(subs), "--out", str(tmp_path / "r3")]) == 0
    assert most[0] == 1  # a CPU lab: one at a time


def test_a_race_and_a_work_split_are_told_apart():
    """The bit check's two diagnoses (grading/checks/identity.py) are two causes in grades.csv."""
    def failed(output):
        return {"score": 40, "tests": [{"name": "bit for bit", "score": 0, "max_score": 20,
                                        "output": output}]}
    race = failed("FAIL: nondeterministic: a data race or shared generator: rows 3-9 differ")
    split = failed("FAIL: deterministic but different: work split: 2 threads differ from 1")
    assert batch.failure_cause(race).startswith("race: ")
    assert batch.failure_cause(split).startswith("work split: ")


def test_a_cause_is_labelled_by_its_verdict_and_shows_its_words():
    """Rows never gathered (lab 04's skeleton) are no race though the check says the image
    "differs for" a count; the words that name the cause survive the cut; threads that took
    turns are their own cause."""
    def failed(output):
        return {"score": 0, "tests": [{"name": "bit for bit", "score": 0, "max_score": 30,
                                       "output": output}]}
    counts = ", ".join(f"{n} ranks x {t} threads" for n in (1, 2, 3) for t in (1, 2, 4))
    gather = failed(f"FAIL: differs for {counts} from lab 01's image: at 2 ranks x 1 threads, "
                    f"150 of 300 rows are exactly black (rows 150-299): rows never rendered or "
                    f"never gathered (how the rows are divided among ranks)")
    cause = batch.failure_cause(gather)
    assert cause.startswith("rows missing: ") and "never gathered" in cause, cause
    turns = failed("FAIL: the threads ran one at a time: the work was shared among them")
    assert batch.failure_cause(turns).startswith("threads took turns: ")


def test_leaderboard_only_for_a_measured_correct_speed():
    """Gradescope's leaderboard (results.json) ranks the speed the grader measured on a
    correct image; a failed, unmeasured or provisional speed check gives no entry."""
    from grading.speed_numbers import leaderboard

    def graded(score, output, regrade=False):
        return {"tests": [{"name": "speed", "score": score, "max_score": 30, "output": output,
                           "extra_data": {"check": "speed", "regrade": regrade}}]}
    measured = "1.62x (0.412 s -> 0.254 s wall clock measured by the grader, best of 3)"
    assert leaderboard(graded(30, measured)) == [
        {"name": "speedup", "value": 1.62, "order": "desc"},
        {"name": "time (s)", "value": 0.254, "order": "asc"}]
    assert leaderboard(graded(0, "wrong image: speed is graded only for a correct image")) == []
    assert leaderboard(graded(0, measured)) == []
    assert leaderboard(graded(30, measured, regrade=True)) == []


HIDDEN_NOTE = "hidden scene: passed (its details are shown once the grades are published)"
SERIAL = {"score": 10, "max_score": 100, "output": HIDDEN_NOTE, "tests": [
    result_test("bitwise", "bit-identical to lab 01", 0, 30,
                "not counted until parallel speedup passes; it saw: PASS identical for 1, 2, 3, "
                "7 threads", passed=False),
    result_test("parallel-speedup", "parallel speedup", 0, 40,
                "serial: in every timed run one thread did at least 90% of the CPU time (99% at "
                "the least; measured by the grader, thread by thread, on a machine giving 1.97 "
                "cores' worth)")]}


def test_the_cause_is_the_failing_gates_verdict_not_a_check_that_passed():
    cause = batch.failure_cause(SERIAL)
    assert "serial: in every timed run one thread did" in cause, cause
    assert "PASS" not in cause, cause
    assert batch.speed_numbers(SERIAL)["capacity"] == "1.97"  # measured: shown beside it


def test_a_timed_serial_verdict_shows_its_numbers():
    """A serial program whose runs were timed: the verdict keeps the times, speedup and
    capacity measured, and the class page reads them beside it."""
    from grading.checks import speed
    from labkit.harness import ParallelTiming
    timing = ParallelTiming(base=0.6, best={"yours": 0.61}, capacity=1.96, cores=2)
    verdict = speed.serial_by_thread([0.99, 0.98], "1.01 cores' worth at most, on a machine "
                                     "giving 1.96", timing.describe("yours"))
    results = {"tests": [result_test("parallel-speedup", "parallel speedup", 0, 40,
                                     verdict.detail)]}
    assert batch.speed_numbers(results) == {"reference_s": "0.600", "yours_s": "0.610",
                                            "speedup": "0.98", "capacity": "1.96"}
    assert "serial: in every timed run" in batch.failure_cause(results)


def test_the_class_page_names_links_sorts_plots_and_says_a_shared_note_once(tmp_path,
                                                                             monkeypatch):
    monkeypatch.setitem(batch.RUBRICS, "03", [type("I", (), {"label": t["name"]})()
                                              for t in FAST["tests"]])
    rows = {"submission_1": {**FAST, "output": HIDDEN_NOTE},
            "submission_2": SERIAL, "submission_3": {**BROKEN}}
    for student in rows:
        (tmp_path / student).mkdir()
    submitters = {"submission_1": "Ada Lovelace <ada@example.edu> (1815)",
                  "submission_2": "Alan Turing <alan@example.edu> (1912)",
                  "submission_3": "Grace Hopper <grace@example.edu> (1906)"}
    batch.write_report(tmp_path, "03", rows, submitters)
    page = (tmp_path / "report.html").read_text()
    for name in ("Ada Lovelace", "Alan Turing", "Grace Hopper"):
        assert name in page
    for student in rows:  # every row links to a page that exists
        assert f'href="{student}/heatmaps/report.html"' in page
        assert (tmp_path / student / "heatmaps" / "report.html").is_file()
    assert page.count(HIDDEN_NOTE.split(" (")[0]) == 1, page  # said once, not per row
    assert page.count("<svg") >= 2 and "sort" in page and "<th onclick" in page
    assert "serial: in every timed run" in page and "1.91" in page and "1.97" in page
    # causes and notes wrap in columns of their own width, so every column fits a screen
    assert 'td.words{' in page and page.count('<td class="words">') == 2 * len(rows)


def test_a_cause_is_cut_between_words():
    from grading.classes.verdicts import clipped
    text = "the timed render differs from the serial reference " * 10
    cut = clipped(text, 60)
    assert len(cut) <= 60 and cut.endswith("…") and text.startswith(cut[:-1])
    assert text[len(cut) - 1] == " ", cut  # where a word ended
    assert clipped("short", 60) == "short"


def test_a_grader_that_never_ends_is_stopped_and_the_class_goes_on(tmp_path, monkeypatch):
    """One hand-in must not hold up the class: a grader still running past its time is
    stopped, and its row says so."""
    import sys
    subs = tmp_path / "subs"
    for student in ("ann", "bob"):
        (subs / student).mkdir(parents=True)
    monkeypatch.setattr(batch, "GRADER_SECONDS", 1)
    monkeypatch.setattr(batch, "STOP_GRACE_SECONDS", 1)
    monkeypatch.setattr(batch, "grader_command", lambda lab, folder, out, extra: [
        sys.executable, "-c", "import signal, time; signal.signal(signal.SIGTERM, "
        "signal.SIG_IGN); time.sleep(600)"])
    assert batch.main(["01", str(subs), "--out", str(tmp_path / "r")]) == 0
    rows = {r["student"]: r for r in rows_of(tmp_path / "r" / "grades.csv")}
    assert rows["ann"]["cause"].startswith("timeout: the grader did not finish"), rows["ann"]
    assert rows["bob"]["cause"].startswith("timeout: the grader did not finish"), rows["bob"]
