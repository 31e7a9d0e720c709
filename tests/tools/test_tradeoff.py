"""`make tradeoff`'s checks: the quick mode passes for the reference renderer, and each check
can fail: made-up error series with the wrong slope or a plateau, a renderer whose samples
are all the same path (correlated seeds: the error stops falling) and one that stops a
bounce early (the bias check's closed form catches it).

CI cost, measured on a busy two-core machine: about a minute (the quick run, two mutants
built by `make variant` and run through the quick checks)."""
import csv
import importlib.util
import math
import random
import subprocess
import sys

import pytest

from grading import scenes
from grading.harness import ROOT, build

sys.path.insert(0, str(ROOT / "tools"))
import tradeoff_bias  # noqa: E402
import tradeoff_fit  # noqa: E402
import tradeoff_series  # noqa: E402
from tradeoff_sweep import Sweep  # noqa: E402

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
    (grading/scenes.py, checked by the grader): the difference of two bounce counts must be
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


def run_tool(*args):
    return subprocess.run([sys.executable, str(ROOT / "tools" / "tradeoff.py"), *map(str, args)],
                          capture_output=True, text=True, timeout=900)


def read_csv(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def test_quick_mode_passes(tmp_path):
    p = subprocess.run(["make", "-s", "-C", str(ROOT), "tradeoff", "QUICK=1",
                        f"REPORTS={tmp_path}"], capture_output=True, text=True, timeout=900)
    assert p.returncode == 0, p.stdout[-3000:] + p.stderr[-2000:]
    assert p.stdout.strip().splitlines()[-1].startswith("tradeoff: PASS")
    fits = read_csv(tmp_path / "tradeoff-fits.csv")
    assert [r["series"] for r in fits] == ["lab01-ref"]
    assert abs(float(fits[0]["slope"]) + 0.5) <= 0.05 and not fits[0]["plateau_spp"]
    bias = read_csv(tmp_path / "tradeoff-bias.csv")
    assert [int(r["bounces"]) for r in bias] == list(range(1, 9))
    assert all(r["pass"] == "pass" for r in bias)
    report = (tmp_path / "tradeoff.md").read_text()
    assert "lab01 double: variants are not in the quick plan" in report and "Verdict: PASS" in report
    for png in ("tradeoff-error-time-cornell.png", "tradeoff-bias.png"):
        assert (tmp_path / png).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
        assert f"]({png})" in report


def lab01_mutant(name, workdir):
    """A mutant of tests/labs/test_lab01_mutants.py (one definition of each bug)."""
    spec = importlib.util.spec_from_file_location(
        "lab01_mutants", ROOT / "tests" / "labs" / "test_lab01_mutants.py")
    mutants = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mutants)
    return mutants.build_mutant(name, workdir)


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
])
def test_bad_input_is_one_line_and_exit_2(args, says):
    p = run_tool(*args)
    assert p.returncode == 2 and p.stdout == "", (p.returncode, p.stdout, p.stderr)
    lines = p.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: ") and says in lines[0], lines
