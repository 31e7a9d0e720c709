"""Speed grading's partial credit and its provisional points (grading/checks/speed.py,
grading/results.py): the curve, and points a regrade may add kept out of every total."""
import math
import time

import pytest

from grading.checks.check_result import CheckResult
from grading.checks.speed import ZERO_CREDIT_AT, speed_credit
from grading.results import Results, Test


def test_credit_is_full_at_the_bar_and_none_at_its_documented_fraction():
    assert speed_credit(1.5, 1.5) == 1.0 and speed_credit(9.0, 1.5) == 1.0
    assert speed_credit(ZERO_CREDIT_AT * 1.5, 1.5) == 0.0
    assert speed_credit(1.0, 1.5) == 0.0  # a serial program against a 1.5x bar
    middle = (1 + ZERO_CREDIT_AT) / 2 * 1.5
    assert speed_credit(middle, 1.5) == pytest.approx(0.5)
    assert speed_credit(math.nan, 1.5) == 0.0


def test_credit_falls_linearly():
    values = [speed_credit(x, 2.0) for x in (1.5, 1.6, 1.7, 1.8, 1.9, 2.0)]
    steps = [b - a for a, b in zip(values, values[1:])]
    assert all(s == pytest.approx(0.2) for s in steps), values


def test_provisional_points_are_never_in_the_score():
    results = Results()
    results.add_all([Test("images", "images", 60), Test("speed", "speed", 40)])
    results.test("images").finish(60, "fine", ok=True)
    results.test("speed").finish(10, "short of the bar on a busy machine", regrade=True,
                                 ok=True, provisional=30)
    results.complete(1.0)
    data = results.as_dict()
    assert data["score"] == 70
    speed = data["tests"][1]
    assert speed["score"] == 10 and speed["extra_data"]["provisional"] == 30
    assert speed["status"] == "failed" and "+30 if the regrade confirms" in speed["output"]
    assert "70/100, +30 if the regrade confirms" in data["output"]


def test_check_result_defaults_to_all_or_nothing():
    assert CheckResult("x", True, "").credit is None


def test_a_cpu_quota_below_two_cores_times_nothing(monkeypatch):
    """Gradescope's default container (--cpus=0.5) sees every CPU of the host, but may use
    half of one: the capacity is the cgroup's quota, and a parallel lab is not timed there:
    correctness is graded, the speed marked for regrade with its points shown apart."""
    from grading.checks import speed
    from labkit import harness
    monkeypatch.setattr(harness, "cpu_quota", lambda: 0.5)
    assert harness.cpu_capacity() == 0.5 and harness.available_cores() == 1
    result = speed.check_parallel_speedup("/nonexistent", "/nonexistent")
    assert result.regrade and result.passed and result.credit == 0 and result.provisional == 1
    assert result.detail.startswith("not timed: this machine gives 0.5 cores"), result.detail


def test_the_quota_is_read_from_the_cgroup():
    """Whatever this machine's quota, the capacity never exceeds the CPUs it may run on."""
    import os

    from labkit import harness
    quota = harness.cpu_quota()
    assert quota is None or quota > 0
    assert 0 < harness.cpu_capacity() <= len(os.sched_getaffinity(0))


def test_one_thread_doing_the_work_is_told_from_work_shared():
    from grading.checks.speed import ONE_THREAD, one_thread_did_it
    assert one_thread_did_it([1.0, ONE_THREAD]) and not one_thread_did_it([1.0, 0.5])
    assert not one_thread_did_it([]) and not one_thread_did_it([math.nan, 1.0])


@pytest.mark.parametrize("binary, serial", [("lab01-ref", True), ("lab03-ref", False)])
def test_serial_is_final_even_where_nothing_is_timed(monkeypatch, binary, serial):
    """At a CPU quota too small to time a speedup (Gradescope's default 0.5) one run still
    shows whose work it is: a serial program's one thread did all of it (final: no points,
    no regrade, the gated checks closed), a parallel one shares it (correctness graded,
    speed left to a regrade)."""
    from grading.checks import speed
    from labkit import harness
    monkeypatch.setattr(harness, "cpu_quota", lambda: 0.5)
    program, = harness.build(binary)
    result = speed.check_parallel_speedup(program, speed.LAB01_REFERENCE, threads=2)
    if serial:
        assert not result.regrade and not result.passed and result.credit == 0, result
        assert result.detail.startswith("serial: in every timed run one thread did"), result.detail
    else:
        assert result.regrade and result.passed and result.provisional == 1, result


def timed_with(monkeypatch, before: float, yours: float, after: float):
    """check_speedup with every run replaced by one that takes the given wall-clock seconds:
    the reference's run before the program in each round, the program's, the reference's
    after it. Returns the result and how many runs of the program it measured."""
    import numpy as np

    from grading.checks import speed
    from labkit.harness import Run
    calls = {"yours": 0, "reference": 0}

    def run_lab(binary, **_):
        if binary == "yours":
            calls["yours"] += 1
            seconds = yours
        else:
            seconds = before if calls["reference"] % 2 == 0 else after
            calls["reference"] += 1
        return Run(0, "", "", {}, np.zeros((1, 1, 3), np.float32), seconds, seconds, 1.0)

    monkeypatch.setattr(speed, "run_lab", run_lab)
    monkeypatch.setattr(speed, "timed_golden", lambda scene: None)
    monkeypatch.setattr(speed, "wrong_timed_image", lambda *args: None)
    monkeypatch.setattr(speed.time, "sleep", lambda seconds: None)
    result = speed.check_speedup("yours", "reference", 1.5)
    return result, calls["yours"]


def test_a_speedup_the_references_own_runs_disagree_about_is_left_to_a_regrade(monkeypatch):
    """The reference slowed before the program but not after it: 1.5x over its runs before
    (full points, were they the only ones), 1.25x over its best, and its two series 20% apart,
    which could make that anything from 1.04x to 1.5x. Measured again, then the lower credit
    counts and the rest waits for a regrade."""
    result, measured = timed_with(monkeypatch, before=0.30, yours=0.20, after=0.25)
    assert result.regrade and result.credit == 0 and result.provisional == 1, result
    assert not result.passed and measured == 9, (result, measured)
    assert "1.25x (0.250 s -> 0.200 s" in result.detail and "20.0% apart" in result.detail


def test_a_steady_reference_gives_final_credit(monkeypatch):
    result, measured = timed_with(monkeypatch, before=0.25, yours=0.20, after=0.25)
    assert not result.regrade and result.credit == pytest.approx(1 / 3) and measured == 3, result


def test_an_unsteady_reference_that_cannot_change_the_credit_is_final(monkeypatch):
    """Far above the bar, 10% of unsteadiness changes nothing: full points at once."""
    result, measured = timed_with(monkeypatch, before=1.0, yours=0.1, after=0.9)
    assert not result.regrade and result.credit == 1 and measured == 3, result


def parallel_timed(monkeypatch, *, capacity: float, base: float, yours: float, cores_used: float,
                   busiest: float):
    """check_parallel_speedup with the machine and every timed run replaced: the capacity and
    the serial reference's best as measure_parallel reports them, and each of the program's
    runs taking `yours` seconds, using `cores_used` cores' worth of CPU time, its busiest
    thread `busiest` of it."""
    import numpy as np

    from grading.checks import speed
    from labkit import harness
    from labkit.harness import ParallelTiming, Run

    def run_lab(binary, **_):
        return Run(0, "", "", {}, np.zeros((1, 1, 3), np.float32), yours, yours * cores_used,
                   busiest)

    def measure_parallel(baseline, candidates, **_):
        return ParallelTiming(2, capacity, base, {n: c() for n, c in candidates.items()})

    monkeypatch.setattr(speed, "run_lab", run_lab)
    monkeypatch.setattr(harness, "cpu_capacity", lambda: 2.0)
    monkeypatch.setattr(harness, "measure_parallel", measure_parallel)
    monkeypatch.setattr(speed.time, "sleep", lambda seconds: None)
    return speed.check_parallel_speedup("yours", "reference")


def test_a_speedup_beyond_the_machines_capacity_is_refused_as_impossible(monkeypatch):
    """A serial hand-in that replays a render it kept (its own first one, another run's):
    6.21x on two cores giving 1.91x is no speedup, whatever its threads looked like."""
    result = parallel_timed(monkeypatch, capacity=1.91, base=0.600, yours=0.600 / 6.21,
                            cores_used=1.2, busiest=0.6)
    assert not result.passed and result.credit == 0 and not result.regrade, result
    assert result.detail.startswith("impossible: yours 6.21x"), result.detail
    assert "1.91x capacity" in result.detail, result.detail


def test_a_speedup_within_the_capacity_is_scored(monkeypatch):
    result = parallel_timed(monkeypatch, capacity=1.91, base=0.600, yours=0.320,
                            cores_used=1.9, busiest=0.5)
    assert result.passed and result.credit == 1 and not result.regrade, result


def test_a_spinning_thread_opens_no_gate_on_cpu_share_alone(monkeypatch, tmp_path):
    """Serial code beside a thread that only spins, on a machine too busy to time: its work
    looks shared among threads, so the speed is left to a regrade, and the checks gated on
    it (bit identity, golden images) are graded with their points provisional, never in the
    score, until the regrade measures a speedup."""
    from grading.checks import check_result
    from grading.grade import Item, grade_items
    from labkit.harness import RunPolicy
    from labkit.sandbox import Limits

    speed = parallel_timed(monkeypatch, capacity=1.3, base=0.600, yours=0.600,
                           cores_used=1.3, busiest=0.5)
    assert speed.passed and speed.regrade and speed.credit == 0, speed
    rubric = [Item("parallel-speedup", "parallel speedup", 40, lambda b: speed),
              Item("bitwise", "bit-identical to lab 01", 30,
                   lambda b: check_result.CheckResult("bit-identical", True, "identical"),
                   requires="parallel-speedup")]
    results = Results()
    results.add_all([Test(i.id, i.label, i.points) for i in rubric])
    grade_items(rubric, "yours", tmp_path, "secret", results, RunPolicy(trusted=False),
                Limits(), 600, time.perf_counter())
    results.complete(1.0)
    data = results.as_dict()
    assert data["score"] == 0, data
    bitwise = data["tests"][1]
    assert bitwise["score"] == 0 and bitwise["extra_data"]["provisional"] == 30, (
        bitwise["output"], data["tests"][0]["output"])
    assert "counted when the regrade confirms the parallel speedup" in bitwise["output"], bitwise


def test_threads_that_take_turns_are_named_not_left_to_a_regrade(monkeypatch):
    """An `ordered` row loop: the work shared among the threads (the busiest did half), the
    waiting threads spinning (1.9 cores' worth of CPU time), and 0.95x where the same rounds
    measured 1.78 cores' worth: a final verdict that names the cause, not the machine."""
    result = parallel_timed(monkeypatch, capacity=1.78, base=0.600, yours=0.600 / 0.95,
                            cores_used=1.9, busiest=0.5)
    assert not result.passed and not result.regrade and result.credit == 0, result
    assert result.detail.startswith("the threads ran one at a time"), result.detail
    assert "0.95x" in result.detail and "1.78 cores' worth" in result.detail, result.detail


def test_a_slow_speedup_on_a_machine_without_room_still_waits_for_a_regrade(monkeypatch):
    """The same 0.95x where the machine gave only 1.4 cores' worth: not told apart from the
    load, so marked for regrade as before."""
    result = parallel_timed(monkeypatch, capacity=1.4, base=0.600, yours=0.600 / 0.95,
                            cores_used=1.3, busiest=0.5)
    assert result.regrade and result.credit == 0, result
