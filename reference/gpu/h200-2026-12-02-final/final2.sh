#!/usr/bin/env bash
# The session's final GPU call, part 2: the grader's GPU tests, the sanitizer, and the
# wavefront measurements (labs/06-cuda-split/measure.sh).
export CPATH=$PWD/.gpu-deps/include
if ! command -v bwrap >/dev/null; then dpkg -x .gpu-deps/bubblewrap_*.deb /tmp/bw && export PATH=/tmp/bw/usr/bin:$PATH; fi
make -j16 lab01-ref lab05-ref lab05-bench lab06-ref lab07-ref lab07-bench > /tmp/build.log 2>&1 || { tail -20 /tmp/build.log; exit 1; }
( timeout 240 python3 -m pytest -q -rs -p no:cacheprovider tests/grading/test_gpu_rubrics.py > $OUT/pytest-grading.txt 2>&1; echo "grading tests rc=$?" ) 
tail -15 $OUT/pytest-grading.txt
{ compute-sanitizer --tool memcheck --error-exitcode 3 ./lab05-ref --quiet --width 48 --height 40 --spp 4 &&
  compute-sanitizer --tool racecheck --error-exitcode 3 ./lab05-bench --width 48 --height 40 --spp 4 --repeat 1 --only reference >/dev/null &&
  compute-sanitizer --tool memcheck --error-exitcode 3 ./lab06-ref --quiet --width 48 --height 40 --spp 4 &&
  compute-sanitizer --tool memcheck --error-exitcode 3 ./lab07-ref --quiet --width 48 --height 40 --spp 4; } > $OUT/sanitizer.txt 2>&1; echo "sanitizer rc=$?"
WAVEFRONT_ONLY=AoS,SoA,AoS-wave-524288,SoA-wave-262144,SoA-wave-524288,megakernel WAVEFRONT_REPEAT=2 timeout 300 bash labs/06-cuda-split/measure.sh /tmp/wavefront > $OUT/measure.log 2>&1; echo "measure rc=$?"
cp /tmp/wavefront/wavefront.md $OUT/; tar -C /tmp -czf $OUT/wavefront.tar.gz wavefront
head -40 /tmp/wavefront/wavefront.md
