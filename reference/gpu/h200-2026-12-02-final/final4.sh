#!/usr/bin/env bash
# Last GPU call: the double-precision megakernel's checks, the grader's sandboxed builds of
# submitted CUDA sources (the JSON library where the sandbox sees it), and make bench's GPU rows.
cp -r .gpu-deps/include/nlohmann /usr/local/include/ 2>/dev/null
if ! command -v bwrap >/dev/null; then dpkg -x .gpu-deps/bubblewrap_*.deb /tmp/bw && export PATH=/tmp/bw/usr/bin:$PATH; fi
make -j16 lab01-ref lab05-ref lab05-ref-double lab06-ref lab07-ref > /tmp/build.log 2>&1 || { tail -20 /tmp/build.log; exit 1; }
timeout 150 python3 tools/bench_report.py --gpu-only --scale 3 --json-out $OUT/gpu-rows.json > $OUT/bench-gpu.log 2>&1; echo "bench rc=$?"; tail -5 $OUT/bench-gpu.log
timeout 200 python3 -m pytest -q -rs -p no:cacheprovider tests/labs/test_lab05.py tests/grading/test_gpu_rubrics.py -k "double or build_in_the_sandbox or does_not_compile" > $OUT/pytest.txt 2>&1; echo "tests rc=$?"; tail -12 $OUT/pytest.txt
