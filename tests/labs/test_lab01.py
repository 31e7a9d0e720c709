"""Lab 01 (serial): the reference passes every correctness check, the skeleton visibly does
not, and both honour the shared command line."""
import subprocess
import sys

import pytest

from grading.checks import analytic
from grading.checks.golden import check_golden
from grading.checks.renderer import CHECKS
from labkit.harness import ROOT, run_lab


@pytest.mark.parametrize("check", list(CHECKS.values()), ids=list(CHECKS))
def test_reference_passes(lab01_ref, check, tmp_path):
    result = check(lab01_ref)
    assert result.passed, str(result)


def test_skeleton_is_visibly_incomplete(lab01_pristine_skeleton):
    """Until students fill it in, the skeleton builds and runs but fails the image checks."""
    skeleton = lab01_pristine_skeleton
    results = [analytic.check_sphere_interior(skeleton), check_golden(skeleton, "cornell")]
    assert not any(r.passed for r in results), "\n".join(map(str, results))


def test_skeleton_renders_something(lab01_pristine_skeleton):
    """...and what it renders is an image, not a crash or a blank: the sphere's flat colour."""
    run = run_lab(lab01_pristine_skeleton, width=32, height=32, spp=1)
    assert run.image is not None and run.image.max() > 0


def test_students_build_runs(lab01):
    """`make lab01` builds the student's copy and it runs (what it renders is graded)."""
    assert run_lab(lab01, width=8, height=8, spp=1).image.shape == (8, 8, 3)


def test_summary_line_and_json(lab01_ref):
    run = run_lab(lab01_ref, width=8, height=6, spp=2, bounces=3, seed=5)
    for key in ("lab", "width", "height", "spp", "bounces", "seconds", "paths_per_second",
                "device"):
        assert key in run.json
    assert (run.json["width"], run.json["height"], run.json["spp"], run.json["bounces"]) == \
        (8, 6, 2, 3)
    assert run.image.shape == (6, 8, 3)
    plain = subprocess.run([str(lab01_ref), "--quiet", "--width", "8", "--height", "6",
                            "--spp", "1"], capture_output=True, text=True, check=True)
    last = plain.stdout.strip().splitlines()[-1]
    assert "8x6" in last and "1 spp" in last and "Mpaths/s" in last


def test_default_scene_settings_are_the_baseline():
    """The report's baseline lives in the default scene: 600x600, 512 spp, 4 bounces."""
    from labkit import scenes
    assert scenes.load("cornell")["render"] == {"width": 600, "height": 600, "spp": 512,
                                                "bounces": 4}


def test_ppm_is_srgb_of_pfm(lab01_ref, tmp_path):
    ppm, pfm = tmp_path / "a.ppm", tmp_path / "a.pfm"
    subprocess.run([str(lab01_ref), "--quiet", "--width", "16", "--height", "16", "--spp", "4",
                    "--out", str(ppm), "--pfm", str(pfm)], check=True)
    import numpy as np

    from labkit.pfm import read_pfm
    linear = np.clip(read_pfm(pfm), 0, 1)
    srgb = np.where(linear <= 0.0031308, 12.92 * linear, 1.055 * linear ** (1 / 2.4) - 0.055)
    data = ppm.read_bytes()
    assert data.startswith(b"P6\n16 16\n255\n")
    codes = np.frombuffer(data[len(b"P6\n16 16\n255\n"):], dtype=np.uint8).reshape(16, 16, 3)
    assert np.abs(codes.astype(float) - srgb * 255).max() <= 0.51


def test_skeletons_in_sync():
    """The committed skeletons are exactly what labkit/skeletons.py makes from the solutions."""
    p = subprocess.run([sys.executable, "-m", "labkit.skeletons", "--check"], cwd=ROOT,
                       capture_output=True, text=True)
    assert p.returncode == 0, p.stderr


def test_skeletons_carry_no_instructor_text():
    """What students receive says nothing of solutions: no markers, no instructor-only ('//!')
    lines, no path into a solution folder."""
    from labkit.variants import pristine_skeleton_sources
    leaks = ["BEGIN SOLUTION", "END SOLUTION", "//!", "solution/", "skeletons.py"]
    for lab in sorted(p.name for p in (ROOT / "labs").iterdir() if (p / "solution").is_dir()):
        for name, text in pristine_skeleton_sources(lab).items():
            found = [leak for leak in leaks if leak in text]
            assert not found, f"labs/{lab}/skeleton/{name} contains {found}"
