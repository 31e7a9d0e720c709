#!/usr/bin/env bash
# Installs what the labs need and is missing; says what it installs; safe to run again.
# Compilers (g++, nvcc where present) come with the machine; this adds the JSON library,
# GoogleTest, Google Benchmark, OpenMPI, bubblewrap (the grader's sandbox), util-linux's setpriv,
# prlimit and taskset (the grader's sandbox where namespaces cannot be had:
# grading/README.md), python3-seccomp (the grader's tests stand in for Docker's seccomp
# profile with it: tests/grading/no_namespaces.py), Slurm (`make grade-slurm`, tested on a one-node Slurm the test starts),
# debootstrap (`make test-gradescope`'s base image), clang with LLVM's OpenMP (libomp-dev: its
# Archer tool lets ThreadSanitizer follow OpenMP, for lab 03's race check: `make lab03-race`)
# ccache (the tests compile the same sources many times: Makefile, TEST_ENV) and the Python packages of
# tools/requirements.txt at their pinned versions (matplotlib: the plots of `make tradeoff`;
# ruff and clang-format: `make lint`).
set -euo pipefail

debian_packages=(g++ make nlohmann-json3-dev libgtest-dev libbenchmark-dev openmpi-bin
                 libopenmpi-dev iproute2 bubblewrap util-linux python3-seccomp slurm-wlm
                 debootstrap clang libomp-dev ccache)
requirements="$(dirname "$0")/requirements.txt"
[ -f "$requirements" ] || { echo "deps: $requirements is missing" >&2; exit 2; }

missing=()
for p in "${debian_packages[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
    echo "deps: installing Debian packages: ${missing[*]}"
    sudo=""
    [ "$(id -u)" -eq 0 ] || sudo="sudo"
    $sudo apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends \
        "${missing[@]}" >/dev/null
fi

python=${PYTHON:-python3}
# The pinned requirements this Python lacks or has at another version.
mapfile -t missing_py < <("$python" - "$requirements" <<'PY'
import sys
from importlib import metadata
for line in open(sys.argv[1]):
    requirement = line.split("#")[0].strip()
    if requirement:
        name, version = requirement.split("==")
        try:
            installed = metadata.version(name)
        except metadata.PackageNotFoundError:
            installed = None
        if installed != version:
            print(requirement)
PY
)
if ((${#missing_py[@]})) && ! "$python" -m pip --version >/dev/null 2>&1 &&
        [ "$(command -v "$python")" = /usr/bin/python3 ]; then
    # The system's Python without pip (a fresh Debian, the Gradescope image): Debian's packages
    # of what the tests and the grader import, at Debian's versions (`make lint` needs pip).
    debian_py=()
    for m in pytest numpy matplotlib; do
        "$python" -c "import $m" 2>/dev/null || debian_py+=("python3-$m")
    done
    if ((${#debian_py[@]})); then
        echo "deps: installing Debian packages for $python: ${debian_py[*]}"
        sudo=""
        [ "$(id -u)" -eq 0 ] || sudo="sudo"
        DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends \
            "${debian_py[@]}" >/dev/null
    fi
    missing_py=()
fi
pip_install() {
    "$python" -m pip install --quiet --disable-pip-version-check "$@" 2>/dev/null ||
        "$python" -m pip install --quiet --disable-pip-version-check --break-system-packages "$@"
}
if ((${#missing_py[@]})); then
    echo "deps: installing Python packages for $python: ${missing_py[*]}"
    if ! pip_install "${missing_py[@]}"; then
        # An older Python than the pins support: the newest versions that install on it.
        echo "deps: the tested versions do not install for $python; installing the newest that do"
        pip_install "${missing_py[@]%%==*}"
    fi
fi
echo "deps: all present"
