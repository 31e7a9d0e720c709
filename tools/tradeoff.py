#!/usr/bin/env python3
"""Speed against accuracy, measured, plotted and checked (`make tradeoff`).

    make tradeoff            every renderer this host runs, on the Cornell baseline and an
                             extreme scene, spp 1..4096, bounces 1..16 (8 min measured on a
                             busy 2-core VM)
    make tradeoff QUICK=1    the CI size: lab01-ref only, small images, fewer points (10-15 s
                             measured on the same VM)
    tools/tradeoff.py --quick --binary PATH   the quick checks on any lab-01-compatible build

Two checks, each failing the run (exit 1, one line `tradeoff: FAIL: ...`):
- unbiased convergence: for every reference renderer the noise-corrected RMSE against spp
  has a log-log slope within -0.5 +- 0.05 and no plateau (tools/tradeoff_fit.py);
- bias against bounces: the energy missing after B bounces in a closed diffuse sphere
  matches its closed form within a Bonferroni limit of standard errors
  (tools/tradeoff_bias.py).
Variants (fast math, fixed ray epsilon) are measured and shown, not checked: showing what
they cost or save is their point. Writes CSV, Markdown and PNG plots to --out
(build/reports/). Exit 2: bad input or a render that failed.
"""
from __future__ import annotations

import argparse
import dataclasses
import pathlib
import shutil
import sys
import tempfile

ROOT = pathlib.Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
from grading.harness import golden  # noqa: E402

import tradeoff_bias  # noqa: E402
import tradeoff_reference  # noqa: E402
import tradeoff_report  # noqa: E402
import tradeoff_scenes  # noqa: E402
import tradeoff_series  # noqa: E402
import tradeoff_sweep  # noqa: E402
from tradeoff_series import Series  # noqa: E402


@dataclasses.dataclass(frozen=True)
class Plan:
    """How much to measure. Images are 64x64 (4096 pixels: each point's MSE is then known
    to ~2%, the fitted slope to ~0.005) and references hold 16x the largest spp."""
    name: str
    labs: tuple | None       # CPU references to sweep (None: all of tradeoff_series')
    max_spp: int
    own_reference: bool      # False: the golden Cornell data (16384 spp), no extreme scene
    variants: bool
    gpu: bool
    bias_size: int           # bias sweep: pixels per side, spp per bounce count
    bias_spp: int
    bias_bounces: tuple
    bias_ref_bounces: int    # any count works: the closed form is of the difference


QUICK = Plan("quick (CI size)", ("lab01-ref",), 1024, False, False, False,
             16, 256, tuple(range(1, 9)), 32)
FULL = Plan("full", None, 4096, True, True, True, 32, 1024, tuple(range(1, 17)), 64)
SIZE, BOUNCES = 64, 4  # the golden data's size and bounces; the extreme scene uses them too


class BadInput(Exception):
    """One line for the user, exit status 2."""


class Parser(argparse.ArgumentParser):
    def error(self, message):  # one line, not argparse's usage block
        raise BadInput(message)


def reference_binary(plan: Plan) -> pathlib.Path:
    """lab03-ref renders the references where it builds (bit for bit lab01-ref's image, on
    every core); lab01-ref otherwise."""
    if plan.own_reference and tradeoff_series.make("lab03-ref") is None:
        return ROOT / "lab03-ref"
    return ROOT / "lab01-ref"


def measured_series(plan: Plan, binary: pathlib.Path | None, given: str | None,
                    log) -> list[Series]:
    if binary is not None:
        # Named as given, so the report's FAIL line says which build failed.
        return [Series(given, f"the build given with --binary ({given})", binary)]
    series = tradeoff_series.cpu_references(plan.labs)
    if plan.gpu:
        series += tradeoff_series.gpu_references()
    if plan.variants:
        series += tradeoff_series.variants(log)
    return series


def main(argv=None) -> int:
    p = Parser(description=__doc__.splitlines()[0])
    p.add_argument("--quick", action="store_true", help="the CI size (QUICK=1)")
    p.add_argument("--out", default=str(ROOT / "build" / "reports"),
                   help="folder for the CSV, Markdown and PNG files (default build/reports)")
    p.add_argument("--note", default="", help="a line for the report (e.g. how busy the "
                   "machine was)")
    p.add_argument("--binary", help="check this build instead of the references (quick plan)")
    try:
        a = p.parse_args(argv)
        binary = pathlib.Path(a.binary).resolve() if a.binary else None
        if binary is not None and not binary.is_file():
            raise BadInput(f"--binary {a.binary}: no such file")
        out = pathlib.Path(a.out)
        if problem := tradeoff_report.cannot_write(out):
            raise BadInput(problem)
        return run(QUICK if a.quick or binary else FULL, out, a.note, binary, a.binary)
    except BadInput as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    except (RuntimeError, ValueError, OSError) as e:
        print(f"error: {str(e).strip().splitlines()[0]}", file=sys.stderr)
        return 2


def run(plan: Plan, out: pathlib.Path, note: str, binary: pathlib.Path | None,
        given: str | None = None) -> int:
    log = lambda *args: print(*args, flush=True)  # noqa: E731
    try:
        import matplotlib  # noqa: F401  (the plots; checked before minutes of rendering)
    except ImportError:
        raise BadInput("matplotlib is not installed for this python: run `make deps`") from None
    machine = tradeoff_report.Machine.here()
    log(f"tradeoff ({plan.name}) on {machine.cpu}, {machine.cores} cores, {machine.date}")
    why = tradeoff_series.make("lab01-ref")
    if why:
        raise RuntimeError(f"lab01-ref {why}")
    ref_bin = reference_binary(plan)
    series = measured_series(plan, binary, given, log)
    runnable = [s for s in series if s.unavailable is None]
    unavailable = [s for s in series if s.unavailable is not None]
    if not plan.gpu:
        unavailable.append(Series("lab05-ref (GPU)", "", unavailable="not in the quick plan"))
    if not plan.variants and binary is None:
        unavailable += [Series(v.name, "", unavailable=v.not_built
                               or "variants are not in the quick plan")
                        for v in tradeoff_series.VARIANTS]
    for s in unavailable:
        log(f"  not measured: {s.name}: {s.unavailable}")

    # Scenes made here go to a folder of this run's own, so two runs at once (a test and a
    # full run) never read each other's half-written file.
    scene_dir = pathlib.Path(tempfile.mkdtemp(prefix="tradeoff-scenes-"))
    try:
        return measure(plan, out, note, machine, ref_bin, runnable, unavailable, scene_dir,
                       log)
    finally:
        shutil.rmtree(scene_dir, ignore_errors=True)


def measure(plan, out, note, machine, ref_bin, runnable, unavailable, scene_dir, log) -> int:
    """The sweeps, the checks and the report; returns the exit status."""
    # ---- spp sweeps ----
    g = golden("cornell")
    scenes = {"cornell": g.scene}
    if plan.own_reference:
        scenes["extreme"] = tradeoff_scenes.write(scene_dir, "extreme", tradeoff_scenes.extreme())
    spps = tradeoff_sweep.spp_list(plan.max_spp)
    sweeps, references, run_failures = [], {}, []
    refs = {}
    for name, path in scenes.items():  # every reference first: then the timed renders run
        if plan.own_reference:        # back to back
            refs[name] = tradeoff_reference.render(ref_bin, path, width=SIZE, height=SIZE,
                                                   bounces=BOUNCES, spp=16 * plan.max_spp,
                                                   log=log)
        else:
            refs[name] = tradeoff_reference.from_golden(name)
        references[name] = (f"{refs[name].made_by}; {SIZE}x{SIZE} pixels, {BOUNCES} bounces, "
                            f"{refs[name].spp} spp")
    for name, path in scenes.items():
        on_scene = runnable if name == "cornell" else [
            s for s in runnable if s.name == "lab01-ref" or not s.checked]
        done, failed = tradeoff_sweep.sweep_all(on_scene, name, path, refs[name], width=SIZE,
                                                height=SIZE, bounces=BOUNCES, spps=spps, log=log)
        sweeps += done
        for s in on_scene:
            if s.name in failed:
                unavailable.append(Series(f"{s.name} on {name}", "", unavailable=failed[s.name]))
                if s.checked:
                    run_failures.append(failed[s.name])

    # ---- bias against bounces ----
    interior = tradeoff_scenes.INTERIOR
    interior_path = tradeoff_scenes.write(scene_dir, "interior",
                                          tradeoff_scenes.off_centre_interior(**interior))
    checked = runnable[0]  # lab01-ref, or the --binary build
    bias_points = tradeoff_bias.sweep(
        checked.name, checked.binary, ref_bin, interior_path, interior,
        bounces=plan.bias_bounces, size=plan.bias_size, spp=plan.bias_spp,
        ref_bounces=plan.bias_ref_bounces, launcher=checked.launcher, log=log)
    params = {k: interior[k] for k in ("albedo", "radius", "intensity")}
    bias_setup = (
        f"Inside a diffuse sphere (albedo rho = {interior['albedo']}, radius {interior['radius']},"
        f" point light of intensity {interior['intensity']} at {list(interior['light'])}, off the"
        f" centre), {plan.bias_size}x{plan.bias_size} pixels, {plan.bias_spp} spp per bounce "
        f"count, against a reference of {16 * plan.bias_spp} spp and {plan.bias_ref_bounces} "
        f"bounces ({ref_bin.name}, other seeds). Closed form of render - reference: <L1> "
        f"(rho^{plan.bias_ref_bounces} - rho^B) / (1 - rho), <L1> = rho I / (pi R^2) = "
        f"{tradeoff_bias.mean_direct(**params):.5f} (tools/tradeoff_bias.py derives it). "
        f"Allowed: {tradeoff_bias.critical_z(tradeoff_bias.ALPHA, len(plan.bias_bounces)):.2f}"
        f" SE (Bonferroni, alpha {tradeoff_bias.ALPHA:g} over {len(plan.bias_bounces)} bounce "
        f"counts) + {tradeoff_bias.ROUNDING:g} of the converged radiance for float rounding.")

    # ---- verdict and report ----
    failures = (run_failures + [s.failed for s in sweeps if s.failed]
                + tradeoff_bias.failures(bias_points))
    machine.load_after = tradeoff_report.load()
    plots = {}
    for name in scenes:
        file = f"tradeoff-error-time-{name}.png"
        tradeoff_report.plot_error_time(out / file, name, [s for s in sweeps if s.scene == name])
        plots[f"error-time-{name}"] = file
    tradeoff_report.plot_bias(out / "tradeoff-bias.png", bias_points, plan.bias_ref_bounces,
                              lambda b: tradeoff_bias.closed_form(
                                  b, plan.bias_ref_bounces, **params))
    plots["bias"] = "tradeoff-bias.png"
    tradeoff_report.write_csvs(out, sweeps, bias_points)
    (out / "tradeoff.md").write_text(tradeoff_report.markdown(
        machine=machine, mode=plan.name, note=note, sweeps=sweeps, references=references,
        unavailable=unavailable, bias_points=bias_points, bias_setup=bias_setup, plots=plots,
        failures=failures))
    log("")
    for line in tradeoff_report.slope_lines(sweeps):
        log(line)
    log(f"report: {out / 'tradeoff.md'} (+ CSV and PNG files)")
    if failures:
        log(f"tradeoff: FAIL: {failures[0]}"
            + (f" (and {len(failures) - 1} more, listed in the report)" if len(failures) > 1
               else ""))
        return 1
    log("tradeoff: PASS: every checked slope is -0.5 +- 0.05 with no plateau, and the bias "
        "matches its closed form at every bounce count")
    return 0


if __name__ == "__main__":
    sys.exit(main())
