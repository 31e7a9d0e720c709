#!/usr/bin/env bash
# The session's third GPU call: the course report's own CUDA code timed on the H200 (built
# from a carried copy, not part of this repository) and the grader's GPU tests after the
# sandboxed-build change (EXTRA_TARGETS and EXTRA_TESTS were left empty).
# .gpu-deps/report/ (git-ignored, carried with the tree) held the course report's public
# code, its folders cuda_a, cuda_b, cuda_c and common, copied by hand from the report's
# repository ("Parallel Ray Tracer"); none of it is part of this repository.
export CPATH=$PWD/.gpu-deps/include
if ! command -v bwrap >/dev/null; then dpkg -x .gpu-deps/bubblewrap_*.deb /tmp/bw && export PATH=/tmp/bw/usr/bin:$PATH; fi
make -j16 lab01-ref lab05-ref lab06-ref lab07-ref ${EXTRA_TARGETS:-} > /tmp/build.log 2>&1 || { tail -20 /tmp/build.log; exit 1; }
R=.gpu-deps/report; ncu=$(command -v ncu || ls /usr/local/cuda/bin/ncu)
( for v in a b c; do nvcc -O3 -std=c++17 -arch=sm_90 $R/cuda_$v/main.cu -o /tmp/report_$v 2>&1 | tail -2 & done; wait )
python3 - <<'PY' > $OUT/report-cuda.txt 2>&1
import subprocess, time, json
def wall(cmd):
    best = 1e9
    for _ in range(3):
        t = time.perf_counter(); subprocess.run(cmd, cwd="/tmp", capture_output=True, check=True); best = min(best, time.perf_counter() - t)
    return best
import os
ctx = wall([os.path.abspath("lab05-ref"), "--quiet", "--width", "1", "--height", "1", "--spp", "1"])
print(f"process wall of lab05-ref at 1x1x1 spp (context creation and start-up): {ctx:.3f} s")
for v in "abc":
    print(f"report cuda_{v}: process wall best of 3 {wall(['/tmp/report_' + v]):.3f} s")
PY
for v in a b; do timeout 120 $ncu --clock-control none --metrics gpu__time_duration.sum --csv /tmp/report_$v 2>/dev/null | grep -i "render_kernel" | sed "s/^/report cuda_$v ncu: /" >> $OUT/report-cuda.txt; done
cat $OUT/report-cuda.txt
timeout 200 python3 -m pytest -q -rs -p no:cacheprovider tests/grading/test_gpu_rubrics.py ${EXTRA_TESTS:-} > $OUT/pytest.txt 2>&1; echo "tests rc=$?"; tail -15 $OUT/pytest.txt
