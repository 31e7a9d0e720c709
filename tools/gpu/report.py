"""The GPU check's measurements and report (tools/gpu/check.sh runs it on the GPU machine).

    python3 -m tools.gpu.report OUT              measure (needs the GPU and the built labs),
                                                 then write OUT/gpu-check.json, OUT/summary.md
    python3 -m tools.gpu.report --summary JSON   only the summary, from a recorded gpu-check.json

collect() runs what needs the GPU: every correctness check on the default, fast-math and
no-FMA builds of lab 05, process time against kernel time, the flag variants' accuracy; it
reads what tools/gpu/check.sh left in OUT and /tmp (the pytest JUnit file, the benchmarks' JSON,
Nsight Compute's CSVs, the compiler's report). summary() only formats: it is tested on the
CPU against a recorded gpu-check.json (tests/tools/test_gpu_report.py).
"""
import argparse
import csv
import json
import os
import pathlib
import sys
import time
import xml.etree.ElementTree as ET

ROOT = pathlib.Path(__file__).resolve().parents[2]


def collect(out: pathlib.Path) -> dict:
    """Everything gpu-check.json holds. Runs the lab binaries in the repository root."""
    import numpy as np

    from grading.checks.renderer import CHECKS as RENDERER_CHECKS
    from labkit.compare import compare
    from labkit.harness import golden, run_lab

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
    result["bench_lab06"] = load_json("bench-lab06.json")
    result["bench_lab07"] = load_json("bench-lab07.json")

    # Every correctness check of the CPU labs on each build: the default, fast math, no FMA.
    result["checks"] = {}
    for name in ("lab05-ref", "lab05-ref-fast-math", "lab05-ref-no-fma"):
        try:
            rs = [check("./" + name) for check in RENDERER_CHECKS.values()]
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
    return result


TARGET_BENCHES = (("bench", "lab05-bench"), ("bench_lab06", "lab06-bench"), ("bench_lab07", "lab07-bench"))


def targets_table(result: dict) -> list[str]:
    """The speed targets each benchmark printed (bench/gpu/speed_targets.h) and whether the
    run met them; nothing for a call whose benchmarks printed none."""
    rows = []
    for key, bench in TARGET_BENCHES:
        b = result.get(key) or {}
        for t in b.get("targets") or []:
            best = "-" if t.get("best_ms") is None else f"{t['best_ms']:.2f}"
            met = {True: "yes", False: "**no**", None: "not judged"}[t.get("met")]
            why = f" ({t['why_not']})" if t.get("why_not") else ""
            rows.append(f"| {bench} | {t['config']} | {t['bar']} | {best} | {met}{why} |")
    if not rows:
        return []
    return ["Speed targets:", "", "| benchmark | configuration | bar | best ms | met |",
            "|---|---|---|---:|---|", *rows, ""]


def summary(result: dict) -> str:
    """summary.md: the tables of a gpu-check.json, for people."""
    b = result.get("bench", {})
    runs = result.get("process_vs_kernel") or []
    acc = result.get("accuracy") or {}
    ncu = result.get("ncu") or []
    md = ["# GPU check", "", "```", result["machine"].strip(), "```", ""]
    if isinstance(result["tests"], list):
        n = {k: sum(1 for c in result["tests"] if c["result"].startswith(k)) for k in ("passed", "failure", "error", "skipped")}
        md += [f"Tests: {n['passed']} passed, {n['failure']} failed, {n['error']} errors, {n['skipped']} skipped", ""]
        md += [f"- {c['test']}: {c['result']}" for c in result["tests"] if not c["result"].startswith("passed")]
        md.append("")
    md += targets_table(result)
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
            md.append(f"| {name} | error: {a['error']} |")
            continue
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
            try:
                return float(r[k].replace(",", ""))
            except Exception:
                return float("nan")
        for r in ncu:
            if "error" in r:
                md.append(f"| {r['run']} | error: {r['error']} |")
                continue
            kn = r.get("Kernel Name", "?")[:60]
            md.append(f"| {r['run']} | `{kn}` | {num(r, keys[0]):.1f} | {num(r, keys[1]):.1f} | {num(r, keys[2]):.1f} | {num(r, keys[3]):.1f} | "
                      f"{num(r, 'smsp__thread_inst_executed.sum') / paths:.0f} | {num(r, 'smsp__sass_thread_inst_executed_op_integer_pred_on.sum') / paths:.0f} | "
                      f"{num(r, 'smsp__sass_thread_inst_executed_op_fp32_pred_on.sum') / paths:.0f} | {num(r, 'smsp__sass_thread_inst_executed_op_fp64_pred_on.sum') / paths:.1f} |")
        md.append("")
    if result["kernel_report"]:
        md += [result["kernel_report"]]
    return "\n".join(md) + "\n"


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", nargs="?", help="the gpu-check output folder")
    parser.add_argument("--summary", metavar="JSON", help="print the summary of a recorded gpu-check.json")
    args = parser.parse_args(argv)
    if args.summary:
        try:
            result = json.loads(pathlib.Path(args.summary).read_text())
        except (OSError, ValueError) as e:
            print(f"gpu_report: cannot read {args.summary}: {e}", file=sys.stderr)
            return 2
        sys.stdout.write(summary(result))
        return 0
    if not args.out:
        parser.error("needs OUT or --summary JSON")
    out = pathlib.Path(args.out)
    result = collect(out)
    (out / "gpu-check.json").write_text(json.dumps(result, indent=1))
    text = summary(result)
    (out / "summary.md").write_text(text)
    print("\n".join(text.splitlines()[:60]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
