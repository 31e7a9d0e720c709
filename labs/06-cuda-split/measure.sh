#!/usr/bin/env bash
# The measurements of handouts/06-cuda-split.md and 07-soa.md, on a GPU machine, after
# `make lab06-ref lab07-ref lab07-bench` (tools/gpu/check.sh calls it; it runs alone too):
#   1. lab07-bench (both pool layouts and lab 05's megakernel, one process per scene): the
#      Cornell baseline, the Cornell box at 16 bounces, the showcase (glass and mirrors, its
#      8 bounces) and the showcase at 16 bounces;
#   2. where Nsight Compute can read the counters: DRAM, L2 and L1 traffic of every kernel
#      of one wave (600x600, 5 spp: 1.8M paths), lab06-ref (AoS) and lab07-ref (SoA);
#   3. DIR/wavefront.md: the tables (bench_tables.py).
#
#   labs/06-cuda-split/measure.sh DIR
#   WAVEFRONT_STEPS='bench' labs/06-cuda-split/measure.sh DIR   some steps only (bench, ncu,
#                                                              tables; default all three)
set -uo pipefail
cd "$(dirname "$0")/../.."
out=${1:?usage: labs/06-cuda-split/measure.sh OUTDIR}
mkdir -p "$out"
status=0
steps=" ${WAVEFRONT_STEPS:-bench ncu tables} "
bench() {  # bench NAME FLAGS...: one JSON per scene
    local name=$1; shift
    echo "measure: lab07-bench $*"
    timeout 240 ./lab07-bench --repeat "${WAVEFRONT_REPEAT:-3}" "$@" > "$out/bench-$name.json" || status=1
}
# WAVEFRONT_ONLY=NAME,...: only those configurations on the three scenes after the baseline
# (when GPU time is short; the baseline always gets them all).
only=(${WAVEFRONT_ONLY:+--only "$WAVEFRONT_ONLY"})
if [[ $steps == *" bench "* ]]; then
    bench cornell
    bench cornell-16 --bounces 16 "${only[@]}"
    bench showcase --scene common/scenes/showcase.json "${only[@]}"
    bench showcase-16 --scene common/scenes/showcase.json --bounces 16 "${only[@]}"
fi

ncu_bin=$(command -v ncu || ls /opt/nvidia/nsight-compute/*/ncu /usr/local/cuda/bin/ncu 2>/dev/null | head -1)
if [[ $steps == *" ncu "* ]] && [ -n "$ncu_bin" ]; then
    metrics=gpu__time_duration.sum,dram__bytes_read.sum,dram__bytes_write.sum,lts__t_bytes.sum,l1tex__t_requests_pipe_lsu_mem_global_op_ld.sum,l1tex__t_sectors_pipe_lsu_mem_global_op_ld.sum,l1tex__t_sectors_pipe_lsu_mem_global_op_st.sum,sm__warps_active.avg.pct_of_peak_sustained_active
    for lab in lab06-ref lab07-ref; do
        echo "measure: $ncu_bin on $lab (one wave: 600x600, 5 spp)"
        timeout 120 "$ncu_bin" --clock-control none --print-units base --metrics "$metrics" --csv --page raw \
            ./$lab --quiet --spp 5 > "$out/ncu-$lab.csv" 2> "$out/ncu-$lab.log" || status=1
    done
fi
[[ $steps == *" tables "* ]] && { python3 labs/06-cuda-split/bench_tables.py "$out" > "$out/wavefront.md" || status=1; }
exit $status
