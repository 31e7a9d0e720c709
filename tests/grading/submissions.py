"""Hostile and broken "submissions" for the grader's tests: each is one executable file, which
is all the grader runs. Most are shell scripts; those that must render correctly are course
staff's kind of binary: a small program running a shell script, carrying the lab-01
reference as the double build a reference carries (labkit/double_twin.py). The sandbox runs
only what the grader staged (the sandbox shows a submission nothing of the repository, and
runs nothing a run wrote), and the grader stages a carried build of a binary it was given
beside it, naming it in RT_DOUBLE_TWIN.
"""
from __future__ import annotations

import contextlib
import pathlib
import shlex
import socket
import subprocess
import sys

from labkit.harness import ROOT

REFERENCE = ROOT / "lab01-ref"


def script(folder: pathlib.Path, body: str, name: str = "lab") -> pathlib.Path:
    path = folder / name
    path.write_text("#!/bin/sh\n" + body)
    path.chmod(0o755)
    return path


# A program that runs its script (a C string) with /bin/sh, with its own arguments in "$@".
RUNS_A_SCRIPT = r"""
#include <unistd.h>
static const char script[] = SCRIPT;
int main(int argc, char** argv) {
    char* args[argc + 3];
    args[0] = (char*)"sh";
    args[1] = (char*)"-c";
    args[2] = (char*)script;
    for (int i = 0; i < argc; ++i) args[i + 3] = argv[i];
    args[argc + 3] = 0;
    execv("/bin/sh", args);
    return 127;
}
"""


def carrying_reference(folder: pathlib.Path, body: str, name: str = "lab",
                       reference: pathlib.Path = REFERENCE) -> pathlib.Path:
    """A program running `body` with /bin/sh, with its arguments in "$@" and the lab-01
    reference (or `reference`) at ./ref's place: the staged copy of the reference it carries
    in the sandbox, the reference itself where the run is trusted."""
    import json
    head = (f'ref="${{RT_DOUBLE_TWIN:-{reference}}}"; unset RT_DOUBLE_TWIN\n'
            + body.replace("./ref", '"$ref"') + "\nexit $?\n")
    source = folder / f"{name}.c"
    source.write_text(RUNS_A_SCRIPT.replace("SCRIPT", json.dumps(head)))
    path = folder / name
    subprocess.run(["cc", "-O1", "-o", str(path), str(source)], check=True)
    subprocess.run(["objcopy", "--add-section", f"rt_double_twin={reference}", str(path)],
                   check=True)
    return path


# Sets $pfm and $scene to the values of --pfm and --scene in the arguments.
FIND_ARGS = """pfm=""; scene=""; prev=""
for a in "$@"; do
  [ "$prev" = "--pfm" ] && pfm="$a"
  [ "$prev" = "--scene" ] && scene="$a"
  prev="$a"
done
"""

# Overwrites the first float of the PFM named by $pfm with a NaN (little-endian 0x7fc00000).
POISON_FIRST_PIXEL = """offset=$(head -n 3 "$pfm" | wc -c)
printf '\\000\\000\\300\\177' | dd of="$pfm" bs=1 seek="$offset" conv=notrunc 2>/dev/null
"""


def nan_pixel(folder, only_in_scaled_scenes=False) -> pathlib.Path:
    """The reference with one NaN pixel in its image (in every run, or only in the scaled scenes
    of the scale-invariance check: the staged files have neutral names, so it looks for the
    tiny or huge numbers of a scene scaled by 1e-4, 1e3 or 1e5)."""
    condition = "grep -Eq '[0-9]e-|[0-9]{6,}[.]' \"$scene\"" if only_in_scaled_scenes \
        else "true"
    return carrying_reference(folder, f"""{FIND_ARGS}./ref "$@" || exit $?
if {condition}; then
{POISON_FIRST_PIXEL}fi""")


def lying_about_seconds(folder) -> pathlib.Path:
    """Serial and correct, but reports a render time of a millisecond."""
    return carrying_reference(folder, """./ref "$@" > ./out || exit $?
sed 's/"seconds": [0-9.e+-]*/"seconds": 0.001/' ./out""")


def exec_reference(folder) -> pathlib.Path:
    """The one-line wrapper: the reference's path is compiled into every build."""
    return script(folder, f'exec "{REFERENCE}" "$@"\n')


def hang_with_grandchild(folder, marker: str) -> pathlib.Path:
    """Forks a grandchild that keeps stdout open and would overwrite results later, then hangs."""
    return script(folder, f"""(sh -c 'sleep {marker}; echo late > results.json' &)
sleep {marker}
""")


def crash(folder) -> pathlib.Path:
    return script(folder, 'kill -SEGV $$\n')


def flood(folder, stream: str, size: int) -> pathlib.Path:
    redirect = ">&2" if stream == "stderr" else ""
    return script(folder, f"head -c {size} /dev/zero | tr '\\0' x {redirect}\n")


def non_utf8_stderr(folder) -> pathlib.Path:
    """Correct, but says something on stderr that is not UTF-8."""
    return carrying_reference(folder, """printf 'warning: \\377\\376 odd bytes\\n' >&2
./ref "$@" """)


def spy(folder, targets: dict[str, pathlib.Path]) -> pathlib.Path:
    """Correct, but first tries to read solutions and golden data, to overwrite golden data
    and to write outside its scratch folder; prints 'SPY <what>' on stderr for each success."""
    lines = []
    for what, path in targets.items():
        if what.startswith("write"):
            lines.append(f'(echo tampered > "{path}") 2>/dev/null && echo "SPY {what}" >&2')
        else:
            lines.append(f'cat "{path}" >/dev/null 2>&1 && echo "SPY {what}" >&2')
    return carrying_reference(folder, "\n".join(lines) + '\n./ref "$@"')


SOCKET_CLIENT = r"""
#include <arpa/inet.h>
#include <cstdio>
#include <cstdlib>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>
// Connects to 127.0.0.1:PORT (argv[1]) and exits 0 if that worked, 3 if not.
int main(int argc, char** argv) {
    int s = socket(AF_INET, SOCK_STREAM, 0);
    if (s < 0) { std::perror("socket"); return 3; }
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_port = htons(static_cast<unsigned short>(std::atoi(argc > 1 ? argv[1] : "1")));
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (connect(s, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) { std::perror("connect"); return 3; }
    std::puts("connected");
    return 0;
}
"""


@contextlib.contextmanager
def loopback_server():
    """A TCP server listening on 127.0.0.1 for socket_client: yields its port, as a word of a
    command line."""
    with socket.socket() as server:
        server.bind(("127.0.0.1", 0))
        server.listen()
        yield str(server.getsockname()[1])


def socket_client(folder) -> pathlib.Path:
    src = folder / "client.cpp"
    src.write_text(SOCKET_CLIENT)
    subprocess.run(["g++", "-O1", "-o", str(folder / "client"), str(src)], check=True)
    return folder / "client"


def golden_copier(folder) -> pathlib.Path:
    """Recognises the golden scenes by name and prints the stored golden images; anything else
    it cannot render."""
    import base64

    from labkit.harness import GOLDEN
    cases = []
    for scene in ("cornell", "showcase"):
        data = base64.b64encode((GOLDEN / scene / "golden.pfm").read_bytes()).decode()
        cases.append(f'  *{scene}.json) base64 -d > "$pfm" <<END\n{data}\nEND\n  ;;')
    return script(folder, FIND_ARGS + 'case "$scene" in\n' + "\n".join(cases) +
                  '\n  *) exit 1;;\nesac\necho \'{"lab": "copy", "seconds": 0.001}\'\n')


# The lab-01 reference with its image changed after the fact (`change`: a Python expression of
# `image`, the H x W x 3 array it wrote), as a mistake would have changed it: the symptoms'
# tests. It runs the repository's Python and reference, so it is graded trusted (outside the
# sandbox, which shows a submission none of that).
ALTERED = """#!/bin/sh
PYTHONPATH={root} exec {python} - "$@" <<'END'
import subprocess, sys
import numpy as np
from labkit.pfm import read_pfm, write_pfm
args = sys.argv[1:]
p = subprocess.run([{reference!r}, *args])
if p.returncode:
    sys.exit(p.returncode)
pfm = args[args.index("--pfm") + 1]
image = read_pfm(pfm)
write_pfm(pfm, {change})
END
"""


def altered_reference(folder: pathlib.Path, change: str,
                      reference: pathlib.Path = REFERENCE) -> pathlib.Path:
    path = folder / "lab"
    path.write_text(ALTERED.format(python=shlex.quote(sys.executable), root=shlex.quote(str(ROOT)),
                                   reference=str(reference), change=change))
    path.chmod(0o755)
    return path


def fewer_samples(folder, divisor: int = 4) -> pathlib.Path:
    """The reference asked for N paths per pixel renders N / divisor: cheaper, and its block
    means are still right."""
    return carrying_reference(
        folder,
        f"""prev=""
for a in "$@"; do
  shift
  if [ "$prev" = "--spp" ]; then set -- "$@" $(( (a + {divisor - 1}) / {divisor} )); else set -- "$@" "$a"; fi
  prev="$a"
done
./ref "$@" """,
    )


# Image changes for altered_reference: a 3x3 box blur, 8x8 blocks flattened to their mean
# (where the image divides into them), and a few finite values at the float limit.
BLUR = ("__import__('numpy').lib.stride_tricks.sliding_window_view("
        "__import__('numpy').pad(image, ((1, 1), (1, 1), (0, 0)), mode='edge'), (3, 3), "
        "axis=(0, 1)).mean(axis=(-1, -2)).astype('float32')")
FLATTEN = ("(image.reshape(image.shape[0] // 8, 8, image.shape[1] // 8, 8, 3).mean(axis=(1, 3))"
           ".repeat(8, 0).repeat(8, 1).astype('float32') if image.shape[0] % 8 == 0 == "
           "image.shape[1] % 8 else image)")
FLOAT_LIMIT = "__import__('numpy').where(image == image.max(), 3.3e38, image).astype('float32')"


def threads_on_every_cpu(folder, parallel_reference: pathlib.Path) -> pathlib.Path:
    """Lab 03's scalar OpenMP reference handed in for lab 02, widening its CPU affinity to
    every CPU of the machine (undoing a confinement to one), with a thread per CPU, and
    rendering whether or not the widening was allowed."""
    import os
    cpus = ",".join(str(c) for c in sorted(os.sched_getaffinity(0)))
    return carrying_reference(
        folder, f'taskset -a -p -c {cpus} $$ >/dev/null 2>&1\n'
                f'OMP_NUM_THREADS={len(cpus.split(","))} exec ./ref "$@"',
        reference=parallel_reference)


def widen_affinity_script() -> str:
    """A shell script that prints its allowed CPUs, tries to take every CPU of the machine
    (printing "widened" if it could) and prints them again."""
    import os
    cpus = ",".join(str(c) for c in sorted(os.sched_getaffinity(0)))
    return (f"grep Cpus_allowed_list /proc/self/status; "
            f"taskset -p -c {cpus} $$ >/dev/null 2>&1 && echo widened; "
            f"grep Cpus_allowed_list /proc/self/status")


# Prints, for every render, the published closed-form answer of the analytic scenes as they
# were before their parameters came from the grading secret (sphere interior: albedo 0.6,
# radius 2, intensity 3, the bounces asked), at the size asked: no renderer at all.
PUBLISHED_ANSWER = """#!/bin/sh
PYTHONPATH={root} exec {python} - "$@" <<'END'
import sys
import numpy as np
from labkit import scenes
from labkit.pfm import write_pfm
args = sys.argv[1:]
value = lambda flag, default: int(args[args.index(flag) + 1]) if flag in args else default
w, h, b = value("--width", 8), value("--height", 8), value("--bounces", 4)
radiance = scenes.sphere_interior_radiance(0.6, 2.0, 3.0, b)
write_pfm(args[args.index("--pfm") + 1], np.full((h, w, 3), radiance, dtype=np.float32))
print('{{"lab": "answers", "seconds": 0.001}}')
END
"""


def published_answers(folder: pathlib.Path) -> pathlib.Path:
    path = folder / "lab"
    path.write_text(PUBLISHED_ANSWER.format(python=shlex.quote(sys.executable),
                                            root=shlex.quote(str(ROOT))))
    path.chmod(0o755)
    return path
