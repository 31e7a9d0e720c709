#!/usr/bin/env python3
"""The tables of handouts/06-cuda-split.md and 07-soa.md from what measure.sh wrote: the
bench-*.json files of lab07-bench and the ncu-*.csv files of Nsight Compute.

    bench_tables.py DIR > DIR/wavefront.md
"""
import csv
import json
import pathlib
import sys

STAGES = ["generate_camera_paths", "find_closest_hits", "shade_hits", "trace_shadow_rays",
          "accumulate_samples"]
NCU_PATHS = 600 * 600 * 5  # the ncu runs: one wave of 600x600 at 5 spp


def bench_tables(path):
    b = json.loads(path.read_text())
    md = [f"### {path.stem}: {pathlib.Path(b['scene']).name}, {b['width']}x{b['height']}, "
          f"{b['spp']} spp, {b['bounces']} bounces ({b['device']})", "",
          f"Timing: {b['timing']}; repeat {b['repeat']}.", "",
          "| configuration | change | best ms | median ms | Gpaths/s | vs megakernel | same bits as first | NaN/Inf pixels |",
          "|---|---|---:|---:|---:|---:|---|---:|"]
    mega = next((c["best_ms"] for c in b["configs"] if c["name"] == "megakernel"), None)
    for c in b["configs"]:
        ratio = f"{mega / c['best_ms']:.2f}x" if mega else "-"
        same = "yes" if c["identical_to_first"] else f"no ({c['max_relative_difference']:.1e})"
        md.append(f"| {c['name']} | {c['change']} | {c['best_ms']:.2f} | {c['median_ms']:.2f} | "
                  f"{c['paths_per_second'] / 1e9:.2f} | {ratio} | {same} | {c['nonfinite_pixels']} |")
    md.append("")
    for c in b["configs"]:
        if "stages" not in c or "-" in c["name"]:
            continue
        md += [f"Per kernel, {c['name']} ({c['waves']} waves of up to {c['wave_paths']} paths, "
               f"{c['bytes_per_path']} bytes of pool and queues a path; times summed over all "
               f"launches, events around each):", "",
               "| kernel | ms | share | registers | local bytes | blocks/SM (128 threads) | occupancy |",
               "|---|---:|---:|---:|---:|---:|---:|"]
        total = sum(s["ms"] for s in c["stages"])
        for s in c["stages"]:
            md.append(f"| {s['kernel']} | {s['ms']:.2f} | {s['ms'] / total:.0%} | {s['registers']} | "
                      f"{s['local_bytes']} | {s['blocks_per_sm']} | {s['occupancy']:.0%} |")
        md += [f"| all | {total:.2f} | | | | | |", ""]
    ref = next((c for c in b["configs"] if "active_paths" in c), None)
    mk = next((c for c in b["configs"] if c["name"] == "megakernel"), None)
    if mk:
        md += [f"Megakernel: {mk['registers']} registers, {mk['local_bytes']} local bytes, "
               f"{mk['blocks_per_sm']} blocks of 64 per SM, occupancy {mk['occupancy']:.0%}.", ""]
    if ref:
        paths = b["width"] * b["height"] * b["spp"]
        md += ["Queue sizes per bounce (all waves), as a share of the camera paths:", "",
               "| bounce | active paths | share | shadow rays | share |", "|---:|---:|---:|---:|---:|"]
        for i, (a, s) in enumerate(zip(ref["active_paths"], ref["shadow_rays"])):
            md.append(f"| {i} | {a} | {a / paths:.1%} | {s} | {s / paths:.1%} |")
        md += [f"| sum | {sum(ref['active_paths'])} | {sum(ref['active_paths']) / paths:.2f} per path | "
               f"{sum(ref['shadow_rays'])} | {sum(ref['shadow_rays']) / paths:.2f} per path |", ""]
    return md


def ncu_tables(out):
    md = []
    for lab in ("lab06-ref", "lab07-ref"):
        f = out / f"ncu-{lab}.csv"
        if not f.exists():
            continue
        rows = list(csv.reader(f.open()))
        try:
            head = next(i for i, r in enumerate(rows) if "Kernel Name" in r)
        except StopIteration:
            md += [f"ncu on {lab}: no kernel rows (see ncu-{lab}.log)", ""]
            continue
        names = rows[head]
        col = {n: i for i, n in enumerate(names)}
        per = {}
        for r in rows[head + 2:]:
            if len(r) != len(names):
                continue
            kernel = next((s for s in STAGES if s in r[col["Kernel Name"]]), r[col["Kernel Name"]][:40])
            acc = per.setdefault(kernel, {})
            for m in names:
                if "__" in m:
                    try:
                        acc[m] = acc.get(m, 0.0) + float(r[col[m]].replace(",", ""))
                    except ValueError:
                        pass
        md += [f"Nsight Compute on {lab}, one wave ({NCU_PATHS} camera paths, 4 bounces), summed per kernel, "
               "bytes per camera path:", "",
               "| kernel | µs | DRAM read B | DRAM write B | L2 B | L1 global load sectors/request |",
               "|---|---:|---:|---:|---:|---:|"]
        for k in STAGES:
            a = per.get(k)
            if not a:
                continue
            req = a.get("l1tex__t_requests_pipe_lsu_mem_global_op_ld.sum", 0)
            sec = a.get("l1tex__t_sectors_pipe_lsu_mem_global_op_ld.sum", 0)
            md.append(f"| {k} | {a.get('gpu__time_duration.sum', 0) / 1e3:.1f} | "
                      f"{a.get('dram__bytes_read.sum', 0) / NCU_PATHS:.1f} | {a.get('dram__bytes_write.sum', 0) / NCU_PATHS:.1f} | "
                      f"{a.get('lts__t_bytes.sum', 0) / NCU_PATHS:.1f} | {sec / req if req else float('nan'):.2f} |")
        md.append("")
    return md


def main():
    out = pathlib.Path(sys.argv[1])
    md = ["# Wavefront measurements (labs 06 and 07)", ""]
    for name in ("cornell", "cornell-16", "showcase", "showcase-16"):
        p = out / f"bench-{name}.json"
        if p.exists():
            try:
                md += bench_tables(p)
            except (ValueError, KeyError) as e:
                md += [f"{p.name}: unreadable ({e})", ""]
    md += ncu_tables(out)
    print("\n".join(md))


if __name__ == "__main__":
    main()
