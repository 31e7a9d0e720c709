#!/usr/bin/env bash
# Everything the CUDA labs need a GPU for, in one call (`make gpu-check OUT=DIR`):
#   1. the machine: GPU, driver, nvcc, host compiler;
#   2. build every CUDA target for the GPU present (plus lab 01's reference): labs 05-07;
#   3. the compiler's resource report (make kernel-report) and the scene loads in the SASS;
#   4. the GPU tests (pytest), for real;
#   5. the benchmark: every kernel shape of lab05-bench on the baseline, CUDA events, best and
#      median of 5 after a warm-up; process time against kernel time;
#   6. accuracy of --use_fast_math and --fmad=false against the golden image and lab 01;
#   7. divergence and occupancy from Nsight Compute's counters, where ncu can read them;
#   8. the wavefront labs (06, 07): labs/06-cuda-split/measure.sh, into DIR/wavefront.tar.gz.
# Writes DIR/gpu-check.json (everything) and DIR/summary.md (the tables), plus the logs.
# GPU_CHECK_SKIP="sanitizer ncu" leaves those steps out (a short lease: their results change
# only when the kernels do).
#
#   tools/gpu_check.sh DIR          run it (on the GPU machine)
#   tools/gpu_check.sh --prepare    here, before sending the tree to a machine without the
#                                   JSON library: copies its headers into .gpu-deps/ (git-ignored
#                                   through .git/info/exclude; carry it with the tree)
set -uo pipefail
cd "$(dirname "$0")/.."
root=$PWD

if [ "${1:-}" = "--prepare" ]; then
    src=$(echo '#include <nlohmann/json.hpp>' | ${CXX:-g++} -std=c++17 -x c++ -H -fsyntax-only - 2>&1 |
          grep -m1 'nlohmann/json.hpp' | sed 's/^\.* //; s|/nlohmann/json.hpp$||')
    [ -d "$src/nlohmann" ] || { echo "gpu_check: the JSON library (nlohmann/json.hpp) is not installed here (make deps)" >&2; exit 1; }
    mkdir -p .gpu-deps/include && cp -r "$src/nlohmann" .gpu-deps/include/
    mkdir -p .git/info && { grep -qx '/.gpu-deps/' .git/info/exclude 2>/dev/null || echo '/.gpu-deps/' >> .git/info/exclude; }
    echo "gpu_check: copied $src/nlohmann to .gpu-deps/include (carry .gpu-deps with the tree)"
    exit 0
fi

out=${1:?usage: tools/gpu_check.sh OUTDIR | --prepare}
mkdir -p "$out"
out=$(cd "$out" && pwd)
log=$out/log.txt
: > "$log"
export PYTHONUNBUFFERED=1
say() { echo "gpu_check: $*" | tee -a "$log"; }
# Step status, for the JSON: name=ok|failed|skipped
declare -A step
run_step() {  # run_step NAME COMMAND...: output to the log, status recorded
    local name=$1; shift
    say "$name: $*"
    if "$@" >> "$log" 2>&1; then step[$name]=ok; else step[$name]=failed; say "$name FAILED (see log.txt)"; fi
}

# ---- 1. the machine ---------------------------------------------------------------------
{
    echo "date: $(date -u +%FT%TZ)"
    nvidia-smi --query-gpu=name,driver_version,compute_cap,memory.total,clocks.sm,clocks.max.sm,power.limit --format=csv 2>&1
    nvcc --version 2>&1 | tail -2
    ${CXX:-g++} --version 2>&1 | head -1
    python3 --version 2>&1
    echo "cpus: $(nproc)"
} > /tmp/gpu-check-machine.txt
cat /tmp/gpu-check-machine.txt | tee -a "$log"

# The scene loader needs the JSON library; a machine without it gets the carried copy.
if ! echo '#include <nlohmann/json.hpp>' | ${CXX:-g++} -std=c++17 -x c++ -fsyntax-only - 2>/dev/null; then
    if [ -f .gpu-deps/include/nlohmann/json.hpp ]; then
        export CPATH=$root/.gpu-deps/include${CPATH:+:$CPATH}
        say "JSON library: the carried copy in .gpu-deps/include"
    else
        say "JSON library missing: run tools/gpu_check.sh --prepare here and carry .gpu-deps"
    fi
fi

# ---- 2. build ---------------------------------------------------------------------------
jobs=$(nproc)
start=$(date +%s)
run_step build make -j"$jobs" lab01-ref lab05 lab05-ref lab05-bench lab05-bench-fast-math \
    lab05-ref-fast-math lab05-ref-no-fma lab06 lab06-ref lab06-bench lab07 lab07-ref lab07-bench
say "build took $(( $(date +%s) - start )) s"

# ---- 3. the compiler's report -----------------------------------------------------------
run_step kernel_report make -s kernel-report
cp build/kernel-report.md /tmp/gpu-check-kernel-report.md 2>/dev/null
# Which load instructions read the scene: LDC (constant bank), LDS (shared), LDG (global).
if command -v cuobjdump >/dev/null && [ -x lab05-bench ]; then
    cuobjdump -sass lab05-bench 2>/dev/null | awk '
        /Function :/ { f = $3 }
        /LDC|LDS|LDG|ULDC/ { for (i = 1; i <= NF; i++) if ($i ~ /^(LDC|LDS|LDG|ULDC)/) { split($i, a, "."); n[f "\t" a[1]]++ } }
        END { for (k in n) print k "\t" n[k] }' | sort > /tmp/gpu-check-sass-loads.tsv
fi

# ---- 4. the GPU tests -------------------------------------------------------------------
gpu_tests="tests/labs/test_lab05.py tests/labs/test_lab06.py tests/labs/test_lab07.py tests/labs/test_device_code.py tests/grading/test_gpu_rubrics.py"
say "tests: pytest $gpu_tests"
python3 -m pytest -q -rs -p no:cacheprovider $gpu_tests \
    --junitxml=/tmp/gpu-check-junit.xml > "$out/pytest.txt" 2>&1
step[tests]=$([ $? -eq 0 ] && echo ok || echo failed)
tail -3 "$out/pytest.txt" | tee -a "$log"

# ---- 5-7. measurements ------------------------------------------------------------------
if [ -x lab05-bench ]; then
    say "benchmark: lab05-bench --repeat 5 (the baseline)"
    ./lab05-bench --repeat 5 > "$out/bench.json" 2>> "$log" && step[bench]=ok || step[bench]=failed
    say "benchmark: lab05-bench-fast-math (--use_fast_math), the main shapes"
    ./lab05-bench-fast-math --repeat 5 --only "${GPU_CHECK_FAST_MATH_VARIANTS:-all-materials,diffuse-split-16,diffuse-regs-64,diffuse-scene-global,reference-16,plain,whole-paths,scene-constant,split-1}" \
        > "$out/bench-fast-math.json" 2>> "$log" && step[bench_fast_math]=ok || step[bench_fast_math]=failed
fi

# The memory checker on a small render: no out-of-bounds access, no uninitialised read, no
# race on the shared-memory copy of the scene (lab05-bench's scene-shared shape).
skipped() { [[ " ${GPU_CHECK_SKIP:-} " == *" $1 "* ]] && { step[$1]=skipped; say "$1: skipped (GPU_CHECK_SKIP)"; }; }
if ! skipped sanitizer && command -v compute-sanitizer >/dev/null && [ -x lab05-ref ]; then
    say "compute-sanitizer: memcheck and initcheck on lab05-ref, racecheck on scene-shared"
    { compute-sanitizer --tool memcheck --error-exitcode 3 ./lab05-ref --quiet --width 48 --height 40 --spp 4 &&
      compute-sanitizer --tool initcheck --error-exitcode 3 ./lab05-ref --quiet --width 48 --height 40 --spp 4 &&
      compute-sanitizer --tool racecheck --error-exitcode 3 ./lab05-bench --width 48 --height 40 --spp 4 --repeat 1 --only reference >/dev/null
    } >> "$log" 2>&1 && step[sanitizer]=ok || step[sanitizer]=failed
    say "compute-sanitizer: ${step[sanitizer]}"
fi

ncu_bin=$(command -v ncu || ls /opt/nvidia/nsight-compute/*/ncu /usr/local/cuda/bin/ncu 2>/dev/null | head -1)
if ! skipped ncu && [ -n "$ncu_bin" ] && [ -x lab05-bench ]; then
    say "counters: $ncu_bin on lab05-bench (64 spp, one timed run per shape)"
    metrics=smsp__thread_inst_executed_per_inst_executed.ratio,smsp__thread_inst_executed_pred_on_per_inst_executed.ratio,sm__warps_active.avg.pct_of_peak_sustained_active,smsp__issue_active.avg.pct_of_peak_sustained_active,smsp__inst_executed.sum,smsp__thread_inst_executed.sum,smsp__sass_thread_inst_executed_op_integer_pred_on.sum,smsp__sass_thread_inst_executed_op_fp32_pred_on.sum,smsp__sass_thread_inst_executed_op_fp64_pred_on.sum,sm__pipe_fma_cycles_active.avg.pct_of_peak_sustained_active,sm__inst_executed_pipe_alu.avg.pct_of_peak_sustained_active,gpu__time_duration.sum
    ncu_run() {  # ncu_run LABEL BENCH-ARGS...: one CSV per run, merged into the JSON below
        local label=$1; shift
        timeout 180 "$ncu_bin" --clock-control none --metrics "$metrics" --csv --page raw \
            ./lab05-bench --repeat 1 "$@" > "/tmp/gpu-check-ncu-$label.csv" 2>> "$log"
    }
    ncu_run cornell --spp 64 --only "${GPU_CHECK_NCU_VARIANTS:-plain,whole-paths-split-1,whole-paths,reference-16,diffuse-split-16}" &&
    ncu_run cornell-1-bounce --spp 64 --bounces 1 --only whole-paths &&
    ncu_run showcase --spp 64 --width 600 --height 600 --scene common/scenes/showcase.json --only whole-paths &&
        step[ncu]=ok || step[ncu]=failed
fi

GPU_CHECK_METRICS=${metrics:-} python3 - "$out" <<'EOF' 2>&1 | tee -a "$log"
"""Accuracy and process-time measurements, then gpu-check.json and summary.md."""
import csv, json, os, pathlib, re, statistics, subprocess, sys, time, xml.etree.ElementTree as ET
sys.path.insert(0, ".")
import numpy as np
from grading.compare import compare
from grading.harness import golden, run_lab

out = pathlib.Path(sys.argv[1])
result = {"machine": pathlib.Path("/tmp/gpu-check-machine.txt").read_text()}

def load_json(name):
    try:
        return json.loads((out / name).read_text())
    except Exception as e:  # a failed step leaves no file; say so in the JSON
        return {"error": f"{name}: {e}"}

# Tests.
try:
    suite = ET.parse("/tmp/gpu-check-junit.xml").getroot()
    suite = suite.find("testsuite") if suite.tag == "testsuites" else suite
    cases = []
    for c in suite.iter("testcase"):
        state = "passed"
        for tag in ("failure", "error", "skipped"):
            el = c.find(tag)
            if el is not None:
                state = tag + ": " + (el.get("message") or "")[:200]
        cases.append({"test": c.get("name"), "result": state, "seconds": float(c.get("time", 0))})
    result["tests"] = cases
except Exception as e:
    result["tests"] = {"error": str(e)}

result["bench"] = load_json("bench.json")
result["bench_fast_math"] = load_json("bench-fast-math.json")

# Every correctness check of the CPU labs on each build: the default, fast math, no FMA.
from grading import checks
result["checks"] = {}
for name in ("lab05-ref", "lab05-ref-fast-math", "lab05-ref-no-fma"):
    try:
        names = ["check_sphere_interior", "check_million_samples", "check_lit_plane",
                 "check_glass_slab", "check_scale_invariance", "check_translation_invariance",
                 "check_large_primitives", "check_reproducible"]
        rs = [getattr(checks, n)("./" + name) for n in names if hasattr(checks, n)]
        rs += [checks.check_golden("./" + name, scene) for scene in ("cornell", "showcase")]
        result["checks"][name] = [{"check": r.name, "passed": r.passed, "detail": r.detail} for r in rs]
    except Exception as e:
        result["checks"][name] = {"error": str(e)[-300:]}

# Process time against kernel time: the whole ./lab05-ref run (context, module load, scene
# and image copies, file writing) against the kernel time it reports.
runs = []
for _ in range(3):
    t = time.perf_counter()
    r = run_lab("./lab05-ref", check=False)
    wall = time.perf_counter() - t
    if r.json:
        runs.append({"process_seconds": wall, "kernel_seconds": r.json["seconds"]})
result["process_vs_kernel"] = runs

# Accuracy of the flag variants: the golden comparison at a high spp (where small biases
# show), and each variant against the default build with the same seed.
g = golden("cornell")
size = dict(width=g.meta["width"], height=g.meta["height"], bounces=g.meta["bounces"])
acc = {}
images = {}
for name in ("lab05-ref", "lab05-ref-no-fma", "lab05-ref-fast-math", "lab01-ref"):
    spp = 1024 if name != "lab01-ref" else 256
    r = run_lab("./" + name, g.scene, spp=spp, seed=9, check=False, **size)
    if r.image is None:
        acc[name] = {"error": r.stderr.strip()[-300:]}
        continue
    images[name] = (r.image, spp)
    rep = compare(r.image, spp, g.mean, g.variance, g.meta["golden_spp"])
    times = [run_lab("./" + name, check=False).json for _ in range(3)] if name != "lab01-ref" else []
    acc[name] = {"spp": spp, "passed": rep.passed, "rmse": rep.rmse, "bias": rep.bias,
                 "bias_se": rep.bias_se, "max_abs_z": rep.max_abs_z, "critical_z": rep.critical_z,
                 "nonfinite": rep.nan_count + rep.inf_count,
                 "baseline_kernel_seconds_best": min(t["seconds"] for t in times if t) if any(times) else None}
if "lab05-ref" in images:
    base, _ = images["lab05-ref"]
    for name in ("lab05-ref-no-fma", "lab05-ref-fast-math"):
        if name in images:
            img, _ = images[name]
            rel = np.abs(img - base) / (np.abs(base) + 1e-3)
            acc[name]["vs_default_same_seed"] = {
                "identical_pixels": float(np.all(img == base, axis=2).mean()),
                "median_rel_diff": float(np.median(rel)), "max_rel_diff": float(rel.max()),
                "mean_rel_diff_of_image_mean": float(img.mean() / base.mean() - 1)}
# lab 01 at the same seed and spp: how many pixels the GPU builds reproduce bit for bit.
cpu = run_lab("./lab01-ref", g.scene, spp=64, seed=9, check=False, **size).image
for name in ("lab05-ref", "lab05-ref-no-fma", "lab05-ref-fast-math"):
    r = run_lab("./" + name, g.scene, spp=64, seed=9, check=False, **size)
    if cpu is not None and r.image is not None and name in acc:
        acc[name]["identical_to_lab01_pixels"] = float(np.all(r.image == cpu, axis=2).mean())
result["accuracy"] = acc

# Counters: one CSV per ncu run; each kernel launch is a row (warm-up and timed run alike).
metrics = set(os.environ.get("GPU_CHECK_METRICS", "").split(","))
ncu = []
for label in ("cornell", "cornell-1-bounce", "showcase"):
    try:
        rows = list(csv.reader(open(f"/tmp/gpu-check-ncu-{label}.csv")))
        head = next(i for i, r in enumerate(rows) if "Kernel Name" in r)
        names = rows[head]
        keep = [i for i, n in enumerate(names) if n in ("ID", "Kernel Name") or n in metrics]
        for r in rows[head + 2:]:
            if len(r) == len(names):
                ncu.append({"run": label, **{names[i]: r[i] for i in keep}})
    except Exception as e:
        ncu.append({"run": label, "error": str(e)})
result["ncu"] = ncu
kr = pathlib.Path("/tmp/gpu-check-kernel-report.md")
result["kernel_report"] = kr.read_text() if kr.exists() else None
sass = pathlib.Path("/tmp/gpu-check-sass-loads.tsv")
result["sass_loads"] = sass.read_text() if sass.exists() else None
(out / "gpu-check.json").write_text(json.dumps(result, indent=1))

# The summary.
md = ["# GPU check", "", "```", result["machine"].strip(), "```", ""]
if isinstance(result["tests"], list):
    n = {k: sum(1 for c in result["tests"] if c["result"].startswith(k)) for k in ("passed", "failure", "error", "skipped")}
    md += [f"Tests: {n['passed']} passed, {n['failure']} failed, {n['error']} errors, {n['skipped']} skipped", ""]
    md += [f"- {c['test']}: {c['result']}" for c in result["tests"] if not c["result"].startswith("passed")]
    md.append("")
b = result["bench"]
if "variants" in b:
    md += [f"Benchmark: {b['device']}, {b['width']}x{b['height']}, {b['spp']} spp, {b['bounces']} bounces; {b['timing']}", "",
           "| shape | change | threads/pixel | scene | block | regs | occupancy | best ms | median ms | Gpaths/s | same image |",
           "|---|---|---:|---|---:|---:|---:|---:|---:|---:|---|"]
    for v in b["variants"]:
        md.append(f"| {v['name']} | {v['change']} | {v['threads_per_pixel']} | {v['scene_memory']} | {v['block_threads']} | "
                  f"{v['registers']} | {v['occupancy']:.0%} | {v['best_ms']:.2f} | {v['median_ms']:.2f} | "
                  f"{v['paths_per_second'] / 1e9:.2f} | {'bits' if v['identical_to_reference'] else '%.1e' % v['max_relative_difference']} |")
    md.append("")
fb = result["bench_fast_math"]
if "variants" in fb and "variants" in b:
    default = {v["name"]: v["best_ms"] for v in b["variants"]}
    md += ["With --use_fast_math (lab05-bench-fast-math):", "", "| shape | best ms | without fast math | same image as fast-math reference |", "|---|---:|---:|---|"]
    for v in fb["variants"]:
        md.append(f"| {v['name']} | {v['best_ms']:.2f} | {default.get(v['name'], float('nan')):.2f} | {'bits' if v['identical_to_reference'] else '%.1e' % v['max_relative_difference']} |")
    md.append("")
if "host_ms" in b:
    md += ["Host-side costs (ms): " + ", ".join(f"{k} {v:.2f}" for k, v in b["host_ms"].items()), ""]
for name, rs in result["checks"].items():
    if isinstance(rs, list):
        md += [f"Checks on {name}: " + "; ".join(f"{'PASS' if r['passed'] else 'FAIL'} {r['check']}" for r in rs), ""]
    else:
        md += [f"Checks on {name}: {rs}", ""]
if runs:
    md += ["| process s | kernel s |", "|---:|---:|"] + [f"| {r['process_seconds']:.3f} | {r['kernel_seconds']:.4f} |" for r in runs] + [""]
md += ["| build | golden passes | RMSE | bias (se) | max z | baseline kernel s | identical to default | identical to lab 01 |", "|---|---|---:|---:|---:|---:|---:|---:|"]
for name, a in acc.items():
    if "error" in a:
        md.append(f"| {name} | error: {a['error']} |"); continue
    same = a.get("vs_default_same_seed", {}).get("identical_pixels")
    md.append(f"| {name} | {a['passed']} | {a['rmse']:.3e} | {a['bias']:.2e} ({a['bias_se']:.1e}) | {a['max_abs_z']:.2f}/{a['critical_z']:.2f} | "
              f"{a['baseline_kernel_seconds_best'] if a['baseline_kernel_seconds_best'] is not None else '-'} | "
              f"{'-' if same is None else f'{same:.1%}'} | {a.get('identical_to_lab01_pixels', '-')} |")
md.append("")
if isinstance(ncu, list) and ncu:
    keys = ["smsp__thread_inst_executed_per_inst_executed.ratio", "sm__warps_active.avg.pct_of_peak_sustained_active",
            "smsp__issue_active.avg.pct_of_peak_sustained_active", "sm__pipe_fma_cycles_active.avg.pct_of_peak_sustained_active"]
    md += ["| run | kernel | active threads/warp | achieved occupancy % | issue active % | FMA pipe % | thread instr/path | integer/path | fp32/path | fp64/path |", "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|"]
    paths = b.get("width", 600) * b.get("height", 600) * 64  # every ncu run renders 64 spp
    def num(r, k):
        try: return float(r[k].replace(",", ""))
        except Exception: return float("nan")
    for r in ncu:
        if "error" in r:
            md.append(f"| {r['run']} | error: {r['error']} |"); continue
        kn = r.get("Kernel Name", "?")[:60]
        md.append(f"| {r['run']} | `{kn}` | {num(r, keys[0]):.1f} | {num(r, keys[1]):.1f} | {num(r, keys[2]):.1f} | {num(r, keys[3]):.1f} | "
                  f"{num(r, 'smsp__thread_inst_executed.sum') / paths:.0f} | {num(r, 'smsp__sass_thread_inst_executed_op_integer_pred_on.sum') / paths:.0f} | "
                  f"{num(r, 'smsp__sass_thread_inst_executed_op_fp32_pred_on.sum') / paths:.0f} | {num(r, 'smsp__sass_thread_inst_executed_op_fp64_pred_on.sum') / paths:.1f} |")
    md.append("")
if result["kernel_report"]:
    md += [result["kernel_report"]]
(out / "summary.md").write_text("\n".join(md) + "\n")
print("\n".join(md[:60]))
EOF

# ---- 8. the wavefront labs --------------------------------------------------------------
if [ -x lab07-bench ]; then
    say "wavefront: labs/06-cuda-split/measure.sh (AoS, SoA and the megakernel on four scenes)"
    [[ " ${GPU_CHECK_SKIP:-} " == *" ncu "* ]] && export WAVEFRONT_STEPS=${WAVEFRONT_STEPS:-bench tables}
    WAVEFRONT_REPEAT=${WAVEFRONT_REPEAT:-2} bash labs/06-cuda-split/measure.sh /tmp/gpu-check-wavefront >> "$log" 2>&1 \
        && step[wavefront]=ok || step[wavefront]=failed
    cp /tmp/gpu-check-wavefront/wavefront.md "$out/" 2>/dev/null
    tar -C /tmp -czf "$out/wavefront.tar.gz" gpu-check-wavefront
fi

status=0
for s in "${!step[@]}"; do
    say "step $s: ${step[$s]}"
    [ "${step[$s]}" = ok ] || [ "${step[$s]}" = skipped ] || status=1
done
exit $status
