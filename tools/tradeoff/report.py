"""The report of `make tradeoff`: CSV files, a Markdown page and PNG plots in one folder.

Files: tradeoff.csv (every render of the spp sweeps), tradeoff-fits.csv (one slope per
sweep), tradeoff-bias.csv (the bounce sweep), tradeoff.md (the page: machine, verdicts,
tables, plots), tradeoff-error-time-<scene>.png (log-log error against render time, one line
per renderer) and tradeoff-bias.png (missing energy against bounces, closed form drawn in).
tradeoff.json, what all of them are made from, is tools/tradeoff/record.py's.
"""
from __future__ import annotations

import csv
import dataclasses
import datetime
import math
import os
import pathlib
import platform
import subprocess

from tools.tradeoff import fit as tradeoff_fit


def cannot_write(out: pathlib.Path) -> str | None:
    """Why a report cannot be written to folder `out` (made if missing), or None: checked
    before minutes of rendering, not after."""
    try:
        out.mkdir(parents=True, exist_ok=True)
        (out / ".write-test").touch()
        (out / ".write-test").unlink()
    except OSError as e:
        return f"--out {out}: cannot write there ({e.strerror or e})"
    return None


@dataclasses.dataclass
class Machine:
    cpu: str
    cores: int
    date: str
    load_before: str
    load_after: str = ""
    gpu: str = ""  # 'NAME, driver X' where the run measured a GPU (tradeoff_series.gpu_info)

    @staticmethod
    def here() -> "Machine":
        cpu = platform.processor() or platform.machine()
        try:
            out = subprocess.run(["lscpu"], capture_output=True, text=True).stdout
            cpu = next(line.split(":", 1)[1].strip() for line in out.splitlines()
                       if line.startswith("Model name")) or cpu
        except (OSError, StopIteration):
            pass
        return Machine(cpu, len(os.sched_getaffinity(0)),
                       datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
                       load())

    def line(self) -> str:
        gpu = f", {self.gpu}" if self.gpu else ""
        return (f"{self.cpu}, {self.cores} cores{gpu}, {self.date}; load average "
                f"{self.load_before} at the start, {self.load_after} at the end")


def load() -> str:
    try:
        return " ".join(pathlib.Path("/proc/loadavg").read_text().split()[:3])
    except OSError:
        return "unknown"


# ---- CSV ---------------------------------------------------------------------------------

def _write_csv(path: pathlib.Path, header, rows) -> None:
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(header)
        w.writerows(rows)


def write_csvs(folder: pathlib.Path, sweeps, bias_points) -> None:
    _write_csv(folder / "tradeoff.csv",
               ["series", "scene", "spp", "seconds", "wall_seconds", "rmse", "relmse", "bias",
                "bias_se", "nan", "inf", "z_test", "mse_corrected", "efficiency"],
               [[p.series, p.scene, p.spp, f"{p.seconds:.6f}", f"{p.wall:.4f}", f"{p.rmse:.6g}",
                 f"{p.relmse:.6g}", f"{p.bias:.6g}", f"{p.bias_se:.4g}", p.nan, p.inf,
                 "pass" if p.z_pass else "FAIL", f"{p.mse:.6g}", f"{p.efficiency:.6g}"]
                for s in sweeps for p in s.points])
    _write_csv(folder / "tradeoff-fits.csv",
               ["series", "scene", "checked", "slope", "slope_se", "points", "plateau_spp",
                "verdict"],
               [[s.series, s.scene, s.checked,
                 f"{s.fit.slope:.4f}" if s.fit else "", f"{s.fit.slope_se:.4f}" if s.fit else "",
                 s.fit.points if s.fit else 0, s.plateau or "", _verdict(s)] for s in sweeps])
    _write_csv(folder / "tradeoff-bias.csv",
               ["series", "bounces", "spp", "bias", "se", "closed_form", "allowed", "z", "pass",
                "seconds"],
               [[p.series, p.bounces, p.spp, f"{p.bias:.6g}", f"{p.se:.4g}", f"{p.closed:.6g}",
                 f"{p.allowed:.4g}", f"{p.z:.2f}", "pass" if p.ok else "FAIL", f"{p.seconds:.4f}"]
                for p in bias_points])


def _verdict(s) -> str:
    if s.failed:
        return "FAIL"
    if not s.checked:
        return "shown" + (" (plateau)" if s.plateau is not None else "")
    return "pass"


# ---- plots -------------------------------------------------------------------------------

def plot_error_time(path: pathlib.Path, scene: str, sweeps) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7.5, 5))
    for s in sweeps:
        pts = [p for p in s.points if p.mse > 0 and p.seconds > 0]
        if not pts:
            continue
        style = "-o" if s.checked else "--s"
        label = s.series + (f" (slope {s.fit.slope:+.2f})" if s.fit else "")
        ax.loglog([p.seconds for p in pts], [math.sqrt(p.mse) for p in pts], style,
                  ms=3.5, lw=1.2, label=label)
    ax.set_xlabel("render time, s (the binary's own `seconds`)")
    ax.set_ylabel("RMSE, less the reference's own noise")
    ax.set_title(f"Error against time, scene '{scene}' (slope -1/2 = unbiased)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_bias(path: pathlib.Path, points, ref_bounces: int, closed_form) -> None:
    """Missing energy (reference - render) against bounces, log scale, with the closed form."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7.5, 5))
    for series in dict.fromkeys(p.series for p in points):
        pts = [p for p in points if p.series == series and -p.bias > 0]
        ax.errorbar([p.bounces for p in pts], [-p.bias for p in pts],
                    yerr=[p.se for p in pts], fmt="o", ms=4, capsize=3,
                    label=f"{series}: measured (+- 1 SE)")
    bs = sorted({p.bounces for p in points})
    fine = [b / 4 for b in range(4 * bs[0], 4 * bs[-1] + 1)]
    ax.semilogy(fine, [-closed_form(b) for b in fine], "-", lw=1.2,
                label=f"closed form <L1> (rho^B - rho^{ref_bounces}) / (1 - rho)")
    ax.set_xlabel("bounces B (surface interactions per path)")
    ax.set_ylabel(f"missing radiance: {ref_bounces}-bounce reference - render")
    ax.set_title("Bias against bounces: diffuse sphere interior, light off-centre")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


# ---- Markdown ----------------------------------------------------------------------------

def markdown(*, machine: Machine, mode: str, note: str, sweeps, references: dict,
             unavailable, bias_points, bias_setup: str, plots, failures) -> str:
    L = ["# Speed against accuracy (`make tradeoff`)", ""]
    L.append(f"Measured on {machine.line()}.")
    if note:
        L.append(note)
    L += ["", f"Mode: {mode}. Time is each binary's own `seconds` from `--json` (render only: "
          "no scene loading, no file writing; GPU: kernel time). MSE is RMSE^2 less the "
          "reference's own noise (mean sigma^2 / N); efficiency = 1 / (MSE x seconds).", ""]
    if not plots:
        L += ["Plots: not drawn by this run (--no-plots, or no matplotlib where it ran); "
              "`python3 -m tools.tradeoff --replot DIR` draws them from DIR/tradeoff.json.", ""]
    L.append("**Verdict: " + ("PASS**" if not failures else "FAIL**"))
    L += [f"- {f}" for f in failures] or ["- every checked slope within -0.5 +- 0.05, no "
                                          "plateau; the bias matches its closed form at every "
                                          "bounce count"]
    L.append("")
    for scene, ref in references.items():
        rows = [s for s in sweeps if s.scene == scene]
        L += [f"## Error against samples per pixel: scene `{scene}`", "",
              f"Reference: {ref}.", "",
              "| renderer | slope +- SE | plateau | verdict | spp range | seconds at most spp "
              "| RMSE at most spp | efficiency at most spp | x lab01-ref |",
              "|---|---|---|---|---|---|---|---|---|"]
        base = next((s.points[-1].efficiency for s in rows if s.series == "lab01-ref"), math.nan)
        for s in rows:
            last = s.points[-1]
            slope = f"{s.fit.slope:+.3f} +- {s.fit.slope_se:.3f}" if s.fit else "-"
            plateau = f"from {s.plateau:g} spp" if s.plateau is not None else "none"
            # The longest render times best (start-up and timer noise are smallest there);
            # for an unbiased renderer efficiency does not depend on spp.
            eff = f"{last.efficiency:.4g}" if math.isfinite(last.efficiency) else "-"
            ratio = last.efficiency / base
            ratio = f"{ratio:.2f}" if math.isfinite(ratio) else "-"
            L.append(f"| {s.series} | {slope} | {plateau} | {_verdict(s)} | "
                     f"{s.points[0].spp}..{last.spp} | {last.seconds:.3f} | {last.rmse:.5f} | "
                     f"{eff} | {ratio} |")
        if f"error-time-{scene}" in plots:
            L += ["", f"![error against time, {scene}]({plots[f'error-time-{scene}']})"]
        L += ["", "<details><summary>every render</summary>", "",
              "| renderer | spp | seconds | RMSE | relMSE | bias +- SE | NaN/Inf | z tests |"
              " efficiency |", "|---|---|---|---|---|---|---|---|---|"]
        for s in rows:
            for p in s.points:
                L.append(f"| {p.series} | {p.spp} | {p.seconds:.4f} | {p.rmse:.5f} | "
                         f"{p.relmse:.3g} | {p.bias:+.5f} +- {p.bias_se:.5f} | {p.nan}/{p.inf} | "
                         f"{'pass' if p.z_pass else 'FAIL'} | {p.efficiency:.4g} |")
        L += ["", "</details>", ""]
    if unavailable:
        L += ["## Not measured here", ""] + [f"- {name}: {why}" for name, why in unavailable]
        L.append("")
    L += ["## Bias against bounces", "", bias_setup, "",
          "| renderer | bounces | measured bias +- SE | closed form | (measured - closed) / SE |"
          " allowed | verdict |", "|---|---|---|---|---|---|---|"]
    for p in bias_points:
        L.append(f"| {p.series} | {p.bounces} | {p.bias:+.5f} +- {p.se:.5f} | {p.closed:+.5f} | "
                 f"{p.z:+.2f} | {p.allowed:.5f} | {'pass' if p.ok else 'FAIL'} |")
    if "bias" in plots:
        L += ["", f"![bias against bounces]({plots['bias']})"]
    L.append("")
    return "\n".join(L)


def slope_lines(sweeps) -> list[str]:
    return [f"{s.series:<20} {s.scene:<8} "
            + (tradeoff_fit.describe(s.fit, s.plateau) if s.fit else s.problem or "no fit")
            + f"  [{_verdict(s)}]" for s in sweeps]
