"""A user of its own for every sandboxed run, and nothing of it left when the run ends.

As in isolate (the sandbox of the CMS contest system), where the grader is root each Runner
(labkit/sandbox.py; the grader makes one per run) is a box: a uid and gid of its own that
no account uses, handed out once from a pool (POOL, a counter kept under a lock, so that two
graders on one machine never share one, and the reference never runs as a user a hand-in
ran as). `seal(box)` runs before the run (a box is reset) and after it (a box is removed):

- every process of the box ends, whatever its state: `kill(-1, SIGKILL)` sent as the box's
  user reaches every process of that user at once (a new session, a process hidden from
  /proc's owner by PR_SET_DUMPABLE, one whose leader thread has ended), repeated until no
  task of any process with the box's uid is alive (/proc/PID/status, /proc/PID/task);
- every file and folder it owns in the places any user may write (SHARED_PLACES, and the
  folders anyone may write below them) is removed;
- every SysV shared memory segment, message queue and semaphore set it owns or made is
  removed (/proc/sysvipc). POSIX message queues it cannot make (labkit/confine.py refuses
  mq_open in the user sandbox; bubblewrap's runs have an IPC namespace of their own).

A box's user has no name: programs that look one up (getpwuid) get none, as they get none
in bubblewrap's sandbox, whose /etc/passwd is not shown.
"""
from __future__ import annotations

import contextlib
import ctypes
import fcntl
import os
import pathlib
import shutil
import signal
import stat
import subprocess
import time

# Ids far above any account's and below 2^31 (some programs keep a uid in a signed int);
# where a user namespace maps fewer ids (a rootless container maps 65536), FALLBACK_POOL, the
# ids of that window no account or group holds.
POOL = range(1_800_000_000, 2_000_000_000)
FALLBACK_POOL = range(50_000, 60_000)
# Where the next box's id is kept: root's alone (mode 700). /run is emptied at each boot,
# /var/lib is not: there ids are not handed out again after a reboot either.
STATE_FOLDERS = ("/var/lib/prt-sandbox", "/run/prt-sandbox")
# The folders any user may write in on a Debian system (mode 1777); /dev/mqueue only where
# the POSIX message queues are mounted.
SHARED_PLACES = ("/dev/shm", "/tmp", "/var/tmp", "/run/lock", "/dev/mqueue")


def _mapped(path: str) -> list[range]:
    try:
        lines = pathlib.Path(path).read_text().splitlines()
    except OSError:
        return [range(0, 1 << 32)]  # a kernel without user namespaces maps every id
    return [range(int(f[0]), int(f[0]) + int(f[2])) for f in map(str.split, lines)]


def pool() -> range | None:
    """The ids boxes are drawn from: POOL where this user namespace maps all of them (as uid
    and as gid), else FALLBACK_POOL where it maps that; None where it maps neither."""
    maps = _mapped("/proc/self/uid_map"), _mapped("/proc/self/gid_map")
    for ids in (POOL, FALLBACK_POOL):
        if all(any(ids.start in m and ids.stop - 1 in m for m in extents) for extents in maps):
            return ids
    return None


def _state_file() -> pathlib.Path:
    """The counter's file, in a folder only root may change (refused where it is not so:
    a folder another user made first would let that user choose the next box)."""
    for folder in map(pathlib.Path, STATE_FOLDERS):
        try:
            folder.mkdir(mode=0o700, parents=True, exist_ok=True)
        except OSError:
            continue
        st = folder.lstat()
        if stat.S_ISDIR(st.st_mode) and st.st_uid == 0 and not st.st_mode & 0o077:
            return folder / "next-box"
    raise OSError(f"no folder for the sandbox's user ids: none of {', '.join(STATE_FOLDERS)} "
                  f"can be made root's alone")


def _taken(ident: int) -> bool:
    """An account or group holds the id (only the fallback's window may have them)."""
    import grp
    import pwd
    try:
        pwd.getpwuid(ident)
        return True
    except KeyError:
        pass
    try:
        grp.getgrgid(ident)
        return True
    except KeyError:
        return False


def new_box() -> tuple[tuple[int, int], bool]:
    """A uid and gid (the same number) no box had before, and whether no box ever had it
    (False once the counter has come round: that box must be reset before it runs). The
    counter starts again at the pool's first id only when the pool is spent (after hundreds
    of millions of runs; the fallback's after ten thousand), skipping ids an account holds."""
    ids = pool()
    if ids is None:
        raise OSError(f"this container's user namespace maps neither ids "
                      f"{POOL.start}-{POOL.stop - 1} nor {FALLBACK_POOL.start}-"
                      f"{FALLBACK_POOL.stop - 1}, from which the sandbox's users are drawn")
    fd = os.open(_state_file(), os.O_RDWR | os.O_CREAT | os.O_NOFOLLOW, 0o600)
    with os.fdopen(fd, "r+") as f:
        fcntl.flock(f, fcntl.LOCK_EX)
        fields = f.read().split()  # the next id, and how often the counter came round
        if len(fields) == 2 and all(x.isdigit() for x in fields) and int(fields[0]) in ids:
            ident, rounds = int(fields[0]), int(fields[1])
        else:  # none yet; or unreadable, where no id can be taken for fresh
            ident, rounds = ids.start, 0 if not fields else 1

        def after(ident: int, rounds: int) -> tuple[int, int]:
            return (ids.start, rounds + 1) if ident + 1 == ids.stop else (ident + 1, rounds)

        while _taken(ident):
            ident, rounds = after(ident, rounds)
        f.seek(0)
        f.truncate()
        f.write("{} {}\n".format(*after(ident, rounds)))
    return (ident, ident), rounds == 0


# ---- ending a box ------------------------------------------------------------------------

def thread_fields(pid: int | str):
    """(tid, fields) for each thread of a process that can be read now, the fields of its
    /proc/PID/task/TID/stat after the command name (fields[0] is its state; a name may
    hold spaces and parentheses, so the split starts after the last ')')."""
    try:
        tasks = os.listdir(f"/proc/{pid}/task")
    except OSError:
        return
    for tid in tasks:
        try:
            with open(f"/proc/{pid}/task/{tid}/stat", "rb") as f:
                line = f.read()
        except OSError:
            continue
        yield int(tid), line[line.rfind(b")") + 2:].split()


def _runs_as(pid: str, uid: int) -> bool:
    """Whether `uid` is one of a process's uids (real, effective, saved, file system: the
    owner of /proc/PID is root for a process that is not dumpable) and any of its threads is
    alive (a process whose leader thread ended reads "Z" in its stat, yet runs)."""
    try:
        with open(f"/proc/{pid}/status") as f:
            uids = next(line.split()[1:] for line in f if line.startswith("Uid:"))
    except (OSError, StopIteration):
        return False
    return str(uid) in uids and any(
        fields[0] not in (b"Z", b"X") for _, fields in thread_fields(pid))


def processes(uid: int) -> list[int]:
    """Processes with a live thread running with `uid` as any of their uids."""
    found = []
    for entry in os.scandir("/proc"):
        if entry.name.isdigit() and _runs_as(entry.name, uid):
            found.append(int(entry.name))
    return found


# kill(-1, SIGKILL), run as the box's user: procps's kill, or the system's Python where a
# slim container image has no procps.
KILL_ALL = ([shutil.which("kill"), "-s", "KILL", "--", "-1"] if shutil.which("kill") else
            ["/usr/bin/python3", "-I", "-S", "-c", "import os; os.kill(-1, 9)"])


def end_processes(uid: int, gid: int, seconds: float = 5.0) -> list[int]:
    """SIGKILL every process of the box until none has a live thread; what is still alive
    after `seconds` (a task stuck in the kernel), else []. Each pass signals, from root,
    every process a /proc sweep finds, then sends kill(-1) as the box's user (POSIX: every
    process it may signal at once, so no fork slips through), with a time limit: a process
    of the box the sweep missed may stop that sender (SIGSTOP to every process of its user),
    and the next pass's sweep finds it."""
    deadline = time.monotonic() + seconds
    while True:
        left = processes(uid)
        for pid in left:
            with contextlib.suppress(OSError):
                os.kill(pid, signal.SIGKILL)
        with contextlib.suppress(OSError, subprocess.TimeoutExpired):
            subprocess.run(KILL_ALL, user=uid, group=gid, extra_groups=[], timeout=0.5,
                           stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                           stderr=subprocess.DEVNULL)
        left = processes(uid)
        if not left or time.monotonic() > deadline:
            return left
        time.sleep(0.01)


def _remove_entry(remove, name: str, folder_fd: int, problems: list[str]) -> None:
    """`remove(name, dir_fd=folder_fd)` (os.unlink or os.rmdir): one already gone is fine,
    any other failure is said in `problems`."""
    try:
        remove(name, dir_fd=folder_fd)
    except FileNotFoundError:
        pass
    except OSError as e:
        problems.append(f"{name}: {e.strerror}")


def _remove_tree(parent_fd: int, name: str) -> list[str]:
    """Remove the folder `name` of the folder open as `parent_fd`, however deep, without
    recursion and without walking paths: each folder is opened from its parent's descriptor
    (never following a link), and a folder whose entries are gone is removed from its
    parent's. A chain thousands of folders deep costs as many steps, never a stack frame
    or a path longer than one name. Returns what could not be removed."""
    problems: list[str] = []
    # Each level: (its descriptor, its name in the level above, the entries left to look at).
    stack: list[tuple[int, str, list[os.DirEntry] | None]] = []

    def enter(at_fd: int, entry_name: str) -> bool:
        try:
            fd = os.open(entry_name, os.O_RDONLY | os.O_DIRECTORY | os.O_NOFOLLOW | os.O_CLOEXEC,
                         dir_fd=at_fd)
        except OSError as e:
            problems.append(f"{entry_name}: {e.strerror}")
            return False
        stack.append((fd, entry_name, None))
        return True

    if not enter(parent_fd, name):
        return problems
    try:
        while stack:
            fd, own_name, entries = stack[-1]
            if entries is None:
                try:
                    entries = list(os.scandir(fd))
                except OSError as e:
                    problems.append(f"{own_name}: {e.strerror}")
                    entries = []
                stack[-1] = (fd, own_name, entries)
            if entries:
                entry = entries.pop()
                try:
                    is_dir = entry.is_dir(follow_symlinks=False)
                except OSError:
                    is_dir = False
                if is_dir:
                    enter(fd, entry.name)
                else:
                    _remove_entry(os.unlink, entry.name, fd, problems)
                continue
            stack.pop()
            os.close(fd)
            _remove_entry(os.rmdir, own_name, stack[-1][0] if stack else parent_fd, problems)
    finally:
        for fd, _, _ in stack:
            os.close(fd)
    return problems


def remove_files(uid: int, places=SHARED_PLACES) -> list[str]:
    """Remove what the box owns in `places`, descending only into folders anyone may write
    (the only ones, besides its own, where a user without groups can make anything). Every
    folder is reached from its parent's descriptor, never by a path, and nothing recurses:
    no depth, name or failure stops the sweep. Returns what could not be removed."""
    problems: list[str] = []
    seen: set[tuple[int, int]] = set()
    folders: list[int] = []
    for place in places:
        with contextlib.suppress(OSError):
            folders.append(os.open(place, os.O_RDONLY | os.O_DIRECTORY | os.O_CLOEXEC))
    while folders:
        fd = folders.pop()
        try:
            st = os.fstat(fd)
            if (st.st_dev, st.st_ino) in seen:  # /var/lock is /run/lock
                continue
            seen.add((st.st_dev, st.st_ino))
            try:
                entries = list(os.scandir(fd))
            except OSError:
                continue
            for entry in entries:
                try:
                    est = entry.stat(follow_symlinks=False)
                except OSError:
                    continue
                # Its own by owner: a folder of the grader's that only the box may enter has
                # the box's group (labkit/sandbox.py, close_to_others) and is not the box's.
                if est.st_uid == uid:
                    if stat.S_ISDIR(est.st_mode):
                        problems += _remove_tree(fd, entry.name)
                    else:
                        _remove_entry(os.unlink, entry.name, fd, problems)
                elif stat.S_ISDIR(est.st_mode) and est.st_mode & stat.S_IWOTH:
                    with contextlib.suppress(OSError):
                        folders.append(os.open(entry.name, os.O_RDONLY | os.O_DIRECTORY |
                                               os.O_NOFOLLOW | os.O_CLOEXEC, dir_fd=fd))
        finally:
            os.close(fd)
    return problems


IPC_RMID = 0


def remove_ipc(uid: int) -> None:
    """Every SysV IPC object the box owns or made, as /proc/sysvipc lists them (all of this
    IPC namespace's, whatever their permissions)."""
    libc = ctypes.CDLL(None, use_errno=True)
    removers = {"shm": lambda i: libc.shmctl(i, IPC_RMID, None),
                "msg": lambda i: libc.msgctl(i, IPC_RMID, None),
                "sem": lambda i: libc.semctl(i, 0, IPC_RMID)}
    for kind, remove in removers.items():
        try:
            lines = pathlib.Path(f"/proc/sysvipc/{kind}").read_text().splitlines()
        except OSError:
            continue
        if not lines:
            continue
        header = lines[0].split()
        column = {name: header.index(name) for name in ("uid", "cuid") if name in header}
        for line in lines[1:]:
            fields = line.split()
            if len(fields) < len(header):
                continue
            if any(fields[i] == str(uid) for i in column.values()):
                remove(int(fields[1]))


def seal(uid: int, gid: int) -> list[str]:
    """End the box: its processes, then its files and IPC objects (none can make more). Each
    step runs whatever the one before met, and none raises: the run is graded or refused all
    the same, and its id is never handed out again (new_box). Returns what was left (processes
    still alive, files that could not be removed, a step that failed), normally []."""
    problems: list[str] = []
    steps = (("its processes", lambda: [f"process {pid} still alive"
                                        for pid in end_processes(uid, gid)]),
             ("its files", lambda: remove_files(uid)),
             ("its IPC objects", lambda: remove_ipc(uid) or []))
    for what, step in steps:
        try:
            problems += step()
        except Exception as e:  # noqa: BLE001 - the next step must run whatever this met
            problems.append(f"ending {what} failed: {type(e).__name__}: {e}")
    if len(problems) > 5:
        problems[5:] = [f"and {len(problems) - 5} more"]
    return problems
