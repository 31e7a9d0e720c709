#!/usr/bin/env bash
# Everything the CUDA labs need a GPU for, in one call (`make gpu-check OUT=DIR`):
#   1. the machine: GPU, driver, nvcc, host compiler;
#   2. build every CUDA target for the GPU present (plus lab 01's reference): every target of
#      every GPU lab in labs/labs.toml (labs 05-07, their benchmarks and lab 05's flag and
#      precision variants);
#   3. the compiler's resource report (make kernel-report) and the scene loads in the SASS;
#   4. the GPU tests (pytest), for real;
#   5. the benchmarks on the baseline, CUDA events, best and median of 5 after a warm-up, each
#      with its lab's speed targets (bench/gpu/speed_targets.h) judged: every kernel shape
#      of lab05-bench (DIR/bench.json), lab06-bench (bench-lab06.json) and lab07-bench
#      (bench-lab07.json); process time against kernel time;
#   6. accuracy of --use_fast_math and --fmad=false against the golden image and lab 01;
#   7. compute-sanitizer on labs 05-07; divergence and occupancy from Nsight Compute's
#      counters, where ncu can read them;
#   8. the wavefront labs (06, 07) on four scenes: labs/06-cuda-split/measure.sh, into
#      DIR/wavefront.tar.gz.
# Writes DIR/gpu-check.json (everything), DIR/summary.md (the tables, the speed targets
# first) and DIR/machine.txt, plus the logs; exits 0 only when every step that ran succeeded.
# `python3 -m tools.gpu.record --install DIR` makes DIR the record of the card it ran on
# (reference/gpu/h100/, reference/gpu/h200/: one record per card).
# GPU_CHECK_SKIP="kernel_report tests bench sanitizer ncu report wavefront" leaves any of those
# steps out (GPU_CHECK_KERNEL_REPORT=FILE: a `make kernel-report` made elsewhere for sm_90,
# build/kernel-report.md, stands in for the compiler's report), and
# GPU_CHECK_TESTS="FILE ..." runs only those test files: one call can be split into several
# that each fit a time limit (build outputs are reused; each call writes its own DIR).
#
#   tools/gpu/check.sh DIR          run it (on the GPU machine)
#   tools/gpu/check.sh --prepare    here, before sending the tree to a machine without the
#                                   JSON library: copies its headers into .gpu-deps/ (git-ignored
#                                   through .git/info/exclude; carry it with the tree)
set -uo pipefail
cd "$(dirname "$0")/../.."
root=$PWD

if [ "${1:-}" = "--prepare" ]; then
    src=$(echo '#include <nlohmann/json.hpp>' | ${CXX:-g++} -std=c++17 -x c++ -H -fsyntax-only - 2>&1 |
          grep -m1 'nlohmann/json.hpp' | sed 's/^\.* //; s|/nlohmann/json.hpp$||')
    [ -d "$src/nlohmann" ] || { echo "gpu_check: the JSON library (nlohmann/json.hpp) is not installed here (make deps)" >&2; exit 1; }
    mkdir -p .gpu-deps/include && cp -r "$src/nlohmann" .gpu-deps/include/
    mkdir -p .git/info && { grep -qx '/.gpu-deps/' .git/info/exclude 2>/dev/null || echo '/.gpu-deps/' >> .git/info/exclude; }
    echo "gpu_check: copied $src/nlohmann to .gpu-deps/include (carry .gpu-deps with the tree)"
    # The grader's sandbox (bubblewrap), for the GPU rubrics' tests: the package, unpacked there.
    if ls .gpu-deps/bubblewrap_*.deb >/dev/null 2>&1 || (cd .gpu-deps && apt-get download bubblewrap >/dev/null 2>&1); then
        echo "gpu_check: bubblewrap's package is in .gpu-deps"
    else
        echo "gpu_check: could not download bubblewrap's package; the GPU grading tests will skip there" >&2
    fi
    exit 0
fi

out=${1:?usage: tools/gpu/check.sh OUTDIR | --prepare}
mkdir -p "$out"
out=$(cd "$out" && pwd)
log=$out/log.txt
: > "$log"
export PYTHONUNBUFFERED=1
say() { echo "gpu_check: $*" | tee -a "$log"; }
# Step status, for the JSON: name=ok|failed|skipped
declare -A step
run_step() {  # run_step NAME COMMAND...: output to the log, status recorded
    local name=$1; shift
    say "$name: $*"
    if "$@" >> "$log" 2>&1; then step[$name]=ok; else step[$name]=failed; say "$name FAILED (see log.txt)"; fi
}

# ---- 1. the machine ---------------------------------------------------------------------
{
    echo "date: $(date -u +%FT%TZ)"
    nvidia-smi --query-gpu=name,driver_version,compute_cap,memory.total,clocks.sm,clocks.max.sm,power.limit --format=csv 2>&1
    nvcc --version 2>&1 | tail -2
    ${CXX:-g++} --version 2>&1 | head -1
    python3 --version 2>&1
    echo "cpus: $(nproc)"
} > /tmp/gpu-check-machine.txt
cat /tmp/gpu-check-machine.txt | tee -a "$log"
cp /tmp/gpu-check-machine.txt "$out/machine.txt"

# The scene loader needs the JSON library; a machine without it gets the carried copy.
if ! echo '#include <nlohmann/json.hpp>' | ${CXX:-g++} -std=c++17 -x c++ -fsyntax-only - 2>/dev/null; then
    if [ -f .gpu-deps/include/nlohmann/json.hpp ] && [ -w /usr/local/include ]; then
        # Where the compiler looks by itself, and where the grader's sandbox sees it (it shows
        # /usr read-only): the grader's tests build submitted sources in the sandbox.
        cp -r .gpu-deps/include/nlohmann /usr/local/include/
        say "JSON library: the carried copy, installed in /usr/local/include"
    elif [ -f .gpu-deps/include/nlohmann/json.hpp ]; then
        export CPATH=$root/.gpu-deps/include${CPATH:+:$CPATH}
        say "JSON library: the carried copy in .gpu-deps/include (the grader's sandboxed builds will not see it)"
    else
        say "JSON library missing: run tools/gpu/check.sh --prepare here and carry .gpu-deps"
    fi
fi

# The grader's sandbox: bubblewrap from the carried package when the machine has none.
if ! command -v bwrap >/dev/null && ls .gpu-deps/bubblewrap_*.deb >/dev/null 2>&1; then
    dpkg -x .gpu-deps/bubblewrap_*.deb /tmp/gpu-check-bwrap && export PATH=/tmp/gpu-check-bwrap/usr/bin:$PATH
    say "bubblewrap: the carried package ($(bwrap --version 2>&1))"
fi

# ---- 2. build ---------------------------------------------------------------------------
jobs=$(nproc)
start=$(date +%s)
# Every target of every GPU lab (labs/labs.toml), and lab 01's reference.
gpu_labs=$(python3 -m labkit.registry gpu-labs) || exit 2
gpu_targets=$(for lab in $gpu_labs; do python3 -m labkit.registry targets "$lab"; done)
run_step build make -j"$jobs" lab01-ref $gpu_targets
say "build took $(( $(date +%s) - start )) s"

# A step named in GPU_CHECK_SKIP is recorded as skipped and left out.
skipped() { [[ " ${GPU_CHECK_SKIP:-} " == *" $1 "* ]] && { step[$1]=skipped; say "$1: skipped (GPU_CHECK_SKIP)"; }; }

# ---- 3. the compiler's report -----------------------------------------------------------
if ! skipped kernel_report; then
    run_step kernel_report make -s kernel-report
    cp build/kernel-report.md /tmp/gpu-check-kernel-report.md 2>/dev/null
elif [ -n "${GPU_CHECK_KERNEL_REPORT:-}" ]; then
    cp "$GPU_CHECK_KERNEL_REPORT" /tmp/gpu-check-kernel-report.md && say "kernel_report: $GPU_CHECK_KERNEL_REPORT"
fi
# Which load instructions read the scene: LDC (constant bank), LDS (shared), LDG (global).
if command -v cuobjdump >/dev/null && [ -x lab05-bench ]; then
    cuobjdump -sass lab05-bench 2>/dev/null | awk '
        /Function :/ { f = $3 }
        /LDC|LDS|LDG|ULDC/ { for (i = 1; i <= NF; i++) if ($i ~ /^(LDC|LDS|LDG|ULDC)/) { split($i, a, "."); n[f "\t" a[1]]++ } }
        END { for (k in n) print k "\t" n[k] }' | sort > /tmp/gpu-check-sass-loads.tsv
fi

# ---- 4. the GPU tests -------------------------------------------------------------------
lab_tests=$(for lab in $gpu_labs; do printf 'tests/labs/test_lab%s.py ' "$lab"; done)
gpu_tests=${GPU_CHECK_TESTS:-"${lab_tests}tests/labs/test_device_code.py tests/labs/test_properties.py tests/grading/test_gpu_rubrics.py"}
rm -f /tmp/gpu-check-junit.xml
if ! skipped tests; then
    say "tests: pytest $gpu_tests"
    python3 -m pytest -q -rs -p no:cacheprovider $gpu_tests \
        --junitxml=/tmp/gpu-check-junit.xml > "$out/pytest.txt" 2>&1
    step[tests]=$([ $? -eq 0 ] && echo ok || echo failed)
    tail -3 "$out/pytest.txt" | tee -a "$log"
fi

# ---- 5-7. measurements ------------------------------------------------------------------
# The scene named as the repository names it: the record must not name this machine's paths.
baseline=common/scenes/cornell.json
if ! skipped bench && [ -x lab05-bench ]; then
    say "benchmark: lab05-bench --repeat 5 (the baseline)"
    ./lab05-bench --repeat 5 --scene "$baseline" > "$out/bench.json" 2>> "$log" && step[bench]=ok || step[bench]=failed
    # The main shapes: the reference (the small-scene kernel, 64 registers in this build), the
    # kinds kernel, and the small-scene shapes this build has (small-regs-64 is its reference).
    say "benchmark: lab05-bench-fast-math (--use_fast_math), the main shapes"
    ./lab05-bench-fast-math --repeat 5 --scene "$baseline" --only "${GPU_CHECK_FAST_MATH_VARIANTS:-reference,kinds-kernel,general,all-materials,scene-shared,no-register-cap,small-selects,small-no-cull,small-regs-56,small-no-register-cap,plain}" \
        > "$out/bench-fast-math.json" 2>> "$log" && step[bench_fast_math]=ok || step[bench_fast_math]=failed
fi
# The wavefront labs' references (and AoS with each thread storing its own record) and their
# targets on the baseline (measure.sh, step 8, has every configuration on four scenes).
for lab in lab06 lab07; do
    if [[ " ${GPU_CHECK_SKIP:-} " != *" bench "* ]] && [ -x $lab-bench ]; then
        say "benchmark: $lab-bench --repeat 5 (the baseline: the pools and the megakernel)"
        ./$lab-bench --repeat 5 --scene "$baseline" --only AoS,AoS-stored-by-thread,SoA,megakernel > "$out/bench-$lab.json" 2>> "$log" \
            && step[bench_$lab]=ok || step[bench_$lab]=failed
    fi
done

# The memory checker on a small render: no out-of-bounds access, no uninitialised read, no
# race on the shared-memory copy of the scene (lab05-bench's scene-shared shape).
if ! skipped sanitizer && command -v compute-sanitizer >/dev/null && [ -x lab05-ref ]; then
    say "compute-sanitizer: memcheck and initcheck on lab05-ref, memcheck on lab06-ref and lab07-ref, racecheck on scene-shared and on lab06-ref (its pushes stage records in shared memory), synccheck on lab06-ref"
    { compute-sanitizer --tool memcheck --error-exitcode 3 ./lab05-ref --quiet --width 48 --height 40 --spp 4 &&
      compute-sanitizer --tool initcheck --error-exitcode 3 ./lab05-ref --quiet --width 48 --height 40 --spp 4 &&
      compute-sanitizer --tool memcheck --error-exitcode 3 ./lab06-ref --quiet --width 48 --height 40 --spp 4 &&
      compute-sanitizer --tool memcheck --error-exitcode 3 ./lab07-ref --quiet --width 48 --height 40 --spp 4 &&
      compute-sanitizer --tool racecheck --error-exitcode 3 ./lab06-ref --quiet --width 48 --height 40 --spp 4 &&
      compute-sanitizer --tool synccheck --error-exitcode 3 ./lab06-ref --quiet --width 48 --height 40 --spp 4 &&
      compute-sanitizer --tool racecheck --error-exitcode 3 ./lab05-bench --width 48 --height 40 --spp 4 --repeat 1 --only scene-shared >/dev/null
    } >> "$log" 2>&1 && step[sanitizer]=ok || step[sanitizer]=failed
    say "compute-sanitizer: ${step[sanitizer]}"
fi

ncu_bin=$(command -v ncu || ls /opt/nvidia/nsight-compute/*/ncu /usr/local/cuda/bin/ncu 2>/dev/null | head -1)
if ! skipped ncu && [ -n "$ncu_bin" ] && [ -x lab05-bench ]; then
    say "counters: $ncu_bin on lab05-bench (64 spp, one timed run per shape)"
    metrics=smsp__thread_inst_executed_per_inst_executed.ratio,smsp__thread_inst_executed_pred_on_per_inst_executed.ratio,sm__warps_active.avg.pct_of_peak_sustained_active,smsp__issue_active.avg.pct_of_peak_sustained_active,smsp__inst_executed.sum,smsp__thread_inst_executed.sum,smsp__sass_thread_inst_executed_op_integer_pred_on.sum,smsp__sass_thread_inst_executed_op_fp32_pred_on.sum,smsp__sass_thread_inst_executed_op_fp64_pred_on.sum,sm__pipe_fma_cycles_active.avg.pct_of_peak_sustained_active,sm__inst_executed_pipe_alu.avg.pct_of_peak_sustained_active,gpu__time_duration.sum
    ncu_run() {  # ncu_run LABEL BENCH-ARGS...: one CSV per run, merged into the JSON below
        local label=$1; shift
        timeout 180 "$ncu_bin" --clock-control none --metrics "$metrics" --csv --page raw \
            ./lab05-bench --repeat 1 "$@" > "/tmp/gpu-check-ncu-$label.csv" 2>> "$log"
    }
    # reference: the small-scene kernel (lab05-ref on the Cornell box); kinds-kernel: the kernel
    # for the scene's kinds, which the other shapes change (tools/gpu/record.py's NCU_SHAPES).
    # lab05-bench runs the first shape the scene fits besides those named, so the one-bounce
    # run profiles both.
    ncu_run cornell --spp 64 --only "${GPU_CHECK_NCU_VARIANTS:-plain,reference,kinds-kernel,exact-rects,no-register-cap,triangles,quads,general,regenerate,together,claimed,scene-shared}" &&
    ncu_run cornell-1-bounce --spp 64 --bounces 1 --only reference,kinds-kernel &&
    ncu_run showcase --spp 64 --width 600 --height 600 --scene common/scenes/showcase.json --only reference &&
        step[ncu]=ok || step[ncu]=failed
fi

# Accuracy, process time, and the JSON and Markdown reports (tools/gpu/report.py).
if ! skipped report; then
    GPU_CHECK_METRICS=${metrics:-} python3 -m tools.gpu.report "$out" 2>&1 | tee -a "$log"
    step[report]=$([ "${PIPESTATUS[0]}" -eq 0 ] && echo ok || echo failed)
fi

# ---- 8. the wavefront labs --------------------------------------------------------------
if ! skipped wavefront && [ -x lab07-bench ]; then
    say "wavefront: labs/06-cuda-split/measure.sh (AoS, SoA and the megakernel on four scenes)"
    [[ " ${GPU_CHECK_SKIP:-} " == *" ncu "* ]] && export WAVEFRONT_STEPS=${WAVEFRONT_STEPS:-bench tables}
    WAVEFRONT_REPEAT=${WAVEFRONT_REPEAT:-2} bash labs/06-cuda-split/measure.sh /tmp/gpu-check-wavefront >> "$log" 2>&1 \
        && step[wavefront]=ok || step[wavefront]=failed
    cp /tmp/gpu-check-wavefront/wavefront.md "$out/" 2>/dev/null
    tar -C /tmp -czf "$out/wavefront.tar.gz" gpu-check-wavefront
fi

status=0
for s in "${!step[@]}"; do
    say "step $s: ${step[$s]}"
    [ "${step[$s]}" = ok ] || [ "${step[$s]}" = skipped ] || status=1
done
exit $status
