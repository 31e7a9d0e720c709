#!/usr/bin/env bash
# make tradeoff's GPU rows, measured on a GPU machine that has python3 with numpy
# but no matplotlib and no package registry (the course's H200 machine):
#   1. the machine: GPU, driver, nvcc, compilers, cores, load;
#   2. the JSON library from the carried .gpu-deps/ where the compiler has none (as
#      tools/gpu/check.sh does; `make deps` cannot run there);
#   3. build what the gpu plan runs, -j(cores), CUDA code for the GPU present only (cuda.mk
#      asks nvidia-smi for its compute capability: one architecture, not the six of its
#      fallback);
#   4. python3 -m tools.tradeoff --plan gpu --no-plots: lab01-ref (the efficiency baseline), lab03-ref
#      and lab03-simd-ref (OpenMP on every core), lab05-ref, its double and --use_fast_math
#      builds, lab06-ref and lab07-ref, and lab 01's double build, spp 1..4096 on the Cornell box and the extreme scene, the bias sweep;
#      CSV, Markdown and tradeoff.json, no PNGs; stopped at the time budget;
#   5. a short summary: the tables of the report.
#
#   bash tools/gpu/tradeoff.sh [DIR]     on the GPU machine; DIR defaults to $OUT (the device
#                                        call's folder), else build/reports/tradeoff-gpu
#   TRADEOFF_GPU_DRY_RUN=1 bash tools/gpu/tradeoff.sh DIR   steps 1-2 and what 3-4 would run
#   TRADEOFF_GPU_BUDGET=S   seconds for the whole script (default 270: a 5-minute call's
#                           limit less start-up and copying); the tool gets what the build
#                           leaves, less 15 s for the summary
#   TRADEOFF_PLAN=full      another plan of tools/tradeoff/run.py (full: not run there; the gpu
#                           plan took 124 s in all on the H200 machine, build included)
#
# DIR then holds tradeoff/ (tradeoff.md, tradeoff.csv, tradeoff-fits.csv, tradeoff-bias.csv,
# tradeoff.json), log.txt and machine.txt: 7 files. Back here, with matplotlib:
#   python3 -m tools.tradeoff --replot COPY_OF_DIR/tradeoff
# draws the plots and rewrites tradeoff.md with them.
# Exit status: the tool's (0 PASS, 1 a check failed, 2 bad input / no GPU / a render failed,
# 124 out of time: log.txt keeps every point measured until then).
set -uo pipefail
cd "$(dirname "$0")/../.." || exit 2
start=$(date +%s)
budget=${TRADEOFF_GPU_BUDGET:-270}
plan=${TRADEOFF_PLAN:-gpu}
dry=${TRADEOFF_GPU_DRY_RUN:-}
out=${1:-${OUT:-build/reports/tradeoff-gpu}}
mkdir -p "$out/tradeoff" || exit 2
out=$(cd "$out" && pwd)
log=$out/log.txt
: > "$log"
export PYTHONUNBUFFERED=1
exec 3>&1  # the terminal: say() writes there even inside a command whose output goes to the log
say() { echo "tradeoff_gpu: $*" | tee -a "$log" >&3; }
elapsed() { echo $(( $(date +%s) - start )); }

# ---- 1. the machine ---------------------------------------------------------------------
{
    echo "date: $(date -u +%FT%TZ)"
    echo "load average: $(cut -d' ' -f1-3 /proc/loadavg)"
    nvidia-smi --query-gpu=name,driver_version,compute_cap,memory.total,clocks.sm,clocks.max.sm --format=csv 2>&1
    nvcc --version 2>&1 | tail -2
    ${CXX:-g++} --version 2>&1 | head -1
    python3 -c 'import sys, numpy; print("python", sys.version.split()[0], "numpy", numpy.__version__)' 2>&1
    lscpu 2>/dev/null | grep -m1 'Model name'
    echo "cpus: $(nproc)"
    echo "mpirun: $(command -v mpirun || echo none)"
} > "$out/machine.txt"
tee -a "$log" < "$out/machine.txt"
load_start=$(cut -d' ' -f1 /proc/loadavg)

gpus=$(nvidia-smi --query-gpu=name --format=csv,noheader 2>/dev/null)
if [ -z "$gpus" ]; then
    say "no NVIDIA GPU here (nvidia-smi is missing or lists none): this script is for the GPU machine"
    exit 2
fi

# ---- 2. the JSON library ----------------------------------------------------------------
if ! echo '#include <nlohmann/json.hpp>' | ${CXX:-g++} -std=c++17 -x c++ -fsyntax-only - 2>/dev/null; then
    if [ -f .gpu-deps/include/nlohmann/json.hpp ]; then
        export CPATH=$PWD/.gpu-deps/include${CPATH:+:$CPATH}
        say "JSON library: the carried copy in .gpu-deps/include"
    else
        say "JSON library missing: run tools/gpu/check.sh --prepare where make deps works, and carry .gpu-deps"
        exit 2
    fi
fi

run() {  # run COMMAND...: shown in the log; only shown when TRADEOFF_GPU_DRY_RUN is set
    say "${dry:+would run: }$*"
    [ -n "$dry" ] || "$@"
}

# ---- 3. build ---------------------------------------------------------------------------
say "CUDA code for: $(make -s print-cuda-build-command | grep -o -- '-gencode [^ ]*' | tr '\n' ' ')"
# Every binary the plan may run (a full plan's variants are built by the tool itself). -k:
# what builds is built; the tool says in its report which renderer did not.
targets=(lab01-ref lab03-ref lab03-simd-ref lab01-ref-double lab05-ref lab05-ref-double lab05-ref-fast-math
         lab06-ref lab07-ref)
[ "$plan" = full ] && targets+=(lab02a-ref lab02-ref lab04-ref lab04-simd-ref)
run make -k -j"$(nproc)" "${targets[@]}" >> "$log" 2>&1 || say "make: some targets failed (the report says which)"
say "build done at $(elapsed) s"

# ---- 4. measure -------------------------------------------------------------------------
left=$(( budget - $(elapsed) - 15 ))
[ "$left" -gt 30 ] || { say "only $left s left of TRADEOFF_GPU_BUDGET=$budget after the build"; exit 124; }
note="Measured by tools/gpu/tradeoff.sh on the GPU machine (no matplotlib there: plots drawn \
afterwards from tradeoff.json by python3 -m tools.tradeoff --replot); load average ${load_start} at the \
start; GPU: ${gpus//$'\n'/, }."
say "python3 -m tools.tradeoff --plan $plan --no-plots, at most $left s"
run timeout "$left" python3 -m tools.tradeoff --plan "$plan" --no-plots --out "$out/tradeoff" \
    --note "$note" 2>&1 | tee -a "$log"
status=${PIPESTATUS[0]}
[ -n "$dry" ] && status=0
say "tradeoff.py exit status $status at $(elapsed) s"

# ---- 5. summary -------------------------------------------------------------------------
if [ -f "$out/tradeoff/tradeoff.md" ] && [ -z "$dry" ]; then
    awk '/^<details>/ { d = 1 } /^<\/details>/ { d = 0; next } /^## Bias/ { exit }
         !d && (/^## / || /^\| / || /^\*\*Verdict/ || /^- /)' "$out/tradeoff/tradeoff.md"
fi
[ "$status" = 124 ] && say "out of time: log.txt has every point measured until then"
say "files: $(cd "$out" && find . -type f | sort | tr '\n' ' ')"
exit "$status"
