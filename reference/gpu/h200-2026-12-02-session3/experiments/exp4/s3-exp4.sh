#!/usr/bin/env bash
# Session 3, call 4: pushes reserved once per block (the same-address atomics were the limit).
set -u
cd "$(dirname "$0")/../.."
if ! echo '#include <nlohmann/json.hpp>' | g++ -std=c++17 -x c++ -fsyntax-only - 2>/dev/null; then
    cp -r .gpu-deps/include/nlohmann /usr/local/include/ 2>/dev/null || export CPATH=$PWD/.gpu-deps/include
fi
start=$(date +%s)
make -j16 lab07-bench lab06 lab06-ref lab07 lab07-ref > $OUT/build.log 2>&1 || { tail -30 $OUT/build.log; exit 1; }
echo "build $(( $(date +%s) - start )) s"
W=$OUT/wavefront
mkdir -p $W
WAVEFRONT_STEPS=bench WAVEFRONT_ONLY=AoS,SoA,AoS-atomic-per-warp,SoA-atomic-per-warp,megakernel WAVEFRONT_REPEAT=3 timeout 300 bash labs/06-cuda-split/measure.sh $W
echo "measure rc=$? at $(( $(date +%s) - start )) s"
python3 - <<'PY'
import json,glob,os
for f in sorted(glob.glob(os.environ["OUT"]+"/wavefront/bench-*.json")):
    try: d=json.load(open(f))
    except Exception as e: print(f, "unreadable", e); continue
    print(os.path.basename(f))
    for c in d["configs"]:
        st=" ".join(f'{s["kernel"][:5]}={s["ms"]:.1f}/{s["registers"]}r' for s in c.get("stages",[]))
        print(f'  {c["name"]:20s} {c["best_ms"]:7.2f} med {c["median_ms"]:7.2f} same={c["identical_to_first"]} rel={c["max_relative_difference"]:.2g} nf={c["nonfinite_pixels"]} {st}')
PY
for b in lab06 lab06-ref lab07 lab07-ref; do ./$b --quiet --spp 16 --width 64 --height 64 --pfm /tmp/$b.pfm; done
python3 - <<'PY'
import numpy as np
for b in ["lab06","lab06-ref","lab07","lab07-ref"]:
    with open(f"/tmp/{b}.pfm","rb") as f:
        f.readline(); f.readline(); s=float(f.readline()); a=np.frombuffer(f.read(),dtype="<f4" if s<0 else ">f4")
    print(b, "mean", a.mean())
PY
tar czf $OUT/wavefront.tgz -C $OUT wavefront && rm -rf $W
