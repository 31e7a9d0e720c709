"""A class graded as a Slurm job array (grading/classes/slurm.py) on a one-node Slurm that this test
starts: its own munge daemon and key, slurmctld and slurmd on free ports, all in a scratch
folder (Debian's slurm-wlm and munge packages). Two lab-01 hand-ins, one finished and one that
does not compile, are graded one per array task in the sandbox; the merge job writes
grades.csv from both. Skipped, saying why, where Slurm is not installed or cannot start."""
import csv
import os
import pathlib
import shutil
import signal
import socket
import subprocess
import time

import pytest

from labkit import sandbox
from labkit.harness import ROOT

DAEMONS = ("munged", "slurmctld", "slurmd", "sbatch")


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def wait_for(condition, seconds, what):
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        if condition():
            return
        time.sleep(0.5)
    pytest.skip(f"one-node Slurm did not start: {what}")



def memory_mb() -> int:
    """The node's memory for slurm.conf, a little under what slurmd finds (more would drain
    the node): the grading tasks ask for --mem, which Slurm checks against it."""
    total_kb = int(pathlib.Path("/proc/meminfo").read_text().split()[1])
    return total_kb * 9 // 10 // 1024

@pytest.fixture
def slurm(tmp_path_factory):
    missing = [d for d in DAEMONS if shutil.which(d) is None
               and not pathlib.Path("/usr/sbin", d).exists()]
    if missing:
        pytest.skip(f"Slurm is not installed ({', '.join(missing)} missing: Debian's slurm-wlm)")
    if os.geteuid() != 0:
        pytest.skip("a one-node Slurm with slurmd needs root here")
    if sandbox.probe():
        pytest.skip(f"the grader's sandbox is not available: {sandbox.probe()}")
    d = tmp_path_factory.mktemp("slurm")
    d.chmod(0o755)
    key = d / "munge.key"
    key.write_bytes(os.urandom(1024))
    key.chmod(0o400)
    sock = d / "munge.sock"
    started = []
    subprocess.run(["munged", f"--socket={sock}", f"--key-file={key}",
                    f"--log-file={d / 'munged.log'}", f"--pid-file={d / 'munged.pid'}",
                    f"--seed-file={d / 'munged.seed'}", "--force"], check=True)
    started.append(d / "munged.pid")
    host = socket.gethostname()
    (d / "state").mkdir()
    (d / "spool").mkdir()
    conf = d / "slurm.conf"
    conf.write_text(f"""\
ClusterName=grading
SlurmctldHost={host}(127.0.0.1)
SlurmUser=root
SlurmdUser=root
SlurmctldPort={free_port()}
SlurmdPort={free_port()}
AuthType=auth/munge
AuthInfo=socket={sock}
CredType=cred/munge
StateSaveLocation={d / 'state'}
SlurmdSpoolDir={d / 'spool'}
SlurmctldPidFile={d / 'slurmctld.pid'}
SlurmdPidFile={d / 'slurmd.pid'}
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
MpiDefault=none
SlurmctldLogFile={d / 'slurmctld.log'}
SlurmdLogFile={d / 'slurmd.log'}
NodeName={host} NodeAddr=127.0.0.1 CPUs={os.cpu_count()} RealMemory={memory_mb()} State=UNKNOWN
PartitionName=grading Nodes={host} Default=YES MaxTime=INFINITE State=UP
""")
    env = {**os.environ, "SLURM_CONF": str(conf)}
    try:
        for daemon in ("slurmctld", "slurmd"):
            subprocess.run([daemon, "-f", str(conf)], check=True, env=env)
            started.append(d / f"{daemon}.pid")

        def idle():
            p = subprocess.run(["sinfo", "-h", "-o", "%t"], capture_output=True, text=True,
                               env=env)
            return p.returncode == 0 and p.stdout.strip() == "idle"
        wait_for(idle, 30, (d / "slurmctld.log").read_text()[-500:]
                 if (d / "slurmctld.log").exists() else "no log")
        yield env
    finally:
        for pid_file in reversed(started):  # only the daemons this test started, by their pid
            try:
                os.kill(int(pid_file.read_text().split()[0]), signal.SIGTERM)
            except (OSError, ValueError):
                pass


def test_a_class_graded_as_a_job_array(tmp_path, slurm):
    base = tmp_path / "class"
    subs, report = base / "subs", base / "report"
    base.mkdir()
    base.chmod(0o755)
    (subs / "ada").mkdir(parents=True)
    shutil.copy(ROOT / "labs/01-serial/solution/render.cpp", subs / "ada")
    shutil.copy(ROOT / "common/core/path_steps.h", subs / "ada")
    (subs / "bob").mkdir()
    (subs / "bob" / "render.cpp").write_text("int broken( {\n")
    (subs / "bob" / "path_steps.h").write_text("")
    p = subprocess.run(["make", "-s", "-C", str(ROOT), "grade-slurm", "LAB=01",
                        f"SUBMISSIONS={subs}", f"REPORT={report}"], capture_output=True,
                       text=True, env=slurm, timeout=120)
    assert p.returncode == 0, p.stdout + p.stderr
    assert "(2 tasks)" in p.stdout, p.stdout
    deadline = time.monotonic() + 900
    while not (report / "grades.csv").exists() and time.monotonic() < deadline:
        time.sleep(2)
    logs = "\n".join(f.read_text()[-800:] for f in report.glob("slurm-*.log"))
    assert (report / "grades.csv").exists(), logs
    rows = {r["student"]: r for r in csv.DictReader((report / "grades.csv").open())}
    assert rows["ada"]["score"] == "100", logs
    assert rows["bob"]["score"] == "0" and rows["bob"]["cause"].startswith("compile error")
    assert rows["(class: 2 students)"]["score"] == "mean 50.0"
    assert len(list(report.glob("slurm-*_*.log"))) == 2  # one log per array task


def test_the_scripts_say_what_they_ask_and_call_python_by_name(tmp_path):
    from grading.classes import slurm
    array, merge = slurm.scripts("03", tmp_path / "subs", tmp_path / "out", 4, "gpu", None,
                                 "00:45:00", "8G", "python3")
    for script in (array, merge):
        assert "#SBATCH --time=00:45:00" in script and "#SBATCH --mem=8G" in script
        assert "#SBATCH --partition=gpu" in script
        command = next(line for line in script.splitlines() if "-m grading.classes.batch" in line)
        assert command.startswith("python3 -m grading.classes.batch"), command
    default = slurm.scripts("03", tmp_path / "subs", tmp_path / "out", 4, None, None)[0]
    assert f"--time={slurm.DEFAULT_TIME}" in default and f"--mem={slurm.DEFAULT_MEM}" in default


def test_run_gpu_runs_a_command_as_a_slurm_job_and_prints_its_log(slurm):
    """`make run-gpu` (labs 05-07 without a GPU of one's own) on the test's one-node Slurm,
    which has no GPUs: GPU_GRES= asks for none. The job runs in the checkout and its log is
    printed when it ends."""
    p = subprocess.run(["make", "-s", "-C", str(ROOT), "run-gpu", "RUN=pwd",
                        "GPU_GRES=", "GPU_MEM=100M", "LAB=05"], capture_output=True, text=True,
                       env=slurm, timeout=300)
    for log in ROOT.glob("run-gpu-*.log"):
        log.unlink()
    assert p.returncode == 0, p.stdout + p.stderr
    assert str(ROOT) in p.stdout.splitlines() and "ended with status 0" in p.stdout, p.stdout


def test_only_flagged_submits_the_flagged_students_tasks(tmp_path, capsys):
    """ONLY=flagged, as the merge's log advises for a class graded through Slurm: the array
    holds the tasks of the students the report flagged or never graded, no others."""
    import json

    from grading.classes import batch, slurm
    subs, report = tmp_path / "subs", tmp_path / "report"
    for student in ("ann", "ben", "cy"):
        (subs / student).mkdir(parents=True)
        (subs / student / "render.cpp").write_text("int main;\n")
    waiting = {"score": 60, "tests": [{"name": "speed", "score": 0, "max_score": 40,
                                       "output": "marked for regrade",
                                       "extra_data": {"regrade": True, "provisional": 40}}]}
    final = {"score": 100, "tests": [{"name": "speed", "score": 40, "max_score": 40,
                                      "output": "1.9x"}]}
    for student, results in (("ann", waiting), ("ben", final)):
        (report / student).mkdir(parents=True)
        (report / student / "results.json").write_text(json.dumps(results))
    assert slurm.main(["01", str(subs), "--out", str(report), "--only", "flagged",
                       "--no-submit"]) == 0
    array = (report / "grade-array.sbatch").read_text()
    assert "#SBATCH --array=0,2\n" in array, array  # ann (flagged) and cy (never graded)
    batch.write_report(report, "01", {"ann": waiting, "ben": final}, None,
                       regrade="make grade-slurm")
    assert "regrade them: make grade-slurm ... ONLY=flagged" in capsys.readouterr().out
