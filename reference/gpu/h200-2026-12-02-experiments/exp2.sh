#!/usr/bin/env bash
set -u
export CPATH=$PWD/.gpu-deps/include
start=$(date +%s)
make -j16 lab05-ref lab05-bench lab05-bench-fast-math lab06-ref lab07-ref lab07-bench > $OUT/build.log 2>&1 || { tail -30 $OUT/build.log; exit 1; }
echo "build $(( $(date +%s) - start )) s"
V=reference,all-materials,diffuse-split-32,diffuse-regs-72,diffuse-split-32-regs-72,diffuse-split-32-block-32
p() { python3 -c "
import json,sys;d=json.load(open(sys.argv[1]))
for v in d['variants']: print(sys.argv[2],'%-26s %7.2f %7.2f regs %d local %d' % (v['name'],v['best_ms'],v['median_ms'],v['registers'],v['local_bytes']))" $1 $2; }
./lab05-bench --repeat 5 --only $V > $OUT/b5.json 2>&1; p $OUT/b5.json std
./lab05-bench-fast-math --repeat 5 --only $V > $OUT/b5f.json 2>&1; p $OUT/b5f.json fast
timeout 200 ./lab07-bench --repeat 3 --only AoS,SoA,AoS-wave-524288,SoA-wave-524288,megakernel > $OUT/b7.json 2>$OUT/b7.err
python3 -c "
import json;d=json.load(open('$OUT/b7.json'))
for v in d['configs']:
    st=' '.join('%s=%.1f' % (s['kernel'][:8], s['ms']) for s in v.get('stages',[]))
    print('%-18s %7.2f same %s nf %d %s' % (v['name'],v['best_ms'],v['identical_to_first'],v['nonfinite_pixels'],st))"
ncu=$(command -v ncu || ls /opt/nvidia/nsight-compute/*/ncu | head -1)
for lab in lab06-ref lab07-ref; do
timeout 150 $ncu --clock-control none --section SpeedOfLight --section WarpStateStats --section MemoryWorkloadAnalysis --section Occupancy --launch-skip 5 --launch-count 5 --csv --page details ./$lab --quiet --spp 5 > $OUT/ncu-$lab.csv 2>$OUT/ncu-$lab.err; echo "ncu $lab rc=$?"
done
