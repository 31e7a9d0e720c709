#!/usr/bin/env bash
# Session 3: make tradeoff's GPU plan again, now with lab05-ref built with --use_fast_math.
cd "$(dirname "$0")/../.."
if ! command -v bwrap >/dev/null; then :; fi
TRADEOFF_GPU_BUDGET=190 bash tools/tradeoff_gpu.sh /tmp/tradeoff > /tmp/tradeoff-run.txt 2>&1; echo "tradeoff rc=$?"
tail -32 /tmp/tradeoff-run.txt
tar -C /tmp -czf $OUT/tradeoff.tgz tradeoff
