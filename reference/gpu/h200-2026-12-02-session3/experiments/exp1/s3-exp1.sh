#!/usr/bin/env bash
# Session 3, call 1: the compacting wavefront (queues carry the paths). Build, bench on the
# baseline (every configuration), the three other scenes (AoS, SoA, megakernel), ncu of one wave.
set -u
cd "$(dirname "$0")/../.."
{ nvidia-smi --query-gpu=name,driver_version,compute_cap --format=csv; nvcc --version | tail -1; } 2>&1
if ! echo '#include <nlohmann/json.hpp>' | g++ -std=c++17 -x c++ -fsyntax-only - 2>/dev/null; then
    cp -r .gpu-deps/include/nlohmann /usr/local/include/ 2>/dev/null || export CPATH=$PWD/.gpu-deps/include
fi
start=$(date +%s)
make -j16 lab06-ref lab07-ref lab07-bench lab06 lab07 > $OUT/build.log 2>&1 || { tail -30 $OUT/build.log; exit 1; }
echo "build $(( $(date +%s) - start )) s"
W=$OUT/wavefront
mkdir -p $W
WAVEFRONT_ONLY=AoS,SoA,megakernel WAVEFRONT_REPEAT=3 timeout 420 bash labs/06-cuda-split/measure.sh $W
echo "measure rc=$? at $(( $(date +%s) - start )) s"
python3 - <<'PY'
import json,glob,os
for f in sorted(glob.glob(os.environ["OUT"]+"/wavefront/bench-*.json")):
    try: d=json.load(open(f))
    except Exception as e: print(f, "unreadable", e); continue
    print(os.path.basename(f))
    for c in d["configs"]:
        st=" ".join(f'{s["kernel"][:8]}={s["ms"]:.1f}/{s["registers"]}r' for s in c.get("stages",[]))
        print(f'  {c["name"]:24s} best {c["best_ms"]:8.2f} med {c["median_ms"]:8.2f} same={c["identical_to_first"]} maxrel={c["max_relative_difference"]:.2g} nonfinite={c["nonfinite_pixels"]} {st}')
PY
# quick correctness on the lab binaries: the skeletons render dark, the references not
for b in lab06 lab06-ref lab07 lab07-ref; do ./$b --quiet --json --spp 16 --width 64 --height 64 --pfm /tmp/$b.pfm 2>&1 | tr -d '\n' | cut -c1-300; echo; done
tar czf $OUT/wavefront.tgz -C $OUT wavefront && rm -rf $W
python3 - <<'PY'
import numpy as np
for b in ["lab06","lab06-ref","lab07","lab07-ref"]:
    try:
        with open(f"/tmp/{b}.pfm","rb") as f:
            assert f.readline().strip()==b"PF"; w,h=map(int,f.readline().split()); s=float(f.readline())
            a=np.frombuffer(f.read(),dtype="<f4" if s<0 else ">f4")
        print(b, "mean", a.mean())
    except Exception as e: print(b, "no image", e)
PY
