#!/usr/bin/env bash
# Session 3, call 3: where find_closest_hits and shade_hits spend their time against the
# megakernel (ncu warp states), and grids of one thread per path.
set -u
cd "$(dirname "$0")/../.."
if ! echo '#include <nlohmann/json.hpp>' | g++ -std=c++17 -x c++ -fsyntax-only - 2>/dev/null; then
    cp -r .gpu-deps/include/nlohmann /usr/local/include/ 2>/dev/null || export CPATH=$PWD/.gpu-deps/include
fi
start=$(date +%s)
make -j16 lab07-bench lab06-ref lab05-ref > $OUT/build.log 2>&1 || { tail -30 $OUT/build.log; exit 1; }
echo "build $(( $(date +%s) - start )) s"
timeout 120 ./lab07-bench --repeat 3 --only AoS,AoS-item-per-thread,AoS-prefetch,SoA,SoA-item-per-thread > $OUT/bench.json
python3 - <<'PY'
import json,os
d=json.load(open(os.environ["OUT"]+"/bench.json"))
for c in d["configs"]:
    st=" ".join(f'{s["kernel"][:5]}={s["ms"]:.1f}/{s["registers"]}r' for s in c.get("stages",[]))
    print(f'  {c["name"]:20s} {c["best_ms"]:7.2f} med {c["median_ms"]:7.2f} same={c["identical_to_first"]} nf={c["nonfinite_pixels"]} {st}')
PY
ncu=$(command -v ncu || ls /usr/local/cuda/bin/ncu | head -1)
sections="--section SpeedOfLight --section WarpStateStats --section SchedulerStats --section Occupancy --section ComputeWorkloadAnalysis --section LaunchStats --metrics smsp__average_warps_issue_stalled_long_scoreboard_per_issue_active.ratio,smsp__average_warps_issue_stalled_short_scoreboard_per_issue_active.ratio,smsp__average_warps_issue_stalled_wait_per_issue_active.ratio,smsp__average_warps_issue_stalled_math_pipe_throttle_per_issue_active.ratio,smsp__average_warps_issue_stalled_lg_throttle_per_issue_active.ratio,smsp__average_warps_issue_stalled_mio_throttle_per_issue_active.ratio,smsp__average_warps_issue_stalled_barrier_per_issue_active.ratio,smsp__average_warps_issue_stalled_not_selected_per_issue_active.ratio,smsp__average_warps_issue_stalled_selected_per_issue_active.ratio,smsp__average_warps_issue_stalled_no_instruction_per_issue_active.ratio,smsp__average_warps_issue_stalled_branch_resolving_per_issue_active.ratio,smsp__average_warps_issue_stalled_dispatch_stall_per_issue_active.ratio,smsp__average_warps_issue_stalled_drain_per_issue_active.ratio,smsp__average_warps_issue_stalled_membar_per_issue_active.ratio,smsp__average_warps_issue_stalled_tex_throttle_per_issue_active.ratio,smsp__average_warps_issue_stalled_imc_miss_per_issue_active.ratio"
timeout 150 $ncu --clock-control none $sections --kernel-name regex:"find_closest|shade_hits|trace_shadow" --launch-count 3 --csv --page details \
    ./lab06-ref --quiet --spp 5 > $OUT/ncu-lab06.csv 2> $OUT/ncu-lab06.log
timeout 100 $ncu --clock-control none $sections --kernel-name regex:"render_kernel" --launch-count 1 --csv --page details \
    ./lab05-ref --quiet --spp 32 > $OUT/ncu-lab05.csv 2> $OUT/ncu-lab05.log
echo "done at $(( $(date +%s) - start )) s"
python3 - <<'PY'
import csv,os,collections
for f in ["ncu-lab06.csv","ncu-lab05.csv"]:
    rows=list(csv.reader(open(os.environ["OUT"]+"/"+f)))
    if not rows: print(f,"empty"); continue
    h=rows[0]; ki=h.index("Kernel Name"); mi=h.index("Metric Name"); vi=h.index("Metric Value"); ii=h.index("ID")
    want=("Duration","Issue Slots Busy","Issued Warp Per Scheduler","No Eligible","Active Warps Per Scheduler","Eligible Warps Per Scheduler","Warp Cycles Per Issued Instruction","Achieved Occupancy","Memory Throughput","Compute (SM) Throughput","Executed Ipc Active","Registers Per Thread","Avg. Active Threads Per Warp","Avg. Not Predicated Off Threads Per Warp")
    for r in rows[1:]:
        if r[mi] in want or ("stalled" in r[mi] and float(r[vi] or 0)>0.3): print(f, r[ii], r[ki][:40], r[mi], r[vi])
PY
