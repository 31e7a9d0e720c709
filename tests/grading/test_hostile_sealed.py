"""Every run sealed, in both sandboxes (bubblewrap; the user sandbox, where namespaces are
refused): nothing one run leaves (files in shared places, SysV IPC, POSIX message queues,
processes) reaches a later run, each run is a user no other run was, and every limit
grading/README.md promises holds. Each case is one hostile run followed by an honest one,
as a hand-in's first render is followed by its timed runs, or by the reference's."""
import os
import signal

import pytest

from labkit import sandbox
from labkit.sandbox import Limits, Runner
from tests.grading import submissions as sub
from tests.grading.sandbox_modes import QUICK, py, sh


@pytest.mark.parametrize("place", ["/dev/shm", "/tmp", "/var/tmp", "/run/lock"])
def test_a_file_left_in_a_shared_place_is_gone_for_the_next_run(mode, place):
    """A serial hand-in that keeps its first render for its timed runs, or for another
    student's run, finds nothing there."""
    path = f"{place}/prt-left-{os.getpid()}"
    try:
        first = sh(f"echo first-render > {path} 2>/dev/null; mkdir {path}.d 2>/dev/null; "
                   f"echo nested > {path}.d/inner 2>/dev/null; exit 0")
        assert first.returncode == 0, first
        later = sh(f"cat {path} {path}.d/inner 2>/dev/null; exit 0")
        assert "first-render" not in later.stdout and "nested" not in later.stdout, later
        assert not os.path.exists(path) and not os.path.exists(f"{path}.d")
    finally:
        for left in (path, f"{path}.d/inner", f"{path}.d"):
            (os.rmdir if left.endswith(".d") else os.unlink)(left) \
                if os.path.lexists(left) else None


def test_sysv_ipc_left_by_a_run_is_gone_for_the_next_run(mode):
    made = sh("ipcmk -M 4096 -p 0666; ipcmk -Q -p 0666; ipcmk -S 1 -p 0666")
    ids = [line.rsplit(":", 1)[1].strip() for line in made.stdout.splitlines() if ":" in line]
    assert made.returncode == 0 and len(ids) == 3, made
    later = sh("for kind in shm msg sem; do echo $kind; cat /proc/sysvipc/$kind; done")
    seen, kind = set(), ""
    for line in later.stdout.splitlines():
        fields = line.split()
        if fields in (["shm"], ["msg"], ["sem"]):
            kind = fields[0]
        elif len(fields) > 1 and fields[1].isdigit():
            seen.add((kind, fields[1]))
    assert not seen & set(zip(("shm", "msg", "sem"), ids)), (ids, later.stdout)


MQUEUE = """import ctypes, os
libc = ctypes.CDLL(None, use_errno=True)
q = libc.mq_open(b"NAME", os.O_CREAT | os.O_RDWR, 0o666, None)
print("made" if q >= 0 else "refused", os.strerror(ctypes.get_errno()))
"""


def open_queue(name: bytes) -> bool:
    """Whether this process (the grader: root, where it may be) can open the queue."""
    import ctypes
    libc = ctypes.CDLL(None, use_errno=True)
    q = libc.mq_open(name, os.O_RDONLY)
    if q >= 0:
        os.close(q)
    return q >= 0


def test_a_message_queue_left_by_a_run_is_gone_for_the_next_run(mode):
    """Whether or not the kernel lets a run's later opens reach it (Landlock refuses the open
    and still lets the queue be made), no queue outlives the run that made it."""
    import ctypes
    name = f"/prt-left-queue-{os.getpid()}".encode()
    try:
        made = py(MQUEUE.replace("NAME", name.decode()))
        assert made.returncode == 0, made
        assert not open_queue(name), made.stdout
    finally:
        ctypes.CDLL(None).mq_unlink(name)


# A process that outlives its run: a new session, hidden from /proc's owner (not dumpable:
# /proc/PID then belongs to root), its leader thread ended (its stat reads "Z"), and a thread
# that stops every process it may signal: in the user sandbox, every later run of its user.
SURVIVOR = """import ctypes, os, signal, threading, time
parent = os.getpid()
if os.fork() == 0:
    os.setsid()
    quiet = os.open("/dev/null", os.O_RDWR)
    for fd in (0, 1, 2):
        os.dup2(quiet, fd)
    libc = ctypes.CDLL(None)
    libc.prctl(4, 0, 0, 0, 0)  # PR_SET_DUMPABLE

    def stop_everyone():
        while os.getppid() == parent:  # the run ends first
            pass
        while True:  # without a pause: whatever its user starts is stopped at once
            try:
                os.kill(-1, signal.SIGSTOP)
            except OSError:
                pass

    threading.Thread(target=stop_everyone, daemon=True).start()
    time.sleep(0.1)
    libc.syscall(60, 0)  # exit: this thread alone, the leader
time.sleep(0.5)  # the run ends once the survivor's leader thread has ended
print(os.getuid())
"""


def test_a_process_that_outlives_its_run_reaches_no_later_run(mode):
    """Nor does it stop the grader: ending the run's user must not wait on a process of that
    user, which the survivor stops as soon as it starts."""
    import concurrent.futures
    pool = concurrent.futures.ThreadPoolExecutor(1)
    with Runner(trusted=False) as r:
        box = getattr(r, "box", None)
        uid = box[0] if box else None
        job = pool.submit(r.run, ["/usr/bin/python3", "-I", "-c", SURVIVOR], QUICK)
        try:
            first = job.result(timeout=30)
            if uid is None and mode == sandbox.USER:
                uid = int(first.stdout.split()[0])
            assert first.wall_seconds < 5, first
            later = sh("sleep 1; echo finished")
            assert later.failure is None and later.stdout.split() == ["finished"], later
            if uid is not None:
                assert not sandbox.user_processes(uid), sandbox.user_processes(uid)
        finally:
            if uid is not None:  # on a grader that let it live: the machine must recover
                stray_processes_killed(uid)
            pool.shutdown()


def stray_processes_killed(uid: int) -> None:
    for entry in os.scandir("/proc"):
        if entry.name.isdigit():
            try:
                with open(f"/proc/{entry.name}/status") as f:
                    uids = next(line.split()[1:] for line in f if line.startswith("Uid:"))
            except (OSError, StopIteration):
                continue
            if str(uid) in uids:
                os.kill(int(entry.name), signal.SIGKILL)
                os.kill(int(entry.name), signal.SIGCONT)


def owner_of_what_it_writes() -> int:
    """The user a run is, as the machine sees it (outside bubblewrap's user namespace): the
    owner of a file it makes in its scratch folder."""
    with Runner(trusted=False) as r:
        out = r.run(["/bin/sh", "-c", "echo made > made"], QUICK)
        assert out.returncode == 0, out
        return (r.root / "scratch" / "made").stat().st_uid


def test_no_two_runs_are_the_same_user(mode):
    """The reference never runs as a user a hand-in ran as: each run is a user of its own."""
    if os.geteuid() != 0:
        pytest.skip("only a grader running as root hands runs to other users")
    seen = [owner_of_what_it_writes() for _ in range(3)]
    assert len(set(seen)) == 3, seen
    assert not {os.geteuid(), sandbox.NOBODY} & set(seen), seen


# ---- one student's renders replayed by another's grade, as in a batch (one secret) -------

# The key of a render: every argument but the two paths, and the scene's content.
RENDER_KEY = """key=$( (prev=""; for a in "$@"; do
  case "$prev" in --pfm|--scene) ;; *) printf '%s ' "$a" ;; esac; prev="$a"; done
  [ -n "$scene" ] && cat "$scene") | md5sum | cut -c1-32)
"""


def keeper(folder, kept: str):
    """Renders honestly (the reference), and keeps each image and summary in /dev/shm."""
    return sub.carrying_reference(folder, f"""{sub.FIND_ARGS}{RENDER_KEY}./ref "$@" > out
status=$?
cat out
mkdir -p {kept} 2>/dev/null && chmod 777 {kept}
cp "$pfm" {kept}/$key.pfm 2>/dev/null; cp out {kept}/$key.out 2>/dev/null
chmod 666 {kept}/* 2>/dev/null
exit $status""", name="keeper")


def replayer(folder, kept: str):
    """No renderer: prints whatever image another run kept for the same arguments."""
    return sub.script(folder, f"""{sub.FIND_ARGS}{RENDER_KEY}
cp {kept}/$key.pfm "$pfm" && cat {kept}/$key.out
""", name="replayer")


def test_a_hand_in_replaying_another_students_renders_scores_nothing(mode, tmp_path):
    from grading.grade import describe, grade
    kept = f"/dev/shm/prt-kept-{os.getpid()}"
    try:
        honest = grade("01", keeper(tmp_path, kept), tmp_path / "a", secret="one-batch")
        assert honest["score"] == 100, describe(honest)
        replayed = grade("01", replayer(tmp_path, kept), tmp_path / "b", secret="one-batch")
        assert replayed["score"] == 0, describe(replayed)
    finally:
        if os.path.isdir(kept):
            import shutil
            shutil.rmtree(kept)


# ---- the limits grading/README.md promises, each exceeded --------------------------------

FORKS = """import os, time
made = 0
for _ in range(300):
    try:
        if os.fork() == 0:
            time.sleep(2)
            os._exit(0)
        made += 1
    except OSError:
        break
print(made)
"""


def test_more_processes_than_the_limit_are_refused(mode):
    out = py(FORKS, Limits(wall_seconds=20))
    assert out.returncode == 0 and int(out.stdout) < Limits().processes, out


def test_more_memory_than_the_limit_is_refused(mode):
    out = py("bytearray(400 << 20); print('allocated')",
             Limits(wall_seconds=10, memory_bytes=256 << 20))
    assert "allocated" not in out.stdout and "MemoryError" in out.stderr, out


def test_a_file_larger_than_the_limit_is_cut(mode):
    out = sh("head -c 2000000 /dev/zero > big", Limits(wall_seconds=10, file_bytes=1 << 20))
    assert out.failure and "file size limit exceeded" in out.failure, out


def test_more_cpu_time_than_the_limit_is_stopped(mode):
    out = sh("while :; do :; done", Limits(wall_seconds=10, cpu_seconds=1))
    assert out.failure and "CPU time limit exceeded" in out.failure, out


def test_more_wall_time_than_the_limit_is_stopped(mode):
    out = sh("sleep 30", Limits(wall_seconds=0.5))
    assert out.failure == "timed out after 0.5 s (wall clock)" and out.wall_seconds < 5, out


def test_more_output_than_the_limit_is_cut(mode):
    out = sh("head -c 3000000 /dev/zero | tr '\\0' x", Limits(wall_seconds=10,
                                                               output_bytes=1 << 20))
    assert out.failure and "wrote more than 1024 KiB on stdout" in out.failure, out
    assert len(out.stdout) == 1 << 20


def test_more_open_files_than_the_limit_are_refused(mode):
    out = py("import os\nfds = []\ntry:\n    while len(fds) < 2000:\n"
             "        fds.append(os.open('/dev/null', os.O_RDONLY))\n"
             "except OSError as e:\n    print(len(fds), e.strerror)")
    assert "Too many open files" in out.stdout, out
    assert int(out.stdout.split()[0]) < Limits().open_files, out


def test_more_left_in_scratch_than_the_limit_is_refused(mode):
    out = sh("for i in 1 2 3; do head -c 600000 /dev/zero > f$i; done",
             Limits(wall_seconds=10, scratch_bytes=1 << 20))
    assert out.failure and "left 2 MiB in its scratch folder" in out.failure, out
