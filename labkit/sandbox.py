"""Running a submission's processes where they can do no harm, and measuring them from outside.

A submission is hostile until proven otherwise: it may hang, fork children that outlive it,
flood its output, fill the disk, read other students' code or the golden data, open sockets or
lie about its own speed. Every process the grader starts from a submission goes through
`Runner.run`, which

- (untrusted, the default) runs it under bubblewrap: as an unprivileged user (where the grader
  is root, a user of its own that no other run was: labkit/boxes.py), in its own user,
  PID, network, IPC and mount namespaces, seeing read-only exactly the files it was given, the
  system's libraries and MPI's files (and, for a GPU lab, the GPU: labkit/gpu.py), and
  writing only to a scratch folder of its own;
- runs nothing but what it was given: inside either sandbox labkit/confine.py confines the
  file system with Landlock (execute only the system's programs and the staged binary) and
  loads a seccomp filter refusing code that is no file (memory files, fexecve, anonymous
  executable memory); and while the run lasts the grader reads every executable mapping of
  every process of its tree (`ExecCheck`): one that is neither the staged binary nor a file
  of the system's stops the run as "ran a program it did not build";
- applies resource limits inside (CPU seconds, memory, file size, processes, open files);
- ends every process of its user after the run, whatever its state, and removes what that
  user left in the places anyone may write (/dev/shm, /tmp, SysV IPC: labkit/boxes.py), so
  that nothing of one run reaches a later one;
- kills the whole process tree when the wall-clock limit passes, when an output stream exceeds
  its cap, or when the grader itself dies (`--die-with-parent`; the PID namespace dies with its
  first process, so no grandchild survives);
- reads at most `Limits.output_bytes` of stdout and of stderr and says when it cut them;
- measures wall-clock and CPU time itself, from outside the sandbox.

`--trusted` (students grading their own code at home, where bubblewrap may be missing) runs the
same commands without the sandbox, still with the limits, the caps and the timing.
"""
from __future__ import annotations

import dataclasses
import os
import pathlib
import select
import shutil
import signal
import stat
import subprocess
import tempfile
import time
from typing import Sequence

from labkit import boxes, double_twin

NOBODY = 65534
# The sandbox's fixed layout: inputs appear read-only under /job, the scratch folder is the
# working directory and the only writable place besides a small /tmp.
JOB, SCRATCH = "/job", "/scratch"


@dataclasses.dataclass(frozen=True)
class Limits:
    wall_seconds: float = 60.0           # the whole process tree, measured by the grader
    cpu_seconds: int = 240               # RLIMIT_CPU, per process
    memory_bytes: int | None = 4 << 30   # RLIMIT_AS, per process (None: unlimited, for CUDA)
    file_bytes: int = 256 << 20          # RLIMIT_FSIZE: the largest file it may write
    scratch_bytes: int = 512 << 20       # what it may leave in scratch (checked after the run)
    tmp_bytes: int = 256 << 20           # size of the sandbox's /tmp (a tmpfs)
    processes: int = 256                 # RLIMIT_NPROC: threads count, so MPI and OpenMP fit
    open_files: int = 1024               # RLIMIT_NOFILE
    output_bytes: int = 1 << 20          # kept of stdout and of stderr, each
    cpu: int | None = None               # the one CPU the whole tree runs on (taskset, by the
                                         # grader), which it cannot widen: sched_setaffinity
                                         # is refused in the sandbox (labkit/confine.py)


@dataclasses.dataclass
class Outcome:
    """What the grader saw of one run."""
    returncode: int | None      # as the kernel reported it (negative: a signal); see failure
    stdout: str                 # decoded leniently: a stray byte is U+FFFD, never an error
    stderr: str
    wall_seconds: float         # measured by the grader around the whole tree
    cpu_seconds: float | None   # user + system time of the whole tree: in trusted runs the
                                # rusage of the reaped tree; in the sandbox (whose monitor does
                                # not reap it, so its rusage holds nothing of it) sampled by the
                                # grader from /proc every SAMPLE_SECONDS, so it misses at most
                                # the last interval of each process (TreeClock)
    killed: str | None = None   # why the grader killed it, e.g. "timed out after 60 s"
    cut: tuple[str, ...] = ()   # streams cut at the output cap
    busiest_thread_share: float = float("nan")  # of the tree's CPU time, its busiest thread's
                                                # (sampled by the grader: TreeClock)
    foreign: str | None = None  # what it ran that it was not given (ExecCheck), e.g.
                                # "/tmp/x (mapped executable by process 12)"

    @property
    def failure(self) -> str | None:
        """One phrase naming what went wrong, or None for a clean exit 0."""
        if self.killed:
            return self.killed
        if self.returncode == 0:
            return None
        return describe_exit(self.returncode)


SIGNAL_NAMES = {
    signal.SIGSEGV: "segmentation fault", signal.SIGBUS: "bus error",
    signal.SIGFPE: "floating-point exception", signal.SIGILL: "illegal instruction",
    signal.SIGABRT: "aborted", signal.SIGKILL: "killed", signal.SIGXCPU: "CPU time limit exceeded",
    signal.SIGXFSZ: "file size limit exceeded", signal.SIGTERM: "terminated",
}


def describe_exit(returncode: int) -> str:
    """'segmentation fault (signal 11)' rather than 'exited -11'. Inside the sandbox a shell
    reports a signal as 128 + its number, so both spellings are decoded."""
    sig = -returncode if returncode < 0 else returncode - 128 if 128 < returncode < 160 else 0
    if sig:
        try:
            name = SIGNAL_NAMES.get(signal.Signals(sig)) or signal.Signals(sig).name
        except ValueError:
            name = f"signal {sig}"
        return f"{name} (signal {sig})"
    return f"exited with status {returncode}"


def decode(data: bytes) -> str:
    return data.decode("utf-8", errors="replace")


def bwrap_path() -> str | None:
    return shutil.which("bwrap")


# The two isolations (grading/README.md): bubblewrap's namespaces where they can be had, else
# a dedicated unprivileged user (setpriv, prlimit, a seccomp filter: labkit/confine.py), which
# works where a container's seccomp profile refuses namespaces (Docker's default, Gradescope).
BUBBLEWRAP, USER = "bubblewrap", "user"
DESCRIPTIONS = {
    BUBBLEWRAP: "bubblewrap (user, PID, network, IPC and mount namespaces; seccomp filter"
                "{landlock})",
    USER: "a user of its own for each run (setpriv, prlimit, seccomp filter{landlock}; no "
          "namespaces here; IP sockets only under mpirun)",
}
# OpenMPI's launchers: their PMIx server and every rank's MPI_Init talk over loopback TCP.
MPI_LAUNCHERS = ("mpirun", "mpiexec")
SYSTEM_PYTHON = "/usr/bin/python3"  # runs labkit/confine.py, seen in either sandbox

_probe_result: list[str | None] = []
_isolation: list[str] = []


def probe() -> str | None:
    """None when a sandbox works here, else one line saying why neither can be had (checked
    once). GRADING_SANDBOX=bubblewrap or =user asks for one of them only."""
    if not _probe_result:
        _probe_result.append(_probe())
    return _probe_result[0]


def isolation() -> str:
    """Which sandbox untrusted runs use (after a successful probe())."""
    return _isolation[0] if _isolation else BUBBLEWRAP


def description() -> str:
    return DESCRIPTIONS[isolation()].format(
        landlock=", Landlock" if landlock_available() else "; no Landlock on this kernel")


def landlock_available() -> bool:
    """Whether the kernel (and a container's seccomp profile) offers Landlock (x86-64)."""
    import ctypes
    import platform
    if platform.machine() != "x86_64":
        return False
    libc = ctypes.CDLL(None, use_errno=True)
    libc.syscall.restype = ctypes.c_long
    return libc.syscall(444, None, ctypes.c_size_t(0), ctypes.c_uint32(1)) >= 1


def _probe() -> str | None:
    wanted = os.environ.get("GRADING_SANDBOX", "")
    if not shutil.which("prlimit"):
        return "prlimit (util-linux) is not installed: run `make deps`"
    reasons = []
    for kind, check in ((BUBBLEWRAP, _probe_bubblewrap), (USER, _probe_user)):
        if wanted and wanted != kind:
            continue
        reason = check()
        if reason is None:
            _isolation[:] = [kind]
            return None
        reasons.append(reason)
    return "; and ".join(reasons) or f"GRADING_SANDBOX={wanted} is neither bubblewrap nor user"


def _seccomp_active() -> bool:
    try:
        status = pathlib.Path("/proc/self/status").read_text()
    except OSError:
        return False
    return any(line.split() == ["Seccomp:", "2"] for line in status.splitlines())


def _trial_run(isolation):
    """A trivial command run under `isolation` alone: its result, or the OSError that stopped it."""
    _isolation[:] = [isolation]
    try:
        with Runner(trusted=False) as r:
            return r.run(["/bin/sh", "-c", "exit 0"], Limits(wall_seconds=20))
    except OSError as e:
        return e
    finally:
        _isolation.clear()


def _confinement_missing() -> str | None:
    """Why labkit/confine.py, which every sandboxed run goes through, cannot run here."""
    if not os.path.exists(SYSTEM_PYTHON):
        return f"{SYSTEM_PYTHON} is missing (the sandbox's seccomp filter runs on it)"
    return None


def _probe_bubblewrap() -> str | None:
    if not bwrap_path():
        return "bubblewrap (bwrap) is not installed: run `make deps`"
    reason = _confinement_missing()
    if reason:
        return reason
    out = _trial_run(BUBBLEWRAP)
    if isinstance(out, OSError):
        return f"bubblewrap cannot start: {out}"
    if out.returncode != 0:
        if _seccomp_active():
            return ("namespaces are refused here by a seccomp filter (as in a Docker container "
                    f"with its default profile), so bubblewrap cannot run "
                    f"({out.stderr.strip()[:120]})")
        return f"bubblewrap cannot create its namespaces here: {out.stderr.strip()[:200]}"
    return None


def _probe_user() -> str | None:
    if os.geteuid() != 0:
        return "the user sandbox needs the grader to run as root (to switch to its user)"
    for tool in ("setpriv", "prlimit"):
        if not shutil.which(tool):
            return f"{tool} (util-linux) is not installed: run `make deps`"
    reason = _confinement_missing()
    if reason:
        return reason
    out = _trial_run(USER)
    if isinstance(out, OSError):
        return f"the user sandbox cannot start: {out}"
    if out.returncode != 0:
        return f"the user sandbox cannot start: {(out.stderr.strip() or out.failure)[:200]}"
    return None


def unreachable(folder: pathlib.Path, uid: int, gid: int) -> pathlib.Path | None:
    """The first folder on the way to `folder` that user uid/gid cannot pass (no x), or None."""
    path = pathlib.Path(folder).resolve()
    for part in [*reversed(path.parents), path]:
        st = os.stat(part)
        bits = (stat.S_IXUSR if st.st_uid == uid else stat.S_IXGRP if st.st_gid == gid
                else stat.S_IXOTH)
        if not st.st_mode & bits:
            return part
    return None


def exposed(folder: pathlib.Path) -> bool:
    """Whether a sandboxed run could read `folder`: in the user sandbox without Landlock
    (labkit/confine.py) only permissions keep a run from a file, so a folder every user may
    enter is open to it. bubblewrap shows a run only what it mounts; Landlock only what it
    allows."""
    ids = boxes.pool()
    return (isolation() == USER and ids is not None and not landlock_available()
            and unreachable(folder, ids.start, ids.start) is None)


def hide_from_sandbox(folder: pathlib.Path) -> None:
    """In the user sandbox, nothing shows the grader's files but their permissions: a
    repository the sandbox's users can reach (as others: a box's user has no group but its
    own) is closed (mode 700) when the grader owns it."""
    ids = boxes.pool()
    if isolation() != USER or ids is None or unreachable(folder, ids.start, ids.start):
        return
    st = os.stat(folder)
    if st.st_uid == os.geteuid():
        os.chmod(folder, stat.S_IMODE(st.st_mode) & 0o700)


def _confine_script() -> str:
    """labkit/confine.py copied where the sandbox user can read it (the repository is closed
    to it), once per grader process."""
    if not _confine_copy:
        folder = pathlib.Path(tempfile.mkdtemp(prefix="grading-confine-"))
        folder.chmod(0o755)
        target = folder / "confine.py"
        shutil.copyfile(pathlib.Path(__file__).with_name("confine.py"), target)
        target.chmod(0o444)
        import atexit
        atexit.register(shutil.rmtree, folder, True)
        _confine_copy.append(str(target))
    return _confine_copy[0]


_confine_copy: list[str] = []


def user_processes(uid: int) -> list[int]:
    """Processes of `uid` with a thread alive (labkit/boxes.py)."""
    return boxes.processes(uid)


def system_mounts() -> list[str]:
    """Read-only system files a dynamically linked program (and mpirun) needs, whether /lib is
    a folder or merged into /usr. Nothing of /root, /home, /work or the grader's tree."""
    args = ["--ro-bind", "/usr", "/usr"]
    for top in ("/bin", "/sbin", "/lib", "/lib32", "/lib64", "/libx32"):
        if os.path.islink(top):
            args += ["--symlink", os.readlink(top), top]
        elif os.path.isdir(top):
            args += ["--ro-bind", top, top]
    for path in ("/etc/alternatives", "/etc/ld.so.cache", "/etc/ld.so.conf",
                 "/etc/ld.so.conf.d", "/etc/openmpi", "/etc/localtime",
                 "/sys/devices/system/cpu", "/sys/devices/system/node"):
        args += ["--ro-bind-try", path, path]  # hwloc (mpirun) reads the CPU topology
    return args


def _threads_of(uid: int) -> int:
    """Tasks (threads) this uid runs now: RLIMIT_NPROC counts all of them, so a non-root grader
    sets the limit above what it already uses."""
    count = 0
    for entry in os.scandir("/proc"):
        if entry.name.isdigit():
            try:
                if entry.stat().st_uid == uid:
                    count += len(os.listdir(f"/proc/{entry.name}/task"))
            except OSError:
                pass
    return count


class Runner:
    """Runs commands of one check: inputs staged once, each run in a fresh scratch folder.

        with Runner(trusted=False) as r:
            exe = r.input(binary)                 # the path to use in the command
            out = r.run([exe, "--pfm", r.scratch("image.pfm")], limits)
            data = r.output("image.pfm")          # bytes or None, read after the run
    """

    def __init__(self, trusted: bool, gpu: bool = False):
        self.trusted = trusted
        self.gpu = gpu  # a GPU lab's runs: the sandbox shows the GPU (labkit/gpu.py)
        self.user_mode = not trusted and isolation() == USER
        # A grader running as root runs each Runner as a user of its own (labkit/boxes.py),
        # whom the submission's files belong to; else as the grader's own user (bubblewrap's
        # namespaces are then the only walls).
        self.box, self._reset = None, False
        if not trusted and os.geteuid() == 0:
            self.box, fresh = boxes.new_box()
            self._reset = not fresh  # an id that came round: whatever it left goes first
        if self.user_mode and self.box is None:
            raise OSError("the user sandbox needs the grader to run as root")
        self.root = pathlib.Path(tempfile.mkdtemp(prefix="grading-"))
        os.chmod(self.root, 0o755)  # the unprivileged sandbox user must reach staged inputs
        self.close_to_others(self.root)
        self.inputs: dict[str, pathlib.Path] = {}
        self.env: dict[str, str] = {}  # set for every run (a staged double build's path)
        self.binds: list[tuple[str, bool]] = []  # (path, writable), mounted at the same path
        self._scratch: pathlib.Path | None = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        shutil.rmtree(self.root, ignore_errors=True)

    def close_to_others(self, folder: os.PathLike | str) -> None:
        """Only this run's user may enter `folder` (group of its box, mode 750): another run,
        another student's, finds nothing of this one's inputs or build there. Where the grader
        is not root there is no box, and bubblewrap's mounts alone show a run its files."""
        if self.box:
            os.chown(folder, -1, self.box[1])
            os.chmod(folder, 0o750)

    # ---- what the command may see ---------------------------------------------------------
    def input(self, path: os.PathLike | str) -> str:
        """Make a file readable to the command; returns its path as the command sees it. In the
        sandbox it is a private copy (the original's folder may be closed to the sandbox user,
        and the submission must not be able to change what later runs see)."""
        path = pathlib.Path(path).resolve()
        if self.trusted:
            return str(path)
        # A neutral name: a submission must not tell which check runs it from a file's name.
        name = f"{len(self.inputs)}{path.suffix if path.suffix in ('.json', '.pfm') else ''}"
        staged = self.root / "inputs" / name
        staged.parent.mkdir(mode=0o755, exist_ok=True)
        shutil.copyfile(path, staged)
        program = os.access(path, os.X_OK)
        os.chmod(staged, 0o555 if program else 0o444)
        if program and (twin := double_twin.stage(path, staged.parent, f"{name}-double")):
            self.env[double_twin.ENVIRONMENT] = self._inside(twin)
        return self._inside(staged)

    def _inside(self, staged: pathlib.Path) -> str:
        """Show a file staged in inputs/ to the command; its path as the command sees it."""
        inside = str(staged) if self.user_mode else f"{JOB}/{staged.name}"
        self.inputs[inside] = staged  # user sandbox: no mounts, read where it lies
        return inside

    def bind(self, path: os.PathLike | str, writable: bool = False) -> str:
        """Show a file or folder at its own path, without copying (a build needs the tree's
        layout). Read-only unless `writable`; a writable one is handed to the sandbox user."""
        path = str(pathlib.Path(path).resolve())
        if writable and self.box:
            for dirpath, dirs, files in os.walk(path):
                for name in [dirpath, *(os.path.join(dirpath, f) for f in dirs + files)]:
                    os.lchown(name, *self.box)
        self.binds.append((path, writable))
        return path

    def scratch(self, name: str = "") -> str:
        """A path in the run's scratch folder, as the command sees it."""
        base = SCRATCH if not (self.trusted or self.user_mode) else str(self._scratch_dir())
        return f"{base}/{name}" if name else base

    def _scratch_dir(self) -> pathlib.Path:
        if self._scratch is None:
            self._scratch = self.root / "scratch"
            self._scratch.mkdir(mode=0o700)
            if self.box:
                os.chown(self._scratch, *self.box)
        return self._scratch

    def output(self, name: str, limit: int = 256 << 20) -> bytes | None:
        """A regular file the run left in scratch (never through a symlink), or None."""
        try:
            fd = os.open(self._scratch_dir() / name, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK)
        except OSError:
            return None
        with os.fdopen(fd, "rb") as f:
            if not stat.S_ISREG(os.fstat(fd).st_mode):
                return None
            return f.read(limit + 1)[:limit + 1]

    # ---- running --------------------------------------------------------------------------
    def command(self, argv: Sequence[str], limits: Limits, env: dict[str, str]) -> list[str]:
        """The full command line: taskset (for limits.cpu), bubblewrap or setpriv (unless
        trusted), prlimit, labkit/confine.py (unless trusted), then argv."""
        nproc = limits.processes  # a box's user runs nothing else: the run's alone
        if self.box is None and os.geteuid() != 0:
            nproc += _threads_of(os.geteuid())
        # SIGXCPU at the CPU limit, SIGKILL a second later (for a program that ignores it)
        limit = [shutil.which("prlimit") or "prlimit",
                 f"--cpu={limits.cpu_seconds}:{limits.cpu_seconds + 1}",
                 f"--fsize={limits.file_bytes}", f"--nofile={limits.open_files}", "--core=0"]
        if limits.memory_bytes:
            limit.append(f"--as={limits.memory_bytes}")
        if self.box or os.geteuid() != 0:  # root ignores RLIMIT_NPROC
            limit.append(f"--nproc={nproc}")
        pin = [] if limits.cpu is None else [shutil.which("taskset") or "taskset", "-c",
                                             str(limits.cpu)]
        if self.trusted:
            return pin + limit + ["--", *argv]
        confine = [SYSTEM_PYTHON, "-I", _confine_script(), *self._confinement(argv, limits),
                   "--", *argv]
        if self.user_mode:
            uid, gid = self.box
            return [*pin, shutil.which("setpriv") or "setpriv", f"--reuid={uid}",
                    f"--regid={gid}", "--clear-groups", "--no-new-privs", "--inh-caps=-all", "--",
                    *limit, "--", *confine]
        scratch = self._scratch_dir()
        confine_folder = str(pathlib.Path(_confine_script()).parent)
        cmd = [bwrap_path() or "bwrap", "--unshare-all", "--unshare-user",
               "--uid", str(NOBODY), "--gid", str(NOBODY), "--die-with-parent", "--new-session",
               "--cap-drop", "ALL", *system_mounts(), "--proc", "/proc", "--dev", "/dev",
               "--size", str(limits.tmp_bytes), "--tmpfs", "/tmp",
               "--bind", str(scratch), SCRATCH, "--chdir", SCRATCH,
               "--ro-bind", confine_folder, confine_folder, "--clearenv"]
        for inside, outside in self.inputs.items():
            cmd += ["--ro-bind", str(outside), inside]
        for path, writable in self.binds:
            cmd += ["--bind" if writable else "--ro-bind", path, path]
        if self.gpu:  # after --dev /dev and --clearenv, which it adds to
            from labkit.gpu import sandbox_args
            cmd += sandbox_args()
        cmd += ["--remount-ro", "/"]  # bubblewrap's root is a tmpfs: no files may go there
        for key, value in {"PATH": "/usr/local/bin:/usr/bin:/bin", "HOME": SCRATCH,
                           "TMPDIR": "/tmp", "LANG": "C.UTF-8", **env}.items():
            cmd += ["--setenv", key, value]
        return pin + cmd + ["--", *limit, "--", *confine]

    def _confinement(self, argv: Sequence[str], limits: Limits) -> list[str]:
        """labkit/confine.py's options for this run: what it may read, run and write."""
        options = ["--ro", str(pathlib.Path(_confine_script()).parent)]
        if self.user_mode:
            options += ["--exec", str(self.root / "inputs"), "--rw", str(self._scratch_dir())]
            if os.path.basename(argv[0]) in MPI_LAUNCHERS:  # the grader's launcher, never a
                options.append("--ip-sockets")               # hand-in's name (confine.py)
        else:  # its own /tmp and /dev/shm, and a network namespace of its own
            options += ["--exec", JOB, "--rw", SCRATCH, "--rw", "/tmp", "--rw", "/dev/shm",
                        "--ip-sockets"]
        for path, writable in self.binds:
            options += ["--rw" if writable else "--ro", path]
        if self.gpu:
            from labkit import gpu
            options += [x for node in gpu.node_paths() for x in ("--device", node)]
            options += [x for folder in gpu.lib_dirs() for x in ("--ro", folder)]
            options.append("--thread-names")
        if limits.cpu is not None:
            options.append("--fixed-affinity")
        return options

    def exec_check(self) -> ExecCheck | None:
        """What this run's processes may map executable (None: trusted, nothing checked)."""
        if self.trusted:
            return None
        programs = {inside for inside, outside in self.inputs.items()
                    if os.access(outside, os.X_OK)}
        if not self.user_mode and bwrap_path():  # the grader's own launcher, wherever it lies
            programs.add(os.path.realpath(bwrap_path()))
        folders = list(SYSTEM_FOLDERS)
        if self.gpu:
            from labkit import gpu
            folders += gpu.lib_dirs()
        return ExecCheck(programs, tuple(folders))

    def run(self, argv: Sequence[str], limits: Limits = Limits(),
            env: dict[str, str] | None = None) -> Outcome:
        env = {**self.env, **(env or {})}
        if self.trusted:  # as before the sandbox: the caller's environment and folder
            full_env, cwd = {**os.environ, **env}, None
        elif self.user_mode:  # nothing of the grader's environment
            scratch = str(self._scratch_dir())
            full_env = {"PATH": "/usr/local/bin:/usr/bin:/bin", "HOME": scratch,
                        "TMPDIR": scratch, "LANG": "C.UTF-8", **env}
            if self.gpu:  # no mount namespace to show one GPU's node: name the grader's GPU
                full_env.update({k: os.environ[k] for k in
                                 ("CUDA_VISIBLE_DEVICES", "CUDA_DEVICE_ORDER") if k in os.environ})
            if os.path.basename(argv[0]) in MPI_LAUNCHERS:
                # OpenMPI's shared memory in the run's scratch, not in the /dev/shm every user
                # shares (which the run may not write: labkit/confine.py)
                full_env.setdefault("OMPI_MCA_btl_vader_backing_directory", scratch)
            cwd = scratch
        else:
            full_env, cwd = None, self.root
        cmd = self.command(argv, limits, env)
        user = {}
        if self.box and not self.user_mode:  # the user sandbox switches users with setpriv
            user = dict(user=self.box[0], group=self.box[1], extra_groups=[])
        if self._reset:
            boxes.seal(*self.box)
        start = time.perf_counter()
        p = subprocess.Popen(cmd, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, env=full_env, cwd=cwd,
                             start_new_session=True, **user)
        try:
            outcome = _supervise(p, start, limits, self.exec_check())
        finally:
            if self.box:  # nothing of this run outlives it
                problems = boxes.seal(*self.box)
                self._reset = False
                if problems:
                    SWEEP_PROBLEMS.append(f"after a run of user {self.box[0]}: "
                                          + "; ".join(problems))
        if outcome.foreign:
            FOREIGN_CODE.append(outcome.foreign)
        if outcome.killed is None and outcome.returncode == 0:
            used = _tree_size(self._scratch_dir())
            if used > limits.scratch_bytes:
                outcome.killed = (f"left {used / 2**20:.0f} MiB in its scratch folder "
                                  f"(allowed {limits.scratch_bytes / 2**20:.0f} MiB)")
        return outcome


SAMPLE_SECONDS = 0.05
_CLOCK_TICKS = os.sysconf("SC_CLK_TCK")
# Every run the grader starts runs at this nice value, its sessions' autogroups and each of its
# threads alike, where the grader may raise priority (as root): beside another user's process
# burning a core, a parallel program at the default weight gets about one core's worth in all
# (its session shares the CPUs with the other session as one), so neither the reference nor a
# hand-in could show a speedup. Both sides of every timing run at the same value; a process may
# lower its own priority again (setsid, nice), never raise it. Not a real-time class: the
# grader and the system still run.
RUN_NICE = -10


# Where the system's programs and libraries lie: read-only in both sandboxes, and no run can
# mount anything over them (labkit/confine.py refuses every mount and namespace call).
SYSTEM_FOLDERS = ("/usr", "/bin", "/sbin", "/lib", "/lib32", "/lib64", "/libx32")
# The kernel's own executable mappings, which every process has.
KERNEL_MAPPINGS = ("[vdso]", "[vsyscall]", "[uprobes]")
# Every run that mapped code it was not given (ExecCheck), and every sweep after a run that
# left something (labkit/boxes.py), in this grader process: the grade reads them (grading/grade.py).
FOREIGN_CODE: list[str] = []
SWEEP_PROBLEMS: list[str] = []


class ExecCheck:
    """What a sandboxed run may have mapped executable: the staged programs (as the run sees
    their paths: /job/N in bubblewrap) and the files under the system's folders (and a GPU
    lab's driver library folders). The kernel shows each process's mappings with the paths of
    its own mount namespace (/proc/PID/maps); the sandbox's processes can change neither what
    lies at those paths nor the namespace. Anything else, an anonymous executable mapping
    (code made in memory), a memory file (/memfd:...), a file the run wrote, is foreign."""

    def __init__(self, programs: set[str], folders: tuple[str, ...]):
        self.programs = programs
        self.prefixes = tuple(folder.rstrip("/") + "/" for folder in folders)

    def foreign(self, pid: int) -> str | None:
        """The first executable mapping of `pid` the run was not given, described; None when
        every one is allowed or the process has gone."""
        try:
            with open(f"/proc/{pid}/maps", "rb") as f:
                maps = f.read()
        except OSError:
            return None  # it has ended (the next sample sees its children, if any)
        for line in maps.splitlines():
            fields = line.split(maxsplit=5)
            if len(fields) < 5 or b"x" not in fields[1]:
                continue
            path = fields[5].decode("utf-8", "replace") if len(fields) == 6 else ""
            if path in self.programs or path.startswith(self.prefixes):
                continue
            if fields[4] == b"0" and path in KERNEL_MAPPINGS:
                continue
            what = path or "executable memory that is no file"
            return f"{what} (mapped executable by process {pid})"
        return None


class TreeClock:
    """CPU time of every process descended from one pid, read from /proc by the grader (the
    processes cannot change what the kernel reports there): utime + stime of each process
    (all its threads) plus cutime + cstime (its reaped children). A process that ends is
    counted in its parent's cutime once reaped; `seconds` keeps the largest total seen.

    It also keeps each thread's own CPU time (/proc/PID/task/TID/stat; the last value seen of
    a thread that has ended), so that `busiest_thread_share` says how much of the work one
    thread did, whatever the load: a serial program does all of it on one thread, a parallel
    one shares it. The fraction's denominator is the most work seen: the largest tree total,
    or the sum of every thread's own time where that is larger (a child that has exited but
    is not yet reaped can drop out of one sample's tree total, which alone would make its
    sibling's share look whole). The last interval before the exit, which no sample sees, is
    missing from both sides.

    With `nice` (the grader is root) each sample also raises the tree's new sessions and
    threads to that priority (RUN_NICE says why)."""

    def __init__(self, pid: int, nice: int | None = None, exec_check: ExecCheck | None = None):
        self.pid = pid
        self.seconds = 0.0
        self.nice = nice
        self.exec_check = exec_check
        self.foreign: str | None = None  # the first foreign mapping seen (ExecCheck)
        self._threads: dict[tuple[int, int, int], int] = {}  # (pid, tid, start) -> ticks
        self._sessions: set[int] = set()  # sessions whose autogroup was raised
        self.busiest_thread_share = float("nan")

    def sample(self) -> None:
        parents: dict[int, int] = {}
        times: dict[int, int] = {}
        sessions: dict[int, int] = {}
        for entry in os.scandir("/proc"):
            if not entry.name.isdigit():
                continue
            try:
                with open(f"/proc/{entry.name}/stat", "rb") as f:
                    stat_line = f.read()
            except OSError:
                continue
            fields = stat_line[stat_line.rfind(b")") + 2:].split()
            pid = int(entry.name)
            parents[pid] = int(fields[1])
            sessions[pid] = int(fields[3])
            times[pid] = sum(int(v) for v in fields[11:15])  # utime stime cutime cstime
        tree, frontier = {self.pid}, [self.pid]
        children: dict[int, list[int]] = {}
        for pid, ppid in parents.items():
            children.setdefault(ppid, []).append(pid)
        while frontier:
            for child in children.get(frontier.pop(), []):
                if child not in tree:
                    tree.add(child)
                    frontier.append(child)
        ticks = sum(times.get(pid, 0) for pid in tree)
        self.seconds = max(self.seconds, ticks / _CLOCK_TICKS)
        for pid in tree:
            if pid in times:
                self._sample_threads(pid, sessions[pid])
                if self.exec_check and self.foreign is None:
                    self.foreign = self.exec_check.foreign(pid)
        work = max(self.seconds * _CLOCK_TICKS, sum(self._threads.values()))
        if work > 0:
            self.busiest_thread_share = min(1.0, max(self._threads.values(), default=0) / work)

    def _sample_threads(self, pid: int, session: int) -> None:
        if self.nice is not None and session not in self._sessions:
            self._sessions.add(session)
            try:
                with open(f"/proc/{pid}/autogroup", "w") as f:
                    f.write(str(self.nice))
            except OSError:
                pass  # a kernel without autogroups, or the process has gone
        for tid, fields in boxes.thread_fields(pid):
            key = (pid, tid, int(fields[19]))  # a reused thread id starts at another time
            ticks = int(fields[11]) + int(fields[12])  # this thread's utime + stime
            self._threads[key] = max(self._threads.get(key, 0), ticks)
            if self.nice is not None and int(fields[16]) > self.nice:
                try:
                    os.setpriority(os.PRIO_PROCESS, tid, self.nice)
                except OSError:
                    pass


def _tree_size(folder: pathlib.Path) -> int:
    total = 0
    for dirpath, _, files in os.walk(folder):
        for f in files:
            try:
                total += os.lstat(os.path.join(dirpath, f)).st_size
            except OSError:
                pass
    return total


def _kill_tree(p: subprocess.Popen) -> None:
    """SIGKILL the process group. In the sandbox that kills bubblewrap, whose PID namespace
    takes every descendant with it, even those that left the group."""
    try:
        os.killpg(p.pid, signal.SIGKILL)
    except (ProcessLookupError, PermissionError):
        pass


def _supervise(p: subprocess.Popen, start: float, limits: Limits,
               exec_check: ExecCheck | None = None) -> Outcome:
    """Read both streams up to the cap and wait for the exit within the wall limit; with
    `exec_check`, stop the tree at the first foreign executable mapping. The rusage holds the
    whole tree's CPU time in trusted mode only (see Outcome.cpu_seconds)."""
    deadline = start + limits.wall_seconds
    streams = {
        p.stdout.fileno(): ("stdout", bytearray()),
        p.stderr.fileno(): ("stderr", bytearray()),
    }
    for fd in streams:
        os.set_blocking(fd, False)
    pidfd = os.pidfd_open(p.pid)
    clock = TreeClock(p.pid, RUN_NICE if os.geteuid() == 0 else None, exec_check)
    killed, cut, exited_at, status, usage = None, [], None, None, None
    try:
        open_fds = set(streams)
        while True:
            timeout = deadline - time.perf_counter()
            if timeout <= 0 and killed is None and exited_at is None:
                killed = f"timed out after {limits.wall_seconds:g} s (wall clock)"
                _kill_tree(p)
            wait_on = list(open_fds) + ([pidfd] if exited_at is None else [])
            if not wait_on:
                break
            # After the exit, give stragglers (trusted mode: children keep pipes open) 1 s.
            limit = (
                max(timeout, 0.05)
                if exited_at is None
                else max(exited_at + 1 - time.perf_counter(), 0)
            )
            if exited_at is None:
                clock.sample()
                limit = min(limit, SAMPLE_SECONDS)
                if clock.foreign and killed is None:
                    killed = f"ran a program it did not build: {clock.foreign}"
                    _kill_tree(p)
            ready, _, _ = select.select(wait_on, [], [], limit)
            if not ready and exited_at is not None:
                _kill_tree(p)
                break
            for fd in ready:
                if fd == pidfd:
                    _, status, usage = os.wait4(p.pid, 0)
                    exited_at = time.perf_counter()
                    _kill_tree(p)  # anything left in the group (trusted mode) goes too
                    continue
                try:
                    chunk = os.read(fd, 1 << 16)
                except BlockingIOError:
                    continue
                if not chunk:
                    open_fds.discard(fd)
                    continue
                name, buf = streams[fd]
                room = limits.output_bytes - len(buf)
                buf += chunk[:max(room, 0)]
                if len(chunk) > room and name not in cut:
                    cut.append(name)
                    if killed is None:
                        killed = (f"wrote more than {limits.output_bytes // 1024} KiB on {name}: "
                                  f"output cut there and the program stopped")
                        _kill_tree(p)
    finally:
        if exited_at is None:  # interrupted (SIGTERM, Ctrl-C): the tree must not outlive us
            _kill_tree(p)
            _, status, usage = os.wait4(p.pid, 0)
        os.close(pidfd)
        p.stdout.close()
        p.stderr.close()
    end = exited_at or time.perf_counter()
    p.returncode = os.waitstatus_to_exitcode(status) if status is not None else None
    cpu = max(usage.ru_utime + usage.ru_stime if usage else 0.0, clock.seconds)
    (_, out), (_, err) = streams.values()
    return Outcome(p.returncode, decode(bytes(out)), decode(bytes(err)), end - start, cpu,
                   killed, tuple(cut), clock.busiest_thread_share, clock.foreign)
