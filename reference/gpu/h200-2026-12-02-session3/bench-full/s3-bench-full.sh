#!/usr/bin/env bash
# Session 3: make bench's GPU rows again (labs 06 and 07 changed), at full size (the report's own settings), for a full-size report; not at the committed report's
# scale, to merge into reference/reports/bench-xeon-2core-2026-12-02.
set -u
cd "$(dirname "$0")/../.."
if ! echo '#include <nlohmann/json.hpp>' | g++ -std=c++17 -x c++ -fsyntax-only - 2>/dev/null; then
    cp -r .gpu-deps/include/nlohmann /usr/local/include/ 2>/dev/null || export CPATH=$PWD/.gpu-deps/include
fi
make -j16 lab01-ref lab05-ref lab06-ref lab07-ref > /tmp/build.log 2>&1 || { tail -20 /tmp/build.log; exit 1; }
timeout 300 python3 tools/bench_report.py --gpu-only --json-out $OUT/gpu-rows-full.json > $OUT/bench-gpu.log 2>&1
echo "rc=$?"; tail -25 $OUT/bench-gpu.log
