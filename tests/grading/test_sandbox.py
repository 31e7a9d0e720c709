"""labkit/sandbox.py on its own: what a sandboxed process may touch, and its limits."""
import pytest

from labkit import sandbox
from labkit.sandbox import Limits, Runner, describe_exit


@pytest.fixture(autouse=True)
def needs_sandbox():
    reason = sandbox.probe()
    if reason:
        pytest.fail(f"the grader's sandbox is not available here: {reason}")


def sh(script: str, limits: Limits = Limits(wall_seconds=10), **runner):  # noqa: B008 (frozen)
    with Runner(trusted=False, **runner) as r:
        return r.run(["/bin/sh", "-c", script], limits)


def test_only_scratch_and_tmp_are_writable():
    out = sh("for p in /job/x /usr/x /x /etc/x /proc/x /scratch/ok /tmp/ok; do "
             "(echo > $p) 2>/dev/null && echo wrote $p; done; id -u")
    assert out.stdout.split() == ["wrote", "/scratch/ok", "wrote", "/tmp/ok", "65534"], out


def test_it_sees_only_its_inputs(tmp_path):
    secret = tmp_path / "secret.txt"
    secret.write_text("x")
    given = tmp_path / "given.txt"
    given.write_text("y")
    with Runner(trusted=False) as r:
        inside = r.input(given)
        out = r.run(["/bin/sh", "-c", f"ls /job; cat {inside}; cat {secret}; ls /root /home"])
    # A neutral name: a submission cannot tell from a file's name which check runs it.
    assert out.stdout.split() == ["0", "y"], out


def test_file_size_limit_is_named():
    out = sh("head -c 2000000 /dev/zero > big", Limits(wall_seconds=10, file_bytes=1 << 20))
    assert "file size limit exceeded" in out.failure, out


def test_what_is_left_in_scratch_is_limited():
    out = sh("for i in 1 2 3; do head -c 600000 /dev/zero > f$i; done",
             Limits(wall_seconds=10, scratch_bytes=1 << 20))
    assert out.failure and "left 2 MiB in its scratch folder" in out.failure, out


def test_process_limit():
    out = sh("for i in $(seq 40); do sleep 3 & done; wait", Limits(wall_seconds=10, processes=20))
    assert "fork" in out.stderr.lower(), out


def test_wall_limit_counts_from_outside():
    out = sh("sleep 30", Limits(wall_seconds=0.5))
    assert out.failure == "timed out after 0.5 s (wall clock)"
    assert 0.5 <= out.wall_seconds < 3


def test_a_run_confined_to_one_cpu_cannot_widen_its_affinity():
    """Limits.cpu: the whole run is on that CPU and sched_setaffinity is refused (bwrap
    --seccomp), where an unconfined run may change its affinity."""
    import os

    from tests.grading.submissions import widen_affinity_script
    cpus = sorted(os.sched_getaffinity(0))
    if len(cpus) < 2:
        pytest.skip("one CPU: nothing to widen to")
    free = sh(widen_affinity_script())
    assert "widened" in free.stdout, free
    confined = sh(widen_affinity_script(), Limits(wall_seconds=10, cpu=cpus[-1]))
    assert confined.returncode == 0, confined
    assert confined.stdout.split() == ["Cpus_allowed_list:", str(cpus[-1])] * 2, confined


@pytest.mark.parametrize("code, name", [(-11, "segmentation fault (signal 11)"),
                                        (139, "segmentation fault (signal 11)"),
                                        (134, "aborted (signal 6)"), (3, "exited with status 3")])
def test_exit_statuses_are_named(code, name):
    assert describe_exit(code) == name


# ---- the grader's clocks, thread by thread (sandbox.TreeClock) -----------------------------

SPIN = "i=0; while [ $i -lt 600000 ]; do i=$((i+1)); done"  # ~0.5 s of one core's time


def test_one_busy_thread_did_all_the_work():
    out = sh(SPIN, Limits(wall_seconds=30))
    assert out.returncode == 0 and out.busiest_thread_share >= 0.9, out


def test_work_shared_by_two_at_once_is_shared():
    out = sh(f"({SPIN}) & ({SPIN}); wait", Limits(wall_seconds=30))
    assert out.returncode == 0 and 0.3 <= out.busiest_thread_share <= 0.7, out


def test_the_work_of_ended_processes_still_counts():
    """Two workers one after the other, each ended and reaped before the next: what they did
    stays in the tree's total, so neither is taken for all of the work."""
    out = sh(f"({SPIN}); ({SPIN})", Limits(wall_seconds=30))
    assert out.returncode == 0 and 0.3 <= out.busiest_thread_share <= 0.7, out


def test_the_runs_get_the_graders_priority_where_it_may_give_it():
    """As root, every run of the grader's runs at sandbox.RUN_NICE, its session's autogroup
    and its threads alike (a burner in another session does not halve a parallel program's
    cores); a process may lower its priority again, not raise it."""
    import os
    if os.geteuid() != 0:
        pytest.skip("only root may raise a process's priority")
    out = sh("sleep 0.3; cat /proc/self/autogroup; cut -d' ' -f19 /proc/self/stat; "
             "renice -n -19 -p $$ >/dev/null 2>&1 && echo raised")
    assert f"nice {sandbox.RUN_NICE}" in out.stdout, out
    assert out.stdout.split()[-1] == str(sandbox.RUN_NICE), out
