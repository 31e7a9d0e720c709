"""The innermost wrapper of every sandboxed run (labkit/sandbox.py), in both sandboxes: run by
the system's Python as the sandbox's user (inside bubblewrap, or after setpriv and prlimit
where namespaces cannot be had), it confines the file system with Landlock, loads a seccomp
filter (a classic BPF program written here, so any Python 3 runs it, without a binding to
libseccomp) and execs the command, which inherits both and can remove neither.

    /usr/bin/python3 -I confine.py [--ro PATH]... [--exec PATH]... [--rw PATH]...
                                   [--device PATH]... [--thread-names] [--fixed-affinity]
                                   [--ip-sockets] -- COMMAND...

Only what the run was given may run. Where the kernel offers Landlock (and a container's
seccomp profile lets it through), files may be executed only from the system's folders (/usr,
/bin, /sbin, /lib*) and each --exec PATH (the staged binary's read-only folder); read only
there, under /etc, /proc, /sys, /dev and /run, and under each --ro PATH; written (never
executed) only under each --rw PATH (its scratch folder; inside bubblewrap its private /tmp
and /dev/shm), each --device PATH (a GPU's nodes) and device files such as /dev/null; with
--thread-names also the files of its own threads under /proc/self/task (the CUDA driver names
its threads, and does not start where it cannot). So nothing a run writes can be executed,
and in the user sandbox nothing is written where a later run could read it (/dev/shm and
/tmp are shared there: the run's TMPDIR is its scratch). Without Landlock the permissions
alone keep the grader's files from the sandbox user, and the grader's check of every
executable mapping (labkit/sandbox.py, ExecCheck) finds a program run from a written file.

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
import ctypes
import errno
import os
import signal
import struct
import sys

# The system calls the filter names, by their x86-64 numbers (the filter is written as a
# classic BPF program here, so any Python 3 runs it without a binding to libseccomp).
SYSCALLS = {
    "mmap": 9, "mprotect": 10, "shmat": 30, "socket": 41, "clone": 56, "ptrace": 101,
    "personality": 135, "pivot_root": 155, "adjtimex": 159, "chroot": 161, "acct": 163,
    "settimeofday": 164, "mount": 165, "umount2": 166, "swapon": 167, "swapoff": 168,
    "reboot": 169, "iopl": 172, "ioperm": 173, "init_module": 175, "delete_module": 176,
    "quotactl": 179, "sched_setaffinity": 203, "lookup_dcookie": 212, "clock_settime": 227,
    "mq_open": 240, "kexec_load": 246, "add_key": 248, "request_key": 249, "keyctl": 250,
    "unshare": 272, "perf_event_open": 298, "name_to_handle_at": 303,
    "open_by_handle_at": 304, "clock_adjtime": 305, "setns": 308, "process_vm_readv": 310,
    "process_vm_writev": 311, "kcmp": 312, "finit_module": 313, "memfd_create": 319,
    "kexec_file_load": 320, "bpf": 321, "execveat": 322, "userfaultfd": 323,
    "pkey_mprotect": 329, "io_uring_setup": 425, "io_uring_enter": 426,
    "io_uring_register": 427, "open_tree": 428, "move_mount": 429, "fsopen": 430,
    "fsconfig": 431, "fsmount": 432, "fspick": 433, "clone3": 435, "mount_setattr": 442,
}
AF_UNIX, AF_INET, AF_INET6 = 1, 2, 10
CLONE_NEW_FLAGS = (0x00020000, 0x02000000, 0x04000000, 0x08000000, 0x10000000, 0x20000000,
                   0x40000000, 0x00000080)  # NS, CGROUP, UTS, IPC, USER, PID, NET, TIME
# io_uring: its requests are no system calls, so no filter would see them.
REFUSED = ("ptrace", "process_vm_readv", "process_vm_writev", "kcmp", "add_key",
           "request_key", "keyctl", "unshare", "setns", "mount", "umount2", "pivot_root",
           "chroot", "open_tree", "move_mount", "fsopen", "fsconfig", "fsmount", "fspick",
           "mount_setattr", "bpf", "perf_event_open", "userfaultfd", "init_module",
           "finit_module", "delete_module", "kexec_load", "kexec_file_load", "reboot",
           "swapon", "swapoff", "settimeofday", "clock_settime", "clock_adjtime", "adjtimex",
           "acct", "quotactl", "lookup_dcookie", "personality", "name_to_handle_at",
           "open_by_handle_at", "iopl", "ioperm", "mq_open", "io_uring_setup",
           "io_uring_enter", "io_uring_register")
PROT_EXEC, MAP_ANONYMOUS, MFD_NOEXEC_SEAL, SHM_EXEC = 0x4, 0x20, 0x8, 0o100000

# Classic BPF (linux/filter.h, linux/seccomp.h).
LD_W_ABS, AND_K = 0x20, 0x54
JEQ_K, JGT_K, JGE_K, RET_K = 0x15, 0x25, 0x35, 0x06
RET_ALLOW, RET_KILL_PROCESS, RET_ERRNO = 0x7FFF0000, 0x80000000, 0x00050000
AUDIT_ARCH_X86_64, X32_SYSCALL_BIT = 0xC000003E, 0x40000000
NR, ARCH = 0, 4


def _arg(index: int) -> int:
    """Offset of a system call argument's low 32 bits in struct seccomp_data: what the calls
    filtered here read (ints, flags), whatever the upper half holds."""
    return 16 + 8 * index


def rules(fixed_affinity: bool = False, ip_sockets: bool = False) -> list[tuple]:
    """(system call, [(argument, mask, test, value)...], errno): the call is refused with
    errno when every test holds for (argument & mask); test is "eq" or "gt"."""
    found = []

    def deny(name, *tests, err=errno.EPERM):
        found.append((name, list(tests), err))
    if fixed_affinity:
        deny("sched_setaffinity")
    # Code that is no file: an executable memory file, fexecve, anonymous executable memory.
    deny("memfd_create", (1, MFD_NOEXEC_SEAL, "eq", 0))
    deny("execveat")
    deny("mmap", (2, PROT_EXEC, "eq", PROT_EXEC), (3, MAP_ANONYMOUS, "eq", MAP_ANONYMOUS))
    deny("mprotect", (2, PROT_EXEC, "eq", PROT_EXEC))
    deny("pkey_mprotect", (2, PROT_EXEC, "eq", PROT_EXEC))
    deny("shmat", (2, SHM_EXEC, "eq", SHM_EXEC))
    for name in REFUSED:
        deny(name)
    allowed = (AF_UNIX, AF_INET, AF_INET6) if ip_sockets else (AF_UNIX,)
    for family in range(max(allowed) + 1):
        if family not in allowed:
            deny("socket", (0, 0xFFFFFFFF, "eq", family))
    deny("socket", (0, 0xFFFFFFFF, "gt", max(allowed)))
    for flag in CLONE_NEW_FLAGS:
        deny("clone", (0, flag, "eq", flag))
    # clone3's flags sit in memory a filter cannot read: ENOSYS makes the C library use clone.
    deny("clone3", err=errno.ENOSYS)
    return found


def build_filter(fixed_affinity: bool = False, ip_sockets: bool = False) -> bytes:
    """The filter as a classic BPF program (struct sock_filter[]): another architecture's
    calls (int 0x80) and the x32 ABI's end the process; each refused call answers its errno;
    everything else is allowed."""
    program = [(LD_W_ABS, 0, 0, ARCH), (JEQ_K, 1, 0, AUDIT_ARCH_X86_64),
               (RET_K, 0, 0, RET_KILL_PROCESS), (LD_W_ABS, 0, 0, NR),
               (JGE_K, 0, 1, X32_SYSCALL_BIT), (RET_K, 0, 0, RET_KILL_PROCESS)]
    for name, tests, err in rules(fixed_affinity, ip_sockets):
        # Each rule: is it this call? then each test on its argument; all hold: refuse.
        # Whatever fails jumps past the rule's end, where the call's number is loaded again.
        body = []
        for index, mask, test, value in tests:
            body.append((LD_W_ABS, 0, 0, _arg(index)))
            if mask != 0xFFFFFFFF:
                body.append((AND_K, 0, 0, mask))
            body.append((JEQ_K if test == "eq" else JGT_K, 0, None, value))
        body.append((RET_K, 0, 0, RET_ERRNO | err))
        block = [(JEQ_K, 0, None, SYSCALLS[name])] + body
        end = len(block)  # the reload of the call's number that follows the block
        program += [(code, jt, end - k - 1 if jf is None else jf, k_)
                    for k, (code, jt, jf, k_) in enumerate(block)]
        program.append((LD_W_ABS, 0, 0, NR))
    program.append((RET_K, 0, 0, RET_ALLOW))
    return b"".join(struct.pack("<HBBI", *insn) for insn in program)


def load_filter(program: bytes) -> None:
    """Install `program` for this process and every one it starts (no new privileges)."""
    class SockFprog(ctypes.Structure):
        _fields_ = [("len", ctypes.c_ushort), ("filter", ctypes.c_char_p)]
    libc = ctypes.CDLL(None, use_errno=True)
    fprog = SockFprog(len(program) // 8, program)
    if libc.prctl(PR_SET_NO_NEW_PRIVS, 1, 0, 0, 0) != 0 or \
            libc.prctl(PR_SET_SECCOMP, SECCOMP_MODE_FILTER, ctypes.byref(fprog), 0, 0) != 0:
        raise OSError(ctypes.get_errno(), "the seccomp filter could not be loaded")


PR_SET_NO_NEW_PRIVS, PR_SET_SECCOMP, SECCOMP_MODE_FILTER = 38, 22, 2


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


def landlock(read_only, runnable, writable, devices=(), thread_names=False) -> bool:
    """Confines the file system (see the module's docstring); False where Landlock is not
    available, so nothing was confined."""
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
    if thread_names:  # this process's own threads, named by writing task/TID/comm
        allow("/proc/self/task", READ_FILE | WRITE_FILE)
    for path in read_only:
        allow(path, READ)
    for path in runnable:
        allow(path, RUN)
    for path in writable:
        allow(path, WRITE)
    ok = libc.syscall(LANDLOCK_RESTRICT_SELF, ruleset, 0) == 0
    os.close(ruleset)
    return ok


def main(argv) -> int:
    if "--" not in argv:
        print("usage: confine.py [--ro PATH]... [--exec PATH]... [--rw PATH]... "
              "[--device PATH]... [--thread-names] [--fixed-affinity] [--ip-sockets] -- "
              "COMMAND...",
              file=sys.stderr)
        return 2
    options, command = argv[:argv.index("--")], argv[argv.index("--") + 1:]

    def paths(flag):
        return [options[i + 1] for i, o in enumerate(options) if o == flag]
    # Landlock and an unprivileged filter need it; setpriv and bubblewrap set it already.
    ctypes.CDLL(None).prctl(PR_SET_NO_NEW_PRIVS, 1, 0, 0, 0)
    landlock(paths("--ro"), paths("--exec"), paths("--rw"), paths("--device"),
             thread_names="--thread-names" in options)
    try:
        load_filter(build_filter(fixed_affinity="--fixed-affinity" in options,
                                 ip_sockets="--ip-sockets" in options))
    except OSError as e:
        print(f"confine.py: {e.strerror}: {os.strerror(e.errno)}", file=sys.stderr)
        return 126
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
