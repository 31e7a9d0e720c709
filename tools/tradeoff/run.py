"""Speed against accuracy, measured, plotted and checked (`make tradeoff`).

    make tradeoff            every renderer this host runs, on the Cornell baseline and an
                             extreme scene, spp 1..4096, bounces 1..16 (8 min measured on a
                             busy 2-core VM)
    make tradeoff QUICK=1    the CI size: lab01-ref only, small images, fewer points (10-15 s
                             measured on the same VM)
    python3 -m tools.tradeoff --quick --binary PATH   the quick checks on any lab-01-
                             compatible build
    python3 -m tools.tradeoff --plan gpu --no-plots   on a GPU machine without matplotlib
                             (tools/gpu/tradeoff.sh): lab01-ref as the baseline, OpenMP on
                             every core, the GPU labs' references, lab 05's double and fast-
                             math builds; no PNGs
    python3 -m tools.tradeoff --replot DIR            here, afterwards: the plots and
                             Markdown of the report in DIR, drawn from its tradeoff.json

Two checks, each failing the run (exit 1, one line `tradeoff: FAIL: ...`):
- unbiased convergence: for every reference renderer the noise-corrected RMSE against spp
  has a log-log slope within -0.5 +- 0.05 and no plateau (tools/tradeoff/fit.py);
- bias against bounces: the energy missing after B bounces in a closed diffuse sphere
  matches its closed form within a Bonferroni limit of standard errors
  (tools/tradeoff/bias.py).
Variants (fast math, fixed ray epsilon) are measured and shown, not checked: showing what
they cost or save is their point. Writes CSV, Markdown, tradeoff.json (everything the
report is made from, tools/tradeoff/record.py) and PNG plots (not with --no-plots) to --out
(build/reports/). Exit 2: bad input or a render that failed.
"""
from __future__ import annotations

import argparse
import dataclasses
import pathlib
import shutil
import sys
import tempfile

from labkit.harness import golden
from tools.tradeoff import bias as tradeoff_bias
from tools.tradeoff import record as tradeoff_record
from tools.tradeoff import reference as tradeoff_reference
from tools.tradeoff import report as tradeoff_report
from tools.tradeoff import scenes as tradeoff_scenes
from tools.tradeoff import series as tradeoff_series
from tools.tradeoff import sweep as tradeoff_sweep
from tools.tradeoff.series import Series

ROOT = pathlib.Path(__file__).resolve().parents[2]


@dataclasses.dataclass(frozen=True)
class Plan:
    """How much to measure. Images are 64x64 (4096 pixels: each point's MSE is then known
    to ~2%, the fitted slope to ~0.005) and references hold 16x the largest spp."""
    name: str                # its first word is what --plan calls it
    labs: tuple | None       # CPU references to sweep (None: all of tradeoff_series')
    max_spp: int
    own_reference: bool      # False: the golden Cornell data (16384 spp), no extreme scene
    variants: tuple | None   # names of tradeoff_series.VARIANTS to measure (None: all)
    gpu: bool                # the GPU references where a GPU is present
    bias_size: int           # bias sweep: pixels per side, spp per bounce count
    bias_spp: int
    bias_bounces: tuple
    bias_ref_bounces: int    # any count works: the closed form is of the difference
    needs_gpu: bool = False  # refuse to start (exit 2) when a GPU reference cannot run


QUICK = Plan("quick (CI size)", ("lab01-ref",), 1024, False, (), False,
             16, 256, tuple(range(1, 9)), 32)
FULL = Plan("full", None, 4096, True, None, True, 32, 1024, tuple(range(1, 17)), 64)
# The GPU machine's plan (tools/gpu/tradeoff.sh): FULL's sweeps for the GPU references, with
# lab01-ref as the efficiency baseline, OpenMP on every core as the CPU's best, and lab 01's
# double build beside lab 05's. 124 s on the H200 machine's 16 cores
# (reference/reports/tradeoff-h200/).
GPU = Plan("gpu", ("lab01-ref", "lab03-ref", "lab03-simd-ref"), 4096, True, ("lab01 double",),
           True, 32, 1024, tuple(range(1, 17)), 64, needs_gpu=True)
PLANS = {plan.name.split()[0]: plan for plan in (FULL, QUICK, GPU)}
SIZE, BOUNCES = 64, 4  # the golden data's size and bounces; the extreme scene uses them too
# Renderers checked on the extreme scene too: the float baselines of the CPU and the GPU (the
# variants, shown there, are compared with them).
EXTREME_CHECKED = ("lab01-ref", "lab05-ref")


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
    # The GPU first: a plan that needs one stops here, before minutes of building and
    # rendering on the CPU.
    gpu = tradeoff_series.gpu_references() if plan.gpu else []
    if plan.needs_gpu and (missing := next((s for s in gpu if s.unavailable), None)):
        raise BadInput(f"the {plan.name} plan needs {missing.name}: {missing.unavailable}")
    series = tradeoff_series.cpu_references(plan.labs) + gpu
    return series + tradeoff_series.variants(plan.variants, log)


def not_in_plan(plan: Plan) -> list[tuple[str, str]]:
    """(name, why) of each renderer the plan leaves out, for the report's "Not measured"."""
    why = f"not in the {plan.name.split()[0]} plan"
    out = [(name, why) for name, _, _ in tradeoff_series.CPU_REFERENCES
           if plan.labs is not None and name not in plan.labs]
    if not plan.gpu:
        out += [(name, why) for name, *_ in tradeoff_series.GPU_REFERENCES]
    return out + [(v.name, v.not_built or why) for v in tradeoff_series.VARIANTS
                  if plan.variants is not None and v.name not in plan.variants]


def main(argv=None) -> int:
    p = Parser(description=__doc__.splitlines()[0])
    p.add_argument("--quick", action="store_true", help="the CI size (QUICK=1); --plan quick")
    p.add_argument("--plan", choices=sorted(PLANS), help="what to measure (default full; gpu: "
                   "the GPU machine's, refused without a GPU)")
    p.add_argument("--out", default=str(ROOT / "build" / "reports"),
                   help="folder for the CSV, Markdown and PNG files (default build/reports)")
    p.add_argument("--note", default="", help="a line for the report (e.g. how busy the "
                   "machine was)")
    p.add_argument("--binary", help="check this build instead of the references (quick plan)")
    p.add_argument("--no-plots", action="store_true", help="no PNGs and no matplotlib (PLOTS=0):"
                   " --replot draws them later from tradeoff.json")
    p.add_argument("--replot", metavar="DIR", help="draw the plots and Markdown of the report "
                   "in DIR from its tradeoff.json; measures nothing")
    try:
        a = p.parse_args(argv)
        if a.replot:
            if a.quick or a.plan or a.binary or a.no_plots or a.note:
                raise BadInput("--replot only redraws a report: give it nothing else")
            return replot(pathlib.Path(a.replot))
        if a.quick and a.plan not in (None, "quick"):
            raise BadInput(f"--quick and --plan {a.plan}: choose one")
        binary = pathlib.Path(a.binary).resolve() if a.binary else None
        if binary is not None and not binary.is_file():
            raise BadInput(f"--binary {a.binary}: no such file")
        if binary is not None and a.plan not in (None, "quick"):
            raise BadInput(f"--binary runs the quick plan, not --plan {a.plan}")
        out = pathlib.Path(a.out)
        if problem := tradeoff_report.cannot_write(out):
            raise BadInput(problem)
        plan = QUICK if a.quick or binary else PLANS[a.plan or "full"]
        return run(plan, out, a.note, binary, a.binary, plots=not a.no_plots)
    except BadInput as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    except (RuntimeError, ValueError, OSError) as e:
        print(f"error: {str(e).strip().splitlines()[0]}", file=sys.stderr)
        return 2


def run(plan: Plan, out: pathlib.Path, note: str, binary: pathlib.Path | None,
        given: str | None = None, plots: bool = True) -> int:
    log = lambda *args: print(*args, flush=True)  # noqa: E731
    if plots:
        need_matplotlib()  # checked before minutes of rendering, not after
    machine = tradeoff_report.Machine.here()
    if plan.gpu:
        machine.gpu = tradeoff_series.gpu_info() or ""
    log(f"tradeoff ({plan.name}) on {machine.cpu}, {machine.cores} cores"
        f"{', ' + machine.gpu if machine.gpu else ''}, {machine.date}")
    why = tradeoff_series.make("lab01-ref")
    if why:
        raise RuntimeError(f"lab01-ref {why}")
    series = measured_series(plan, binary, given, log)
    ref_bin = reference_binary(plan)
    runnable = [s for s in series if s.unavailable is None]
    unavailable = [(s.name, s.unavailable) for s in series if s.unavailable is not None]
    if binary is None:
        unavailable += not_in_plan(plan)
    for name, why in unavailable:
        log(f"  not measured: {name}: {why}")

    # Scenes made here go to a folder of this run's own, so two runs at once (a test and a
    # full run) never read each other's half-written file.
    scene_dir = pathlib.Path(tempfile.mkdtemp(prefix="tradeoff-scenes-"))
    try:
        return measure(plan, out, note, machine, ref_bin, runnable, unavailable, scene_dir,
                       log, plots)
    finally:
        shutil.rmtree(scene_dir, ignore_errors=True)


def need_matplotlib() -> None:
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        raise BadInput("matplotlib is not installed for this python: run `make deps`, or "
                       "measure with --no-plots (PLOTS=0) and draw later with --replot") from None


def measure(plan, out, note, machine, ref_bin, runnable, unavailable, scene_dir, log,
            plots) -> int:
    """The sweeps, the checks and the report (with PNGs when `plots`); returns the exit
    status."""
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
            s for s in runnable if s.name in EXTREME_CHECKED or not s.checked]
        done, failed = tradeoff_sweep.sweep_all(on_scene, name, path, refs[name], width=SIZE,
                                                height=SIZE, bounces=BOUNCES, spps=spps, log=log)
        sweeps += done
        for s in on_scene:
            if s.name in failed:
                unavailable.append((f"{s.name} on {name}", failed[s.name]))
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
        f"{tradeoff_bias.mean_direct(**params):.5f} (tools/tradeoff/bias.py derives it). "
        f"Allowed: {tradeoff_bias.critical_z(tradeoff_bias.ALPHA, len(plan.bias_bounces)):.2f}"
        f" SE (Bonferroni, alpha {tradeoff_bias.ALPHA:g} over {len(plan.bias_bounces)} bounce "
        f"counts) + {tradeoff_bias.ROUNDING:g} of the converged radiance for float rounding.")

    # ---- verdict and report ----
    failures = (run_failures + [s.failed for s in sweeps if s.failed]
                + tradeoff_bias.failures(bias_points))
    machine.load_after = tradeoff_report.load()
    record = tradeoff_record.Record(
        machine=machine, mode=plan.name, note=note, sweeps=sweeps, references=references,
        unavailable=unavailable, bias_points=bias_points, bias_setup=bias_setup,
        bias_ref_bounces=plan.bias_ref_bounces, interior=params, failures=failures)
    publish(out, record, plots)
    log("")
    for line in tradeoff_report.slope_lines(sweeps):
        log(line)
    log(f"report: {out / 'tradeoff.md'} (+ CSV, JSON{' and PNG' if plots else ''} files)")
    if failures:
        log(f"tradeoff: FAIL: {failures[0]}"
            + (f" (and {len(failures) - 1} more, listed in the report)" if len(failures) > 1
               else ""))
        return 1
    log("tradeoff: PASS: every checked slope is -0.5 +- 0.05 with no plateau, and the bias "
        "matches its closed form at every bounce count")
    return 0


def publish(out: pathlib.Path, r: tradeoff_record.Record, plots: bool) -> None:
    """The report's files from `r`: CSV, JSON, Markdown, and the PNG plots when asked. One
    function for a run and for --replot, so a report drawn later reads as if drawn at once."""
    for old in out.glob("tradeoff-*.png"):  # an earlier run's plot must not sit beside this
        old.unlink()                          # run's numbers
    drawn = {}
    if plots:
        for scene in r.references:
            file = f"tradeoff-error-time-{scene}.png"
            tradeoff_report.plot_error_time(out / file, scene,
                                            [s for s in r.sweeps if s.scene == scene])
            drawn[f"error-time-{scene}"] = file
        if r.bias_points:
            tradeoff_report.plot_bias(out / "tradeoff-bias.png", r.bias_points,
                                      r.bias_ref_bounces, lambda b: tradeoff_bias.closed_form(
                                          b, r.bias_ref_bounces, **r.interior))
            drawn["bias"] = "tradeoff-bias.png"
    tradeoff_report.write_csvs(out, r.sweeps, r.bias_points)
    tradeoff_record.save(out / tradeoff_record.FILE, r)
    (out / "tradeoff.md").write_text(tradeoff_report.markdown(
        machine=r.machine, mode=r.mode, note=r.note, sweeps=r.sweeps, references=r.references,
        unavailable=r.unavailable, bias_points=r.bias_points, bias_setup=r.bias_setup,
        plots=drawn, failures=r.failures))


def replot(folder: pathlib.Path) -> int:
    """--replot: the plots and Markdown of the report in `folder`, from its tradeoff.json (a
    run with --no-plots, e.g. on the GPU machine). Exit 0 once drawn: the verdict is the
    measuring run's, written in the report."""
    need_matplotlib()
    record = tradeoff_record.load(folder / tradeoff_record.FILE)
    if problem := tradeoff_report.cannot_write(folder):
        raise BadInput(problem)
    publish(folder, record, plots=True)
    print(f"replotted {folder / 'tradeoff.md'} from {tradeoff_record.FILE} (measured "
          f"{record.machine.date}; verdict {'FAIL' if record.failures else 'PASS'})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
