"""The report of `make bench`: bench.json (everything measured, what --merge reads), bench.csv
(one row per implementation and setting), bench.md (Tables 4-7 beside the course report's
numbers, the machine, the noise) and PNG plots: bench-baseline.png (speedup on the baseline)
and bench-size.png / bench-spp.png / bench-bounces.png (time and speedup along each sweep).
"""
from __future__ import annotations

import csv
import json
import pathlib
import statistics

import matplotlib

matplotlib.use("Agg")  # files only, no display
import matplotlib.pyplot as plt  # noqa: E402

from tools.bench import report_data as report  # noqa: E402

TITLES = {"baseline": "the baseline", "size": "image size (pixels a side)",
          "spp": "samples per pixel", "bounces": "bounces per ray"}
SERIAL = "lab01-ref"


def experiments(plan: dict) -> dict:
    """The same mapping as bench_report.Plan.experiments, from the plan as JSON holds it."""
    def setting(size, spp, bounces):
        return (max(1, round(size / plan["size_div"])), max(1, spp // plan["spp_div"]), bounces)
    b = report.BASELINE
    out = {"baseline": [(None, setting(b["size"], b["spp"], b["bounces"]))]}
    for exp, values in report.SWEEPS.items():
        out[exp] = [(v, setting(**{**b, exp: v})) for v in values]
    return out


def index(rows: list[dict]) -> dict:
    """{(binary, (side, spp, bounces)): row}, each row with its speedup over lab01-ref."""
    by = {(r["binary"], (r["side"], r["spp"], r["bounces"])): r for r in rows}
    for (_binary, s), r in by.items():
        serial = by.get((SERIAL, s))
        r["speedup"] = serial["seconds"] / r["seconds"] if serial else None
    return by


def spread(r: dict) -> float | None:
    t = r.get("runs") or []
    return (max(t) - min(t)) / min(t) if len(t) > 1 else None


def order(rows: list[dict]) -> list[tuple[str, str]]:
    """(binary, label) in the order rows first appear (the tool lists them lab by lab)."""
    seen = {}
    for r in rows:
        seen.setdefault(r["binary"], r.get("label", r["binary"]))
    return list(seen.items())


def report_rows(exp: str) -> dict:
    """{(report row, paired binary): {setting value: (seconds, speedup)}}"""
    out: dict = {}
    for e, row, binary, value, seconds, speedup in report.ROWS:
        if e == exp:
            out.setdefault((row, binary), {})[value] = (seconds, speedup)
    return out


# ---- CSV ----------------------------------------------------------------------------------

def write_csv(path: pathlib.Path, rows: list[dict]) -> None:
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["binary", "implementation", "side", "spp", "bounces", "seconds", "speedup",
                    "runs", "spread", "device"])
        for r in rows:
            sp, sd = r.get("speedup"), spread(r)
            w.writerow([r["binary"], r.get("label", ""), r["side"], r["spp"], r["bounces"],
                        f"{r['seconds']:.6f}", "" if sp is None else f"{sp:.3f}",
                        " ".join(f"{t:.6f}" for t in r.get("runs", [])),
                        "" if sd is None else f"{sd:.3f}", r.get("device", "")])


# ---- Markdown -----------------------------------------------------------------------------

def _cell(r: dict | None) -> str:
    if r is None:
        return "–"
    sp = r.get("speedup")
    return f"{r['seconds']:.3f} s" + ("" if sp is None else f" ({sp:.2f}x)")


def machines(data: dict) -> list[str]:
    m = data["machine"]
    lines = [f"- Measured here: {m['cpu']}, {m['cores']} cores"
             + (f", GPU {m['gpu']}" if m.get("gpu") else ", no GPU") + f"; {m['date']}; "
             f"load average {m.get('load_before', '?')} at the start, "
             f"{m.get('load_after', '?')} at the end."]
    if m.get("capacity"):
        lines.append(f"- Capacity at the start of each round (cores' worth of throughput: "
                     f"{m['cores']} lab01-ref renders at once against one alone, as the grader "
                     f"measures it; it bounds every parallel speedup here): "
                     + ", ".join(f"{c:.2f}" for c in m["capacity"]) + f" of {m['cores']}.")
    for merged in data.get("merged", []):
        g = merged["machine"]
        lines.append(f"- Merged from another machine ({', '.join(merged['binaries'])}): "
                     f"GPU {g.get('gpu') or 'unnamed'}, host CPU {g['cpu']}, {g['cores']} cores; "
                     f"{g['date']}. Their speedups divide this report's lab01-ref time "
                     f"(measured on the machine above) by the GPU time.")
    lines.append(f"- The course report: {report.REPORT_MACHINE}.")
    return lines


def noise(rows: list[dict]) -> str:
    s = [spread(r) for r in rows if spread(r) is not None]
    if not s:
        return "One round per row: no spread measured."
    worst = max((r for r in rows if spread(r) is not None), key=spread)
    return (f"Spread of the rounds, (slowest - fastest) / fastest per row: median "
            f"{statistics.median(s):.0%}, largest {max(s):.0%} ({worst['binary']} at "
            f"{worst['side']}x{worst['side']}, {worst['spp']} spp, {worst['bounces']} bounces).")


def table(exp: str, points, by: dict, impls) -> list[str]:
    num = report.TABLE[exp]
    if exp == "baseline":
        _, s = points[0]
        lines = [f"## Table {num}: the baseline ({s[0]}x{s[0]}, {s[1]} spp, {s[2]} bounces here)",
                 "", "| implementation | binary | this machine | spread | course report |",
                 "|---|---|---|---|---|"]
        theirs = {b: (row, v[None]) for (row, b), v in report_rows(exp).items()}
        for binary, label in impls:
            r = by.get((binary, s))
            sd = spread(r) if r else None
            rep = theirs.get(binary)
            rep_cell = f"{rep[0]}: {rep[1][0]:.2f} s ({rep[1][1]:.2f}x)" if rep else "–"
            lines.append(f"| {label} | {binary} | {_cell(r)} | "
                         f"{'–' if sd is None else f'{sd:.0%}'} | {rep_cell} |")
        for binary, (row, v) in theirs.items():
            if binary not in dict(impls):
                lines.append(f"| (not measured here) | {binary} | – | – | "
                             f"{row}: {v[0]:.2f} s ({v[1]:.2f}x) |")
        return lines + [""]
    head = [f"{v} ({s[0]}x{s[0]})" if exp == "size" else f"{v} ({s[1 if exp == 'spp' else 2]})"
            for v, s in points]
    lines = [f"## Table {num}: {TITLES[exp]} (report's value, value run here in brackets)", "",
             "| implementation | binary | " + " | ".join(head) + " |",
             "|---|---|" + "---|" * len(points)]
    for binary, label in impls:
        lines.append(f"| {label} | {binary} | "
                     + " | ".join(_cell(by.get((binary, s))) for _, s in points) + " |")
    for (row, binary), vals in report_rows(exp).items():
        cells = [f"{vals[v][0]:.2f} s ({vals[v][1]:.2f}x)" if v in vals else "–"
                 for v, _ in points]
        lines.append(f"| course report: {row} | ≈ {binary} | " + " | ".join(cells) + " |")
    return lines + [""]


def markdown(data: dict, by: dict, pngs: list[str]) -> str:
    plan = data["plan"]
    exps = experiments(plan)
    impls = order(data["rows"])
    scaled = plan["size_div"] != 1 or plan["spp_div"] != 1
    lines = ["# The course report's Tables 4-7 on this machine (`make bench`)", ""]
    lines += machines(data)
    lines += ["", f"Plan: {plan['name']}: image sides / {plan['size_div']}, spp / "
              f"{plan['spp_div']}, best of {plan['repeat']} rounds, implementations interleaved "
              "within each round. Seconds: render time as each binary reports it (GPU labs: "
              "kernel time from CUDA events). Speedup: over lab01-ref at the same setting, "
              "measured in the same run."]
    if scaled:
        lines += ["", "The settings are scaled down, so this machine's seconds are not "
                  "comparable with the report's; its speedups are (the work per pixel is the "
                  "same, only the number of pixels or samples differs)."]
    lines += ["", noise(data["rows"])]
    if data.get("note"):
        lines += ["", data["note"]]
    if data.get("skipped"):
        lines += ["", "Not measured here:"] + [f"- {b}: {w}" for b, w in data["skipped"].items()]
    lines += ["", "The report's speedups are over its own serial row (Table 4: without SIMD; "
              "Tables 5-7: with its Vec3 SIMD), as printed; its rows are paired with the "
              "nearest binary here (≈). Its OpenMP used 4 threads and its MPI 8 processes.", ""]
    for exp, points in exps.items():
        lines += table(exp, points, by, impls)
    lines += [f"![{p}]({p})" for p in pngs] + [""]
    return "\n".join(lines)


# ---- plots --------------------------------------------------------------------------------

def plot_baseline(path: pathlib.Path, s, by: dict, impls) -> None:
    theirs = {b: v[None] for (_, b), v in report_rows("baseline").items()}
    names = [b for b, _ in impls if (b, s) in by] + [b for b in theirs
                                                     if b not in [x for x, _ in impls]]
    fig, ax = plt.subplots(figsize=(7, 0.45 * len(names) + 1.5))
    y = range(len(names))
    ours = [by[(b, s)]["speedup"] or 0 if (b, s) in by else 0 for b in names]
    rep = [theirs[b][1] if b in theirs else 0 for b in names]
    ax.barh([i - 0.2 for i in y], ours, height=0.4, label="this machine")
    ax.barh([i + 0.2 for i in y], rep, height=0.4, label="course report (i5-7500, Tesla T4)")
    ax.set_yticks(list(y), names)
    ax.invert_yaxis()
    ax.set_xscale("log")
    ax.set_xlabel("speedup over the serial reference (log)")
    ax.set_title(f"Baseline: {s[0]}x{s[0]}, {s[1]} spp, {s[2]} bounces")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def plot_sweep(path: pathlib.Path, exp: str, points, by: dict, impls) -> None:
    fig, (ax_t, ax_s) = plt.subplots(1, 2, figsize=(11, 4.2))
    xs = [v for v, _ in points]
    colours = {}
    for binary, _ in impls:
        got = [(v, by[(binary, s)]) for v, s in points if (binary, s) in by]
        if not got:
            continue
        line, = ax_t.plot([v for v, _ in got], [r["seconds"] for _, r in got], "o-",
                          label=binary)
        colours[binary] = line.get_color()
        ax_s.plot([v for v, _ in got], [r["speedup"] or float("nan") for _, r in got], "o-",
                  color=line.get_color(), label=binary)
    for (row, binary), vals in report_rows(exp).items():
        v = [x for x in xs if x in vals]
        kw = dict(color=colours.get(binary, "grey"), linestyle="--", marker="x",
                  label=f"report: {row}")
        ax_t.plot(v, [vals[x][0] for x in v], **kw)
        ax_s.plot(v, [vals[x][1] for x in v], **kw)
    for ax in (ax_t, ax_s):
        ax.set_xscale("log", base=2)
        ax.set_yscale("log")
        ax.set_xticks(xs, [str(x) for x in xs])
        ax.set_xlabel(TITLES[exp] + " (the report's value)")
        ax.grid(True, which="both", alpha=0.3)
    ax_t.set_ylabel("render seconds (log)")
    ax_s.set_ylabel("speedup over lab01-ref (log)")
    ax_t.set_title(f"Table {report.TABLE[exp]}: time")
    ax_s.set_title("speedup (solid: this machine; dashed: the report)")
    ax_s.legend(fontsize=7, loc="center left", bbox_to_anchor=(1.02, 0.5))
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def write_all(out: pathlib.Path, data: dict) -> None:
    out.mkdir(parents=True, exist_ok=True)
    by = index(data["rows"])
    impls = order(data["rows"])
    exps = experiments(data["plan"])
    pngs = []
    plot_baseline(out / "bench-baseline.png", exps["baseline"][0][1], by, impls)
    pngs.append("bench-baseline.png")
    for exp in report.SWEEPS:
        plot_sweep(out / f"bench-{exp}.png", exp, exps[exp], by, impls)
        pngs.append(f"bench-{exp}.png")
    (out / "bench.json").write_text(json.dumps(data, indent=1) + "\n")
    write_csv(out / "bench.csv", data["rows"])
    (out / "bench.md").write_text(markdown(data, by, pngs))
