"""`make tradeoff`'s checks: the quick mode passes for the reference renderer, and each check
can fail: made-up error series with the wrong slope or a plateau, a renderer whose samples
are all the same path (correlated seeds: the error stops falling) and one that stops a
bounce early (the bias check's closed form catches it).

Measuring without matplotlib (PLOTS=0, the GPU machine) and drawing later (--replot): the
quick run is made with matplotlib blocked, then replotted; tradeoff.json reads back exactly.
The GPU machine's plan (--plan gpu, tools/gpu/tradeoff.sh) stops in one line where no GPU
can run it, shown here with a stand-in nvidia-smi (skipped where a real GPU is present).

CI cost, measured on a busy two-core machine: about a minute (the quick run, two mutants
built by `make variant` and run through the quick checks); the tests added with --replot
and --plan gpu take a few seconds more (16 s for the whole file on an idle two-core VM with
everything built and the references cached)."""
import csv
import dataclasses
import math
import os
import random
import subprocess
import sys

import pytest

from labkit import scenes
from labkit.harness import ROOT, build
from tools.tradeoff import bias as tradeoff_bias
from tools.tradeoff import fit as tradeoff_fit
from tools.tradeoff import record as tradeoff_record
from tools.tradeoff import report as tradeoff_report
from tools.tradeoff import run as tradeoff
from tools.tradeoff import series as tradeoff_series
from tools.tradeoff.sweep import Point, Sweep

SPP = [1 << k for k in range(11)]


def series(slope, noise=0.01, floor=0.0, seed=1):
    """An error series c * spp^slope, with relative noise like a 64x64 image's MSE estimate
    (~1%) and an optional bias floor (the error then levels off at `floor`)."""
    rng = random.Random(seed)
    return [math.hypot(0.04 * n ** slope, floor) * (1 + noise * rng.gauss(0, 1)) for n in SPP]


def test_slope_of_an_unbiased_series_passes():
    fit = tradeoff_fit.fit_loglog(SPP, series(-0.5))
    assert tradeoff_fit.slope_ok(fit), tradeoff_fit.describe(fit, None)
    assert tradeoff_fit.find_plateau(SPP, series(-0.5)) is None


@pytest.mark.parametrize("slope", [-0.3, -0.6])
def test_slope_fit_rejects_a_wrong_slope(slope):
    fit = tradeoff_fit.fit_loglog(SPP, series(slope))
    assert not tradeoff_fit.slope_ok(fit)
    assert abs(fit.slope - slope) < 0.02  # the fit finds the slope it was given
    failed = Sweep("fake", "cornell", True, [], fit=fit).failed
    assert failed and f"slope {slope:+.3f}"[:10] in failed


def test_plateau_is_flagged_and_fails_a_checked_sweep():
    y = series(-0.5, floor=2e-3)  # a bias of 2e-3: the error stops at ~64 spp
    fit = tradeoff_fit.fit_loglog(SPP, y)
    plateau = tradeoff_fit.find_plateau(SPP, y)
    assert plateau is not None and 32 <= plateau <= 256, plateau
    failed = Sweep("fake", "cornell", True, [], fit=fit, plateau=plateau).failed
    assert failed and "plateau" in failed
    # A variant (not checked) with the same data is shown, not failed.
    assert Sweep("fake", "cornell", False, [], fit=fit, plateau=plateau).failed is None


def test_fit_refuses_bad_data():
    with pytest.raises(ValueError):
        tradeoff_fit.fit_loglog([1, 2, 4], [0.1, 0.0, 0.05])
    with pytest.raises(ValueError):
        tradeoff_fit.fit_loglog([4, 4], [0.1, 0.05])


def test_bias_closed_form_agrees_with_the_centred_interior():
    """With the light at the centre, the render itself is known in closed form
    (labkit/scenes.py, checked by the grader): the difference of two bounce counts must be
    the tool's closed form, which does not depend on where the light is."""
    params = dict(albedo=0.8, radius=2.0, intensity=3.0)
    for b, ref in [(1, 32), (5, 64), (16, 64)]:
        want = (scenes.sphere_interior_radiance(**params, bounces=b)
                - scenes.sphere_interior_radiance(**params, bounces=ref))
        assert tradeoff_bias.closed_form(b, ref, **params) == pytest.approx(want, rel=1e-12)


def test_fixed_epsilon_variant_changes_only_the_offset():
    """The variant's ray.h is today's common/core/ray.h with one line changed: the offset."""
    original = (ROOT / "common" / "core" / "ray.h").read_text().splitlines()
    variant = tradeoff_series.fixed_epsilon_ray_h().splitlines()
    changed = [(a, b) for a, b in zip(original, variant) if a != b]
    assert len(original) == len(variant) and len(changed) == 1, changed
    assert "kRelativeOffset" in changed[0][0] and "0.0001f" in changed[0][1]
    names = [v.name for v in tradeoff_series.VARIANTS]
    double = tradeoff_series.VARIANTS[names.index("lab01 double")]
    assert double.target == "lab01-ref-double" and double.not_built is None


def run_tool(*args, env=None):
    return subprocess.run([sys.executable, "-m", "tools.tradeoff", *map(str, args)], cwd=ROOT,
                          capture_output=True, text=True, timeout=900, env=env)


def read_csv(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def without_matplotlib(tmp_path):
    """An environment whose python cannot import matplotlib, as on the GPU machine."""
    blocker = tmp_path / "no-matplotlib" / "matplotlib"
    blocker.mkdir(parents=True)
    (blocker / "__init__.py").write_text("raise ImportError('matplotlib blocked by the test')\n")
    return {**os.environ, "PYTHONPATH": str(blocker.parent)}


def test_quick_mode_passes_without_matplotlib_and_replots(tmp_path):
    """`make tradeoff QUICK=1 PLOTS=0` measures where matplotlib cannot be imported (the GPU
    machine) and writes no PNG; --replot then draws the plots from tradeoff.json and the
    Markdown differs only by them."""
    out = tmp_path / "report"
    p = subprocess.run(["make", "-s", "-C", str(ROOT), "tradeoff", "QUICK=1", "PLOTS=0",
                        f"REPORTS={out}"], capture_output=True, text=True, timeout=900,
                       env=without_matplotlib(tmp_path))
    assert p.returncode == 0, p.stdout[-3000:] + p.stderr[-2000:]
    assert p.stdout.strip().splitlines()[-1].startswith("tradeoff: PASS")
    fits = read_csv(out / "tradeoff-fits.csv")
    assert [r["series"] for r in fits] == ["lab01-ref"]
    assert abs(float(fits[0]["slope"]) + 0.5) <= 0.05 and not fits[0]["plateau_spp"]
    bias = read_csv(out / "tradeoff-bias.csv")
    assert [int(r["bounces"]) for r in bias] == list(range(1, 9))
    assert all(r["pass"] == "pass" for r in bias)
    measured = (out / "tradeoff.md").read_text()
    assert "lab01 double: not in the quick plan" in measured and "Verdict: PASS" in measured
    assert "--replot" in measured and not list(out.glob("*.png")) and ".png" not in measured
    record = (out / "tradeoff.json").read_text()

    p = run_tool("--replot", out)
    assert p.returncode == 0, p.stdout[-3000:] + p.stderr[-2000:]
    report = (out / "tradeoff.md").read_text()
    pngs = ("tradeoff-error-time-cornell.png", "tradeoff-bias.png")
    for png in pngs:
        assert (out / png).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
        assert f"]({png})" in report
    assert (out / "tradeoff.json").read_text() == record
    drop = lambda text, *words: [ln for ln in text.splitlines()  # noqa: E731
                                 if ln and not any(w in ln for w in words)]
    assert drop(report, *pngs) == drop(measured, "--replot")


def test_plots_without_matplotlib_are_refused_at_once(tmp_path):
    p = run_tool("--quick", "--out", tmp_path, env=without_matplotlib(tmp_path))
    assert p.returncode == 2 and p.stdout == "", (p.stdout, p.stderr)
    lines = p.stderr.strip().splitlines()
    assert len(lines) == 1 and "matplotlib" in lines[0] and "--no-plots" in lines[0], lines


def fake_record():
    """A record with what real runs produce at the edges: NaN efficiency, infinite SE."""
    point = Point("lab05-ref", "cornell", 1, 2e-5, 0.4, 0.04, 0.07, -2e-4, 5e-4, 0, 0, True,
                  1.6e-3, math.nan)
    sweep = Sweep("lab05-ref", "cornell", True, [point, dataclasses.replace(point, spp=2)],
                  fit=tradeoff_fit.Fit(-0.5, -3.2, 0.001, 2), plateau=None)
    bias = tradeoff_bias.BiasPoint("lab01-ref", 1, 256, -0.76, math.inf, -0.76, math.inf,
                                   0.01, 0)
    machine = tradeoff_report.Machine("a CPU", 16, "2026-12-02 06:00 UTC", "0.1 0.2 0.3",
                                      "0.4 0.5 0.6", "NVIDIA H200, driver 580")
    return tradeoff_record.Record(machine, "gpu", "a note", [sweep], {"cornell": "golden"},
                                  [("lab02-ref", "not in the gpu plan")], [bias], "setup", 32,
                                  {"albedo": 0.8, "radius": 2.0, "intensity": 3.0}, [])


def test_record_round_trips_exactly(tmp_path):
    """What --replot reads back is what the run measured: the same JSON bytes when saved
    again, the same Markdown, non-finite values included (written as strings: strict JSON)."""
    record = fake_record()
    path = tmp_path / "tradeoff.json"
    tradeoff_record.save(path, record)
    text = path.read_text()
    assert "NaN" not in text and "Infinity" not in text and '"nan"' in text and '"inf"' in text
    back = tradeoff_record.load(path)
    assert math.isnan(back.sweeps[0].points[0].efficiency) and back.bias_points[0].ok
    assert back.sweeps[0].fit == record.sweeps[0].fit and back.machine == record.machine
    tradeoff_record.save(tmp_path / "again.json", back)
    assert (tmp_path / "again.json").read_text() == text
    page = dict(bias_setup="setup", plots={}, failures=[])
    assert (tradeoff_report.markdown(machine=back.machine, mode=back.mode, note=back.note,
                                     sweeps=back.sweeps, references=back.references,
                                     unavailable=back.unavailable,
                                     bias_points=back.bias_points, **page)
            == tradeoff_report.markdown(machine=record.machine, mode=record.mode,
                                        note=record.note, sweeps=record.sweeps,
                                        references=record.references,
                                        unavailable=record.unavailable,
                                        bias_points=record.bias_points, **page))
    assert "NVIDIA H200, driver 580" in tradeoff_report.markdown(
        machine=back.machine, mode="gpu", note="", sweeps=[], references={}, unavailable=[],
        bias_points=[], **page)


def test_replot_refuses_what_is_not_a_record(tmp_path):
    (tmp_path / "tradeoff.json").write_text('{"format": "bench-report rows v1"}')
    p = run_tool("--replot", tmp_path)
    assert p.returncode == 2 and p.stdout == ""
    lines = p.stderr.strip().splitlines()
    assert len(lines) == 1, lines
    assert "not a record written by python3 -m tools.tradeoff" in lines[0], lines


def test_gpu_plan_leaves_out_what_it_says():
    plan = tradeoff.PLANS["gpu"]
    left_out = dict(tradeoff.not_in_plan(plan))
    assert set(left_out) == {"lab02a-ref", "lab02-ref", "lab04-ref", "lab04-simd-ref",
                             "lab01 fast-math", "lab01 fixed-epsilon"}
    assert all(why == "not in the gpu plan" for why in left_out.values())
    assert plan.gpu and plan.needs_gpu and plan.max_spp == tradeoff.FULL.max_spp
    # Every GPU reference, and lab 05's double and fast-math builds as variants beside it.
    assert [name for name, *_ in tradeoff_series.GPU_REFERENCES] == [
        "lab05-ref", "lab05 double", "lab05 fast-math", "lab06-ref", "lab07-ref"]
    targets = {target for _, target, *_ in tradeoff_series.GPU_REFERENCES}
    script = (ROOT / "tools" / "gpu" / "tradeoff.sh").read_text()
    assert all(t in script for t in targets), "tools/gpu/tradeoff.sh builds every GPU reference"
    assert "lab05-ref" in tradeoff.EXTREME_CHECKED


def fake_nvidia_smi(folder, gpu_listed):
    """An nvidia-smi on PATH that lists an H200 (compute capability 9.0), or no GPU."""
    folder.mkdir(parents=True, exist_ok=True)
    answer = ('case "$*" in *compute_cap*) echo 9.0;; *driver_version*) echo "NVIDIA H200, '
              '580.00";; *) echo "NVIDIA H200";; esac' if gpu_listed else "exit 0")
    (folder / "nvidia-smi").write_text(f"#!/bin/sh\n{answer}\n")
    (folder / "nvidia-smi").chmod(0o755)
    return {**os.environ, "PATH": f"{folder}:{os.environ['PATH']}"}


@pytest.mark.skipif(tradeoff_series.gpu_missing() is None, reason="a real GPU is present")
@pytest.mark.parametrize("gpu_listed, says", [
    (False, "no NVIDIA GPU (nvidia-smi lists none)"),
    (True, "lab05-ref: does not build here: lab05-ref: needs the CUDA toolkit"),
])
def test_gpu_plan_without_a_usable_gpu_is_one_line(tmp_path, gpu_listed, says):
    """--plan gpu stops before rendering when lab05-ref cannot run (here: no GPU listed, or
    no nvcc), with one line saying why."""
    build("lab01-ref")
    env = fake_nvidia_smi(tmp_path / "bin", gpu_listed)
    env["NVCC"] = "/no/such/nvcc"  # make's `NVCC ?= nvcc` takes it: lab05-ref cannot build
    p = run_tool("--plan", "gpu", "--no-plots", "--out", tmp_path / "report", env=env)
    assert p.returncode == 2, (p.stdout, p.stderr)
    lines = p.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: the gpu plan needs "), lines
    assert says in lines[0], lines
    assert not (tmp_path / "report" / "tradeoff.md").exists()


def test_a_gpu_build_without_a_gpu_does_not_run(tmp_path):
    """What lab05-ref says where the driver is missing is the reason the report gives."""
    fake = tmp_path / "lab05-ref"
    fake.write_text("#!/bin/sh\necho 'error: GPU: no usable CUDA GPU: no NVIDIA driver "
                    "(cudaErrorInsufficientDriver)' >&2\nexit 3\n")
    fake.chmod(0o755)
    assert tradeoff_series.does_not_run(fake) == (
        "does not run here: GPU: no usable CUDA GPU: no NVIDIA driver "
        "(cudaErrorInsufficientDriver)")
    assert tradeoff_series.does_not_run(build("lab01-ref")[0]) is None


def run_gpu_script(out, env):
    return subprocess.run(["bash", str(ROOT / "tools" / "gpu" / "tradeoff.sh"), str(out)],
                          capture_output=True, text=True, timeout=300,
                          env={**env, "TRADEOFF_GPU_DRY_RUN": "1"})


@pytest.mark.skipif(tradeoff_series.gpu_missing() is None, reason="a real GPU is present")
def test_gpu_script_builds_for_the_gpu_present_and_runs_the_gpu_plan(tmp_path):
    """tools/gpu/tradeoff.sh, dry: with an H200 listed it compiles CUDA code for sm_90 only
    and runs the gpu plan without plots into DIR/tradeoff; with none listed it stops at once."""
    p = run_gpu_script(tmp_path / "none", fake_nvidia_smi(tmp_path / "none-bin", False))
    assert p.returncode == 2 and "no NVIDIA GPU here" in p.stdout, p.stdout + p.stderr
    assert "would run" not in p.stdout

    out = tmp_path / "h200"
    p = run_gpu_script(out, fake_nvidia_smi(tmp_path / "h200-bin", True))
    assert p.returncode == 0, p.stdout + p.stderr
    assert "CUDA code for: -gencode arch=compute_90,code=sm_90 \n" in p.stdout, p.stdout
    make_line = next(ln for ln in p.stdout.splitlines() if "would run: make" in ln)
    assert {"lab01-ref", "lab05-ref", "lab05-ref-double"} <= set(make_line.split()), make_line
    assert f"python3 -m tools.tradeoff --plan gpu --no-plots --out {out}/tradeoff" in p.stdout
    assert {f.name for f in out.iterdir()} == {"log.txt", "machine.txt", "tradeoff"}


def lab01_mutant(name, workdir):
    """A mutant of tests/labs/test_lab01_mutants.py (one definition of each bug)."""
    from tests.labs.test_lab01_mutants import build_mutant
    return build_mutant(name, workdir)


def test_correlated_samples_fail_the_slope_check(tmp_path):
    """Every sample of a pixel reuses sample 0's random numbers: more samples add nothing,
    the error stays flat."""
    build("lab01-ref")
    binary = lab01_mutant("every sample reuses sample 0", tmp_path / "mutant")
    p = run_tool("--binary", binary, "--out", tmp_path / "report")
    assert p.returncode == 1, p.stdout[-3000:] + p.stderr[-2000:]
    last = p.stdout.strip().splitlines()[-1]
    assert last.startswith("tradeoff: FAIL:") and "slope" in last and "cornell" in last, last
    fit = read_csv(tmp_path / "report" / "tradeoff-fits.csv")[0]
    assert float(fit["slope"]) > -0.1 and fit["verdict"] == "FAIL", fit


def test_one_bounce_too_few_fails_the_bias_check(tmp_path):
    """A path that stops one interaction early misses rho^(B-1) <L1> / (1 - rho) instead of
    rho^B <L1> / (1 - rho): far outside the bias check's limit at every bounce count."""
    build("lab01-ref")
    binary = lab01_mutant("one bounce too few", tmp_path / "mutant")
    p = run_tool("--binary", binary, "--out", tmp_path / "report")
    assert p.returncode == 1, p.stdout[-3000:] + p.stderr[-2000:]
    assert p.stdout.strip().splitlines()[-1].startswith("tradeoff: FAIL:")
    bias = read_csv(tmp_path / "report" / "tradeoff-bias.csv")
    caught = [int(r["bounces"]) for r in bias if r["pass"] == "FAIL"]
    # At 1 bounce the mutant still makes its one interaction; from 2 on it is one short.
    assert caught == list(range(2, 9)), caught


@pytest.mark.parametrize("args, says", [
    (["--binary", "/nonexistent/lab"], "no such file"),
    (["--quick", "--out", "/proc/no-such-folder"], "cannot write there"),
    (["--bounces", "3"], "unrecognized arguments"),
    (["--quick", "--plan", "gpu"], "choose one"),
    (["--plan", "gpus"], "invalid choice"),
    (["--replot", "/nonexistent/report"], "cannot read it"),
    (["--replot", "/nonexistent/report", "--quick"], "give it nothing else"),
])
def test_bad_input_is_one_line_and_exit_2(args, says):
    p = run_tool(*args)
    assert p.returncode == 2 and p.stdout == "", (p.returncode, p.stdout, p.stderr)
    lines = p.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: ") and says in lines[0], lines
