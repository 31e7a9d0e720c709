#!/usr/bin/env bash
# Session 3, the final call: labs 06-07 as submitted. Build; their GPU tests; the grader's GPU
# tests; compute-sanitizer (memcheck, and racecheck for the block's shared-memory reserve);
# labs/06-cuda-split/measure.sh (four scenes, ncu, tables); make tradeoff's GPU rows.
set -u
cd "$(dirname "$0")/../.."
t0=$(date +%s); el() { echo $(( $(date +%s) - t0 )); }
{ date -u +%FT%TZ; nvidia-smi --query-gpu=name,driver_version,compute_cap,memory.total,clocks.max.sm --format=csv; nvcc --version | tail -1; echo "cpus $(nproc)"; } > $OUT/machine.txt 2>&1
cat $OUT/machine.txt
if ! echo '#include <nlohmann/json.hpp>' | g++ -std=c++17 -x c++ -fsyntax-only - 2>/dev/null; then
    cp -r .gpu-deps/include/nlohmann /usr/local/include/ 2>/dev/null || export CPATH=$PWD/.gpu-deps/include
fi
if ! command -v bwrap >/dev/null; then dpkg -x .gpu-deps/bubblewrap_*.deb /tmp/bw && export PATH=/tmp/bw/usr/bin:$PATH; fi
make -j16 lab01-ref lab05-ref lab06 lab06-ref lab06-bench lab07 lab07-ref lab07-bench lab03-ref lab03-simd-ref lab01-ref-double lab05-ref-double > /tmp/build.log 2>&1 || { tail -30 /tmp/build.log; }
echo "build done at $(el) s"
timeout 170 python3 -m pytest -q -rs -p no:cacheprovider tests/labs/test_lab06.py tests/labs/test_lab07.py > $OUT/pytest-labs.txt 2>&1; echo "lab tests rc=$? at $(el) s"; tail -4 $OUT/pytest-labs.txt
W=/tmp/wavefront; mkdir -p $W
WAVEFRONT_ONLY=AoS,SoA,AoS-grid-stride,SoA-grid-stride,AoS-wave-524288,SoA-wave-524288,megakernel WAVEFRONT_REPEAT=3 timeout 200 bash labs/06-cuda-split/measure.sh $W > $W/measure.log 2>&1; echo "measure rc=$? at $(el) s"
tar -C /tmp -czf $OUT/wavefront.tgz wavefront
python3 - <<'PY'
import json,glob,os
for f in sorted(glob.glob("/tmp/wavefront/bench-*.json")):
    try: d=json.load(open(f))
    except Exception as e: print(f, "unreadable", e); continue
    print(os.path.basename(f))
    for c in d["configs"]:
        st=" ".join(f'{s["kernel"][:5]}={s["ms"]:.1f}/{s["registers"]}r' for s in c.get("stages",[]))
        print(f'  {c["name"]:20s} {c["best_ms"]:7.2f} med {c["median_ms"]:7.2f} same={c["identical_to_first"]} nf={c["nonfinite_pixels"]} {st}')
PY
{ compute-sanitizer --tool memcheck --error-exitcode 3 ./lab06-ref --quiet --width 48 --height 40 --spp 4 &&
  compute-sanitizer --tool memcheck --error-exitcode 3 ./lab07-ref --quiet --width 48 --height 40 --spp 4 --json &&
  compute-sanitizer --tool racecheck --error-exitcode 3 ./lab06-ref --quiet --width 48 --height 40 --spp 4 &&
  compute-sanitizer --tool racecheck --error-exitcode 3 ./lab07-ref --quiet --width 48 --height 40 --spp 4; } > $OUT/sanitizer.txt 2>&1; echo "sanitizer rc=$? at $(el) s"; tail -3 $OUT/sanitizer.txt
timeout 150 python3 -m pytest -q -rs -p no:cacheprovider tests/grading/test_gpu_rubrics.py > $OUT/pytest-grading.txt 2>&1; echo "grading tests rc=$? at $(el) s"; tail -4 $OUT/pytest-grading.txt
left=$(( 575 - $(el) ))
echo "tradeoff budget $left s"
if [ $left -gt 60 ]; then
    TRADEOFF_GPU_BUDGET=$left bash tools/tradeoff_gpu.sh /tmp/tradeoff > /tmp/tradeoff-run.txt 2>&1; echo "tradeoff rc=$? at $(el) s"
    tail -30 /tmp/tradeoff-run.txt
    tar -C /tmp -czf $OUT/tradeoff.tgz tradeoff
fi
