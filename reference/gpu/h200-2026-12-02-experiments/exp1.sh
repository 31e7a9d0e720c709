#!/usr/bin/env bash
# Experiment 1 (not committed): lab 05 material specialisation + vector scene loads, the
# wavefront's lean 16-byte-row pool; quick GPU tests.
set -u
export CPATH=$PWD/.gpu-deps/include
nvidia-smi --query-gpu=name,driver_version,clocks.sm --format=csv
start=$(date +%s)
make -j16 lab01-ref lab05 lab05-ref lab05-bench lab06 lab06-ref lab07 lab07-ref lab07-bench > $OUT/build.log 2>&1 || { tail -30 $OUT/build.log; exit 1; }
echo "build $(( $(date +%s) - start )) s"
./lab05-bench --repeat 5 --only reference,all-materials,diffuse-regs-any,diffuse-regs-56,diffuse-whole-paths,diffuse-split-32,diffuse-block-128,regs-any > $OUT/b5.json 2>&1
python3 -c "
import json;d=json.load(open('$OUT/b5.json'))
for v in d['variants']: print('%-22s %7.2f %7.2f regs %d local %d occ %.2f same %s' % (v['name'],v['best_ms'],v['median_ms'],v['registers'],v['local_bytes'],v['occupancy'],v['identical_to_reference']))"
timeout 200 ./lab07-bench --repeat 3 > $OUT/b7.json 2>$OUT/b7.err
python3 -c "
import json;d=json.load(open('$OUT/b7.json'))
for v in d['configs']:
    st=' '.join('%s=%.1f' % (s['kernel'][:8], s['ms']) for s in v.get('stages',[]))
    print('%-22s %7.2f %7.2f same %s nonfinite %d  %s' % (v['name'],v['best_ms'],v['median_ms'],v['identical_to_first'],v['nonfinite_pixels'],st))"
timeout 150 ./lab07-bench --repeat 2 --bounces 16 --only AoS,SoA,SoA-wave-262144,SoA-wave-524288,megakernel > $OUT/b7-16.json 2>&1
python3 -c "
import json;d=json.load(open('$OUT/b7-16.json'))
for v in d['configs']: print('16b %-22s %7.2f' % (v['name'],v['best_ms']))"
timeout 200 python3 -m pytest -q -x -p no:cacheprovider tests/labs/test_lab05.py tests/labs/test_lab06.py tests/labs/test_lab07.py 2>&1 | tail -15
