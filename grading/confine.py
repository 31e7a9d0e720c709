"""The innermost wrapper of the user sandbox (grading/sandbox.py, where namespaces cannot be
had): run by the system's Python as the sandbox user, after setpriv and prlimit, it loads a
libseccomp filter (python3-seccomp) and execs the submitted command, which inherits the
filter and cannot remove it.

    /usr/bin/python3 -I confine.py -- COMMAND...

Refused, with EPERM: sockets other than AF_UNIX (no network), ptrace and reading or writing
other processes' memory, the kernel keyrings, every namespace and mount call (unshare,
setns, clone with a CLONE_NEW* flag, mount and the new mount API, pivot_root, chroot), bpf,
perf events, userfaultfd, module and kexec loading, reboot, swap and clock setting. clone3,
whose flags sit in memory a filter cannot read, answers ENOSYS, so the C library falls back
to clone, whose flags it can.
"""
import errno
import os
import sys

import seccomp  # python3-seccomp (Debian): the system's Python, not a virtual environment's

AF_UNIX = 1
CLONE_NEW_FLAGS = (0x00020000, 0x02000000, 0x04000000, 0x08000000, 0x10000000, 0x20000000,
                   0x40000000, 0x00000080)  # NS, CGROUP, UTS, IPC, USER, PID, NET, TIME
REFUSED = ("ptrace", "process_vm_readv", "process_vm_writev", "kcmp", "add_key",
           "request_key", "keyctl", "unshare", "setns", "mount", "umount2", "pivot_root",
           "chroot", "open_tree", "move_mount", "fsopen", "fsconfig", "fsmount", "fspick",
           "mount_setattr", "bpf", "perf_event_open", "userfaultfd", "init_module",
           "finit_module", "delete_module", "kexec_load", "kexec_file_load", "reboot",
           "swapon", "swapoff", "settimeofday", "clock_settime", "clock_adjtime", "adjtimex",
           "acct", "quotactl", "lookup_dcookie", "personality", "name_to_handle_at",
           "open_by_handle_at", "iopl", "ioperm")


def build_filter() -> "seccomp.SyscallFilter":
    f = seccomp.SyscallFilter(defaction=seccomp.ALLOW)
    deny = seccomp.ERRNO(errno.EPERM)
    for name in REFUSED:
        try:
            f.add_rule(deny, name)
        except (RuntimeError, ValueError, OSError):
            pass  # not a system call on this architecture
    f.add_rule(deny, "socket", seccomp.Arg(0, seccomp.NE, AF_UNIX))
    for flag in CLONE_NEW_FLAGS:
        f.add_rule(deny, "clone", seccomp.Arg(0, seccomp.MASKED_EQ, flag, flag))
    try:
        f.add_rule(seccomp.ERRNO(errno.ENOSYS), "clone3")
    except (RuntimeError, ValueError, OSError):
        pass
    return f


def main(argv) -> int:
    if "--" not in argv:
        print("usage: confine.py -- COMMAND...", file=sys.stderr)
        return 2
    command = argv[argv.index("--") + 1:]
    build_filter().load()
    try:
        os.execvp(command[0], command)
    except OSError as e:
        print(f"{command[0]}: {e.strerror}", file=sys.stderr)
        return 127


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
