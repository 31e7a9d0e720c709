"""The innermost wrapper of the user sandbox (labkit/sandbox.py, where namespaces cannot be
had): run by the system's Python as the sandbox user, after setpriv and prlimit, it loads a
libseccomp filter (python3-seccomp) and execs the submitted command, which inherits the
filter and cannot remove it.

    /usr/bin/python3 -I confine.py [--ro PATH]... [--rw PATH]... [--fixed-affinity]
                                   [--ip-sockets] -- COMMAND...
    /usr/bin/python3 -I confine.py --export-affinity-filter > FILTER.bpf

Where the kernel offers Landlock (and the container's seccomp profile lets it through), the
file system is confined too: read and execute only under the system's folders (/usr, /bin,
/lib*, /etc, /proc, /sys, /dev) and each --ro PATH, write only under each --rw PATH (its
scratch folder, the build's output folder), /dev/shm and device files such as /dev/null.
Without Landlock the permissions alone keep the grader's files from the sandbox user.

Refused, with EPERM: sockets other than AF_UNIX (no network), ptrace and reading or writing
other processes' memory, the kernel keyrings, every namespace and mount call (unshare,
setns, clone with a CLONE_NEW* flag, mount and the new mount API, pivot_root, chroot), bpf,
perf events, userfaultfd, module and kexec loading, reboot, swap and clock setting, and
POSIX message queues (mq_open: the queues live outside any folder the grader sweeps after a
run, labkit/boxes.py). clone3,
whose flags sit in memory a filter cannot read, answers ENOSYS, so the C library falls back
to clone, whose flags it can.

A run under mpirun needs IP sockets (--ip-sockets): OpenMPI's PMIx server, which every rank
reaches from MPI_Init, listens on loopback TCP only (PMIx 4 has no Unix-socket transport), so
there AF_INET and AF_INET6 are let through and no filter can tell loopback from the network
(the address a connect names lies in memory a filter cannot read). grading/README.md says
what that leaves open and where lab 04 is graded without it.

A run confined to some CPUs (Limits.cpu: lab 02's timed runs, on one) must not widen its
affinity again: with --fixed-affinity sched_setaffinity answers EPERM as well. Bubblewrap's
runs get that one rule alone, as the compiled filter --export-affinity-filter writes (bwrap
--seccomp FD): its namespaces are their other walls.
"""
import errno
import os
import signal
import sys

import seccomp  # python3-seccomp (Debian): the system's Python, not a virtual environment's

AF_UNIX, AF_INET, AF_INET6 = 1, 2, 10
CLONE_NEW_FLAGS = (0x00020000, 0x02000000, 0x04000000, 0x08000000, 0x10000000, 0x20000000,
                   0x40000000, 0x00000080)  # NS, CGROUP, UTS, IPC, USER, PID, NET, TIME
REFUSED = ("ptrace", "process_vm_readv", "process_vm_writev", "kcmp", "add_key",
           "request_key", "keyctl", "unshare", "setns", "mount", "umount2", "pivot_root",
           "chroot", "open_tree", "move_mount", "fsopen", "fsconfig", "fsmount", "fspick",
           "mount_setattr", "bpf", "perf_event_open", "userfaultfd", "init_module",
           "finit_module", "delete_module", "kexec_load", "kexec_file_load", "reboot",
           "swapon", "swapoff", "settimeofday", "clock_settime", "clock_adjtime", "adjtimex",
           "acct", "quotactl", "lookup_dcookie", "personality", "name_to_handle_at",
           "open_by_handle_at", "iopl", "ioperm", "mq_open")


def build_filter(fixed_affinity: bool = False, ip_sockets: bool = False) -> "seccomp.SyscallFilter":
    f = seccomp.SyscallFilter(defaction=seccomp.ALLOW)
    deny = seccomp.ERRNO(errno.EPERM)
    if fixed_affinity:
        f.add_rule(deny, "sched_setaffinity")
    for name in REFUSED:
        try:
            f.add_rule(deny, name)
        except (RuntimeError, ValueError, OSError):
            pass  # not a system call on this architecture
    allowed = (AF_UNIX, AF_INET, AF_INET6) if ip_sockets else (AF_UNIX,)
    for family in range(max(allowed) + 1):  # one rule a family: a rule compares once
        if family not in allowed:
            f.add_rule(deny, "socket", seccomp.Arg(0, seccomp.EQ, family))
    f.add_rule(deny, "socket", seccomp.Arg(0, seccomp.GT, max(allowed)))
    for flag in CLONE_NEW_FLAGS:
        f.add_rule(deny, "clone", seccomp.Arg(0, seccomp.MASKED_EQ, flag, flag))
    try:
        f.add_rule(seccomp.ERRNO(errno.ENOSYS), "clone3")
    except (RuntimeError, ValueError, OSError):
        pass
    return f


def affinity_filter() -> "seccomp.SyscallFilter":
    """sched_setaffinity refused and nothing else (a call of another architecture's ABI, such
    as int 0x80, kills the process: libseccomp's default for a foreign architecture)."""
    f = seccomp.SyscallFilter(defaction=seccomp.ALLOW)
    f.add_rule(seccomp.ERRNO(errno.EPERM), "sched_setaffinity")
    return f


# Landlock (linux/landlock.h), through the system calls: no Python binding ships with Debian.
LANDLOCK_CREATE_RULESET, LANDLOCK_ADD_RULE, LANDLOCK_RESTRICT_SELF = 444, 445, 446  # x86-64
EXECUTE, WRITE_FILE, READ_FILE, READ_DIR = 1, 2, 4, 8
ALL_ABI1 = (1 << 13) - 1      # every file-system right of Landlock's first ABI
READ = EXECUTE | READ_FILE | READ_DIR
SYSTEM_READ = ("/usr", "/bin", "/sbin", "/lib", "/lib32", "/lib64", "/libx32", "/etc",
               "/proc", "/sys", "/dev", "/run")
DEVICE_WRITE = READ | WRITE_FILE


def landlock(read_only, writable) -> bool:
    """Confines the file system (see the module's docstring); False where Landlock is not
    available, so nothing was confined."""
    import ctypes
    import platform
    if platform.machine() != "x86_64":
        return False
    libc = ctypes.CDLL(None, use_errno=True)
    libc.syscall.restype = ctypes.c_long
    if libc.syscall(LANDLOCK_CREATE_RULESET, None, ctypes.c_size_t(0), ctypes.c_uint32(1)) < 1:
        return False
    handled = ctypes.c_uint64(ALL_ABI1)
    ruleset = libc.syscall(LANDLOCK_CREATE_RULESET, ctypes.byref(handled), ctypes.c_size_t(8),
                           ctypes.c_uint32(0))
    if ruleset < 0:
        return False

    class PathBeneath(ctypes.Structure):
        _pack_ = 1
        _fields_ = [("allowed_access", ctypes.c_uint64), ("parent_fd", ctypes.c_int32)]

    def allow(path, rights):
        try:
            fd = os.open(path, os.O_PATH | os.O_CLOEXEC)
        except OSError:
            return
        rule = PathBeneath(rights, fd)
        if not os.path.isdir(path):  # a directory's rights on a file (or /dev/null) are invalid
            rule.allowed_access &= EXECUTE | WRITE_FILE | READ_FILE
        libc.syscall(LANDLOCK_ADD_RULE, ruleset, 1, ctypes.byref(rule), 0)
        os.close(fd)

    for path in SYSTEM_READ:
        allow(path, READ)
    for path in ("/dev/null", "/dev/zero", "/dev/full", "/dev/tty"):
        allow(path, DEVICE_WRITE)
    allow("/dev/shm", ALL_ABI1)
    for path in read_only:
        allow(path, READ)
    for path in writable:
        allow(path, ALL_ABI1)
    ok = libc.syscall(LANDLOCK_RESTRICT_SELF, ruleset, 0) == 0
    os.close(ruleset)
    return ok


def main(argv) -> int:
    if argv == ["--export-affinity-filter"]:
        sys.stdout.flush()
        affinity_filter().export_bpf(sys.stdout)
        return 0
    if "--" not in argv:
        print("usage: confine.py [--ro PATH]... [--rw PATH]... [--fixed-affinity] "
              "[--ip-sockets] -- COMMAND...", file=sys.stderr)
        return 2
    options, command = argv[:argv.index("--")], argv[argv.index("--") + 1:]
    read_only = [options[i + 1] for i, o in enumerate(options) if o == "--ro"]
    writable = [options[i + 1] for i, o in enumerate(options) if o == "--rw"]
    landlock(read_only, writable)
    build_filter(fixed_affinity="--fixed-affinity" in options,
                 ip_sockets="--ip-sockets" in options).load()
    # Python ignores SIGXFSZ and SIGPIPE, and an ignored signal stays ignored across exec: the
    # command gets the defaults, so a file over the size limit stops it as it would elsewhere.
    for sig in (signal.SIGXFSZ, signal.SIGPIPE):
        signal.signal(sig, signal.SIG_DFL)
    try:
        os.execvp(command[0], command)
    except OSError as e:
        print(f"{command[0]}: {e.strerror}", file=sys.stderr)
        return 127


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
