#!/usr/bin/env bash
# Installs what the labs need and is missing; says what it installs; safe to run again.
# Compilers (g++, nvcc where present) come with the machine; this adds the JSON library,
# GoogleTest, Google Benchmark, OpenMPI, bubblewrap (the grader's sandbox), util-linux's setpriv,
# prlimit and taskset and python3-seccomp (the grader's sandbox where namespaces cannot be had:
# grading/README.md) and the Python test packages (matplotlib: the plots of `make tradeoff`).
set -euo pipefail

debian_packages=(g++ make nlohmann-json3-dev libgtest-dev libbenchmark-dev openmpi-bin
                 libopenmpi-dev iproute2 bubblewrap util-linux python3-seccomp)
python_modules=(pytest numpy matplotlib)

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
missing_py=()
for m in "${python_modules[@]}"; do
    "$python" -c "import $m" 2>/dev/null || missing_py+=("$m")
done
if ((${#missing_py[@]})) && ! "$python" -m pip --version >/dev/null 2>&1 &&
        [ "$(command -v "$python")" = /usr/bin/python3 ]; then
    # The system's Python without pip (a fresh Debian, the Gradescope image): Debian's packages.
    echo "deps: installing Debian packages for $python: ${missing_py[*]/#/python3-}"
    sudo=""
    [ "$(id -u)" -eq 0 ] || sudo="sudo"
    DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends \
        "${missing_py[@]/#/python3-}" >/dev/null
    missing_py=()
fi
if ((${#missing_py[@]})); then
    echo "deps: installing Python packages for $python: ${missing_py[*]}"
    "$python" -m pip install --quiet --disable-pip-version-check "${missing_py[@]}" 2>/dev/null ||
        "$python" -m pip install --quiet --disable-pip-version-check --break-system-packages \
            "${missing_py[@]}"
fi
echo "deps: all present"
