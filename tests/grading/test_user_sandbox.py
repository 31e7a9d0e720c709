"""The grader where namespaces cannot be had (a Docker container with Docker's default
seccomp profile, as on Gradescope): bubblewrap fails there, and the grader isolates by user
instead (labkit/sandbox.py, labkit/confine.py). The grader runs here under a seccomp filter
refusing namespace creation (tests/grading/no_namespaces.py), as such a container would."""
import json
import os
import subprocess
import sys

import pytest

from labkit import sandbox
from labkit.harness import GOLDEN, ROOT, build
from tests.grading import submissions as sub

NO_NAMESPACES = [
    sandbox.SYSTEM_PYTHON,
    "-I",
    str(ROOT / "tests" / "grading" / "no_namespaces.py"),
    "--",
]


@pytest.fixture(scope="module", autouse=True)
def system_seccomp():
    p = subprocess.run([sandbox.SYSTEM_PYTHON, "-I", "-c", "import seccomp"], capture_output=True)
    if p.returncode != 0:  # make deps installs python3-seccomp
        pytest.fail("python3-seccomp is not installed for /usr/bin/python3: run `make deps`")


def grade_without_namespaces(binary, tmp_path, lab="01", extra_env=None) -> tuple[int, dict, str]:
    out = tmp_path / "results.json"
    p = subprocess.run([*NO_NAMESPACES, sys.executable, "-m", "grading.grade", lab, "--binary",
                        str(binary), "--results", str(out), "--heatmaps", str(tmp_path / "maps")],
                       cwd=ROOT, capture_output=True, text=True, timeout=600,
                       env={**os.environ, **(extra_env or {})})
    return p.returncode, json.loads(out.read_text()), p.stderr


def test_namespaces_are_refused_under_the_filter():
    """The stand-in for Docker's profile works: bubblewrap cannot start under it."""
    p = subprocess.run([*NO_NAMESPACES, "bwrap", "--unshare-all", "--ro-bind", "/", "/", "true"],
                       capture_output=True, text=True)
    assert p.returncode != 0, p.stderr


@pytest.mark.timed
def test_reference_scores_100_without_namespaces(tmp_path):
    build("lab01-ref")
    status, results, stderr = grade_without_namespaces(sub.REFERENCE, tmp_path)
    if os.geteuid() != 0:  # the user sandbox switches users: only root can
        assert status == 2 and stderr.count("\n") == 1, stderr
        assert "seccomp filter" in results["output"] and "\n" not in results["output"]
        assert all(t["extra_data"]["regrade"] for t in results["tests"]), results
        return
    assert status == 0, stderr
    assert "a user of its own" in results["sandbox"], results["sandbox"]
    assert results["score"] == 100, json.dumps(results, indent=1)[:3000]


def test_skeleton_scores_at_most_10_without_namespaces(tmp_path, lab01_pristine_skeleton):
    if os.geteuid() != 0:
        pytest.skip("the user sandbox needs root")
    status, results, stderr = grade_without_namespaces(lab01_pristine_skeleton, tmp_path)
    assert status == 0 and results["score"] <= 10, json.dumps(results, indent=1)[:3000]


@pytest.fixture
def user_sandbox(monkeypatch):
    """This process's runs in the user sandbox."""
    if os.geteuid() != 0:
        pytest.skip("the user sandbox needs root")
    monkeypatch.setenv("GRADING_SANDBOX", "user")
    monkeypatch.setattr(sandbox, "_probe_result", [])
    monkeypatch.setattr(sandbox, "_isolation", [])
    assert sandbox.probe() is None and sandbox.isolation() == sandbox.USER
    sandbox.hide_from_sandbox(ROOT)


def test_user_sandbox_walls(user_sandbox, tmp_path):
    """No network, no namespaces, no reading the grader's files or the grader's environment,
    nothing left running after a run."""
    client = sub.socket_client(tmp_path)
    spy = sub.script(
        tmp_path,
        f"""cat "{ROOT / "labs" / "01-serial" / "solution" / "render.cpp"}" >/dev/null 2>&1 && echo SPY solution
cat "{GOLDEN / "cornell" / "meta.json"}" >/dev/null 2>&1 && echo SPY golden
unshare -U true 2>/dev/null && echo SPY namespace
echo "SECRET=$GRADING_SECRET"
(sleep 987653 &)
""",
        name="spy",
    )
    os.environ["GRADING_SECRET"] = "leak-me-4713"
    try:
        with sub.loopback_server() as port:
            with sandbox.Runner(trusted=False) as r:
                net = r.run([r.input(client), port])
                out = r.run([r.input(spy)])
                uid = r.box[0]
    finally:
        del os.environ["GRADING_SECRET"]
    assert net.returncode == 3, (net.returncode, net.stderr)
    assert "SPY" not in out.stdout and "leak-me-4713" not in out.stdout, out.stdout
    left = sandbox.user_processes(uid)
    assert not left, left


def test_only_mpiruns_runs_get_ip_sockets(user_sandbox, tmp_path):
    """Lab 04 in the user sandbox: OpenMPI's PMIx reaches every rank over loopback TCP, so a
    run the grader starts under mpirun has IP sockets (lab04-ref renders there, and a client
    under mpirun connects), and a run without it has none."""
    from grading.checks.mpi import mpirun
    from labkit.harness import RunPolicy, policy, run_lab
    build("lab04-ref")
    client = sub.socket_client(tmp_path)
    with sub.loopback_server() as port:
        with sandbox.Runner(trusted=False) as r:
            plain = r.run([r.input(client), port])
            launched = r.run([*mpirun(1), r.input(client), port])
    assert plain.returncode == 3, (plain.returncode, plain.stderr)
    assert launched.returncode == 0 and "connected" in launched.stdout, launched
    with policy(RunPolicy(trusted=False)):
        run = run_lab(ROOT / "lab04-ref", width=8, height=6, spp=2, launcher=mpirun(2))
    assert run.image.shape == (6, 8, 3)


def test_a_run_confined_to_one_cpu_cannot_widen_its_affinity(user_sandbox):
    """Limits.cpu in the user sandbox: confine.py's filter refuses sched_setaffinity there."""
    cpus = sorted(os.sched_getaffinity(0))
    if len(cpus) < 2:
        pytest.skip("one CPU: nothing to widen to")
    script = ["/bin/sh", "-c", sub.widen_affinity_script()]
    with sandbox.Runner(trusted=False) as r:
        free = r.run(script, sandbox.Limits(wall_seconds=10))
        confined = r.run(script, sandbox.Limits(wall_seconds=10, cpu=cpus[-1]))
    assert "widened" in free.stdout and not free.stderr, free  # it may write to /dev/null
    assert confined.returncode == 0, confined
    assert confined.stdout.split() == ["Cpus_allowed_list:", str(cpus[-1])] * 2, confined


def test_a_private_temporary_folder_is_refused_in_one_line(tmp_path):
    """The sandbox user must enter the folder where inputs and builds are staged: a private
    one (mode 700, as a fresh temporary folder is) is one line naming it, marked for regrade."""
    if os.geteuid() != 0:
        pytest.skip("only a grader running as root hands runs to another user")
    private = tmp_path / "private"
    private.mkdir(mode=0o700)
    out = tmp_path / "results.json"
    p = subprocess.run([sys.executable, "-m", "grading.grade", "01", "--binary",
                        str(sub.REFERENCE), "--results", str(out)], cwd=ROOT, capture_output=True,
                       text=True, timeout=300, env={**os.environ, "TMPDIR": str(private)})
    results = json.loads(out.read_text())
    assert p.returncode == 2 and p.stderr.count("\n") == 1, p.stderr
    named = p.stderr.split("cannot enter ")[1].split(" (mode")[0]
    assert str(private).startswith(named), p.stderr
    assert all(t["extra_data"]["regrade"] for t in results["tests"]), results


def test_a_batch_grades_the_sources_beside_a_binary_without_namespaces(tmp_path):
    """The reference's prebuilt binary handed in as `lab` beside the skeleton's sources, a
    batch graded as Gradescope's containers grade (the user sandbox): the skeleton's score,
    the binary named as ignored and never run."""
    import shutil

    from grading.students_tree import pristine_skeleton
    if os.geteuid() != 0:
        pytest.skip("the user sandbox needs root")
    subs, report = tmp_path / "subs", tmp_path / "report"
    (subs / "ann").mkdir(parents=True)
    for name, text in pristine_skeleton("01-serial").items():
        (subs / "ann" / name).write_text(text)
    shutil.copyfile(sub.REFERENCE, subs / "ann" / "lab")
    (subs / "ann" / "lab").chmod(0o755)
    p = subprocess.run([*NO_NAMESPACES, sys.executable, "-m", "grading.classes.batch", "01", str(subs),
                        "--out", str(report)], cwd=ROOT, capture_output=True, text=True,
                       timeout=600)
    results = json.loads((report / "ann" / "results.json").read_text())
    assert p.returncode == 0 and "a user of its own" in results["sandbox"], p.stdout + p.stderr
    assert results["score"] <= 10, json.dumps(results, indent=1)[:3000]
    assert "ignored, graded from its sources" in results["output"], results["output"]


def test_a_file_name_that_is_shell_code_is_refused_without_namespaces(tmp_path):
    name = "x.cpp;echo INJECTED-BUILD-STEP;.cpp"
    folder = tmp_path / "in"
    folder.mkdir()
    (folder / "render.cpp").write_text((ROOT / "labs/01-serial/solution/render.cpp").read_text())
    (folder / name).write_text("int unused;\n")
    out = tmp_path / "results.json"
    p = subprocess.run([*NO_NAMESPACES, sys.executable, "-m", "grading.grade", "01", "--sources",
                        str(folder), "--results", str(out)], cwd=ROOT, capture_output=True,
                       text=True, timeout=600)
    results = json.loads(out.read_text())
    assert p.returncode == 1 and results["score"] == 0, p.stderr
    assert p.stderr.count("\n") == 1 and name in p.stderr, p.stderr
    assert "INJECTED-BUILD-STEP\n" not in p.stdout + out.read_text()
