#!/usr/bin/env bash
set -u
export CPATH=$PWD/.gpu-deps/include
start=$(date +%s)
make -j16 lab05-bench lab06-ref lab07-ref lab07-bench > $OUT/build.log 2>&1 || { tail -30 $OUT/build.log; exit 1; }
echo "build $(( $(date +%s) - start )) s"
./lab05-bench --repeat 5 --only reference,all-materials,diffuse-split-16,diffuse-regs-64 > $OUT/b5.json 2>&1
python3 -c "
import json,sys;d=json.load(open('$OUT/b5.json'))
for v in d['variants']: print('%-26s %7.2f %7.2f regs %d local %d' % (v['name'],v['best_ms'],v['median_ms'],v['registers'],v['local_bytes']))"
pr() { python3 -c "
import json,sys;d=json.load(open(sys.argv[1]))
for v in d['configs']:
    st=' '.join('%s=%.1f/%d' % (s['kernel'][:5], s['ms'], s['registers']) for s in v.get('stages',[]))
    print(sys.argv[2], '%-18s %7.2f same %s nf %d %s' % (v['name'],v['best_ms'],v['identical_to_first'],v['nonfinite_pixels'],st))" $1 $2; }
timeout 250 ./lab07-bench --repeat 3 --only AoS,SoA,AoS-occupancy-75,SoA-occupancy-75,AoS-occupancy-100,SoA-occupancy-100,AoS-wave-524288,SoA-wave-524288 > $OUT/b7.json 2>$OUT/b7.err; pr $OUT/b7.json 4b
timeout 150 ./lab07-bench --repeat 2 --bounces 16 --only AoS,SoA,AoS-occupancy-75,SoA-occupancy-75,megakernel > $OUT/b7-16.json 2>&1; pr $OUT/b7-16.json 16b
timeout 150 ./lab07-bench --repeat 2 --scene common/scenes/showcase.json --only AoS,SoA,AoS-occupancy-75,SoA-occupancy-75,megakernel > $OUT/b7-s.json 2>&1; pr $OUT/b7-s.json show
