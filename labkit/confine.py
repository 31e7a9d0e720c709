"""The innermost wrapper of every sandboxed run (labkit/sandbox.py), in both sandboxes: run by
the system's Python as the sandbox's user (inside bubblewrap, or after setpriv and prlimit
where namespaces cannot be had), it confines the file system with Landlock, loads a
libseccomp filter (python3-seccomp) and execs the command, which inherits both and can
remove neither.

    /usr/bin/python3 -I confine.py [--ro PATH]... [--exec PATH]... [--rw PATH]...
                                   [--device PATH]... [--fixed-affinity] [--ip-sockets]
                                   -- COMMAND...

Only what the run was given may run. Where the kernel offers Landlock (and a container's
seccomp profile lets it through), files may be executed only from the system's folders (/usr,
/bin, /sbin, /lib*) and each --exec PATH (the staged binary's read-only folder); read only
there, under /etc, /proc, /sys, /dev and /run, and under each --ro PATH; written (never
executed) only under each --rw PATH (its scratch folder; inside bubblewrap its private /tmp
and /dev/shm), each --device PATH (a GPU's nodes) and device files such as /dev/null. So
nothing a run writes can be executed, and in the user sandbox nothing is written where a
later run could read it (/dev/shm and /tmp are shared there: the run's TMPDIR is its scratch).
Without Landlock the permissions alone keep the grader's files from the sandbox user, and the
grader's check of every executable mapping (labkit/sandbox.py, ExecCheck) finds a program
run from a written file.

The filter refuses, with EPERM, what would run code that is no file of the system's or the
staged binary: memfd_create without MFD_NOEXEC_SEAL (an executable memory file), execveat
(fexecve), anonymous memory mapped executable (mmap with PROT_EXEC and MAP_ANONYMOUS, and
mprotect or pkey_mprotect adding PROT_EXEC, which a loader of its own would need), and SysV
shared memory attached executable (shmat with SHM_EXEC). A file mapped executable by hand
(ld.so run on a written file) is what the grader's check sees.

Refused too: sockets other than AF_UNIX (no network), ptrace and reading or writing other
processes' memory, the kernel keyrings, every namespace and mount call (unshare, setns, clone
with a CLONE_NEW* flag, mount and the new mount API, pivot_root, chroot: so no run can show
the grader's check another file at a system path), bpf, perf events, userfaultfd, module and
kexec loading, reboot, swap and clock setting, and POSIX message queues (mq_open: the queues
live outside any folder the grader sweeps after a run, labkit/boxes.py). clone3, whose flags
sit in memory a filter cannot read, answers ENOSYS, so the C library falls back to clone,
whose flags it can.

A run under mpirun needs IP sockets (--ip-sockets): OpenMPI's PMIx server, which every rank
reaches from MPI_Init, listens on loopback TCP only (PMIx 4 has no Unix-socket transport), so
there AF_INET and AF_INET6 are let through and no filter can tell loopback from the network
(the address a connect names lies in memory a filter cannot read). grading/README.md says
what that leaves open and where lab 04 is graded without it. Inside bubblewrap, whose network
namespace holds only its own loopback, IP sockets are always let through.

A run confined to some CPUs (Limits.cpu: lab 02's timed runs, on one) must not widen its
affinity again: with --fixed-affinity sched_setaffinity answers EPERM as well.
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


PROT_EXEC, MAP_ANONYMOUS, MFD_NOEXEC_SEAL, SHM_EXEC = 0x4, 0x20, 0x8, 0o100000


def build_filter(fixed_affinity: bool = False, ip_sockets: bool = False) -> "seccomp.SyscallFilter":
    f = seccomp.SyscallFilter(defaction=seccomp.ALLOW)
    deny = seccomp.ERRNO(errno.EPERM)
    if fixed_affinity:
        f.add_rule(deny, "sched_setaffinity")
    # Code that is no file: an executable memory file, fexecve, anonymous executable memory.
    f.add_rule(deny, "memfd_create", seccomp.Arg(1, seccomp.MASKED_EQ, MFD_NOEXEC_SEAL, 0))
    f.add_rule(deny, "execveat")
    f.add_rule(deny, "mmap", seccomp.Arg(2, seccomp.MASKED_EQ, PROT_EXEC, PROT_EXEC),
               seccomp.Arg(3, seccomp.MASKED_EQ, MAP_ANONYMOUS, MAP_ANONYMOUS))
    for name in ("mprotect", "pkey_mprotect"):
        f.add_rule(deny, name, seccomp.Arg(2, seccomp.MASKED_EQ, PROT_EXEC, PROT_EXEC))
    f.add_rule(deny, "shmat", seccomp.Arg(2, seccomp.MASKED_EQ, SHM_EXEC, SHM_EXEC))
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


# Landlock (linux/landlock.h), through the system calls: no Python binding ships with Debian.
LANDLOCK_CREATE_RULESET, LANDLOCK_ADD_RULE, LANDLOCK_RESTRICT_SELF = 444, 445, 446  # x86-64
EXECUTE, WRITE_FILE, READ_FILE, READ_DIR = 1, 2, 4, 8
ALL_ABI1 = (1 << 13) - 1      # every file-system right of Landlock's first ABI
READ = READ_FILE | READ_DIR
RUN = EXECUTE | READ
WRITE = ALL_ABI1 & ~EXECUTE   # everything of a folder but running what is in it
SYSTEM_EXEC = ("/usr", "/bin", "/sbin", "/lib", "/lib32", "/lib64", "/libx32")
SYSTEM_READ = ("/etc", "/proc", "/sys", "/dev", "/run")
DEVICES = ("/dev/null", "/dev/zero", "/dev/full", "/dev/tty", "/dev/urandom", "/dev/random")


def landlock(read_only, runnable, writable, devices=()) -> bool:
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

    for path in SYSTEM_EXEC:
        allow(path, RUN)
    for path in SYSTEM_READ:
        allow(path, READ)
    for path in (*DEVICES, *devices):
        allow(path, READ_FILE | WRITE_FILE)
    for path in read_only:
        allow(path, READ)
    for path in runnable:
        allow(path, RUN)
    for path in writable:
        allow(path, WRITE)
    ok = libc.syscall(LANDLOCK_RESTRICT_SELF, ruleset, 0) == 0
    os.close(ruleset)
    return ok


PR_SET_NO_NEW_PRIVS = 38


def main(argv) -> int:
    if "--" not in argv:
        print("usage: confine.py [--ro PATH]... [--exec PATH]... [--rw PATH]... "
              "[--device PATH]... [--fixed-affinity] [--ip-sockets] -- COMMAND...",
              file=sys.stderr)
        return 2
    options, command = argv[:argv.index("--")], argv[argv.index("--") + 1:]

    def paths(flag):
        return [options[i + 1] for i, o in enumerate(options) if o == flag]
    import ctypes
    # Landlock and an unprivileged filter need it; setpriv and bubblewrap set it already.
    ctypes.CDLL(None).prctl(PR_SET_NO_NEW_PRIVS, 1, 0, 0, 0)
    landlock(paths("--ro"), paths("--exec"), paths("--rw"), paths("--device"))
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
