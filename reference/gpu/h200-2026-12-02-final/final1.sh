#!/usr/bin/env bash
# The session's final GPU call, part 1: build, kernel report, the labs' GPU tests, lab 05's
# benchmark, fast math, lab 05's counters and accuracy (tools/gpu_check.sh).
export GPU_CHECK_SKIP="wavefront sanitizer"
export GPU_CHECK_TESTS="tests/labs/test_lab05.py tests/labs/test_lab06.py tests/labs/test_lab07.py tests/labs/test_device_code.py"
timeout 570 bash tools/gpu_check.sh $OUT/check
echo "gpu_check rc=$?"
tail -25 $OUT/check/log.txt
