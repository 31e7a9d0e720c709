"""The precision switch (common/core/real.h): `make lab01-ref-double` and `make
lab05-ref-double` build the same renderer with `real` = double, from the same scene files and
command line. The double build passes every correctness check lab 01's reference passes, says
"double" in --json, and really computes in double (tests/precision/test_double.cpp); the
float build says "float". The double build accepts the wider scenes double can hold
(common/host/scene_limits.h) which the float build refuses in one line."""
import os
import subprocess

import pytest

from grading import checks
from grading.renderer_checks import CHECKS
from labkit import scenes
from labkit.harness import ROOT, build, run_lab


@pytest.fixture(scope="module")
def lab01_ref_double():
    return build("lab01-ref-double")[0]




@pytest.mark.parametrize("check", CHECKS.values(), ids=CHECKS.keys())
def test_double_build_passes(lab01_ref_double, check):
    result = check(lab01_ref_double)
    assert result.passed, str(result)


def test_json_says_double(lab01_ref_double):
    assert run_lab(lab01_ref_double, width=4, height=4, spp=1).json["precision"] == "double"


def test_json_says_float(lab01_ref):
    assert run_lab(lab01_ref, width=4, height=4, spp=1).json["precision"] == "float"


def test_double_build_differs_from_float_by_rounding_only(lab01_ref, lab01_ref_double):
    """The same random numbers in both builds: the images differ, but only a little (were
    they equal, the switch would have done nothing)."""
    settings = dict(width=24, height=24, spp=8, seed=3)
    single = run_lab(lab01_ref, **settings).image
    double = run_lab(lab01_ref_double, **settings).image
    assert (single != double).any(), "the double build rendered the float build's bits"
    # Most pixels agree closely; a path that rounding sends another way changes one sample
    # of a pixel's 8, so the mean over the image stays small.
    assert abs(double.mean() / single.mean() - 1) < 1e-2


def test_computes_in_double():
    """tests/precision/test_double.cpp, built with -DRT_DOUBLE: quantities float cannot
    resolve (a sphere 1e8 from the origin, an edge function below double rounding); and
    tests/unit/test_t_junctions.cpp, written in `real`, in double (rooms watertight where
    walls meet part-way along an edge)."""
    binary = build("build/precision_tests_double")[0]
    p = subprocess.run([str(binary), "--gtest_brief=1"], capture_output=True, text=True)
    assert p.returncode == 0, p.stdout + p.stderr


def test_double_build_accepts_wider_scales(lab01_ref, lab01_ref_double, tmp_path):
    """The sphere interior scaled to radius 1e12: past float's bounds (1e9, one error line),
    within double's (1e30): the double build renders it like the unit-size scene."""
    def interior(scale):
        scene = scenes.sphere_interior(**checks.INTERIOR)
        return scenes.write_scene(tmp_path / f"scaled-{scale:g}.json",
                                  scenes.scaled(scene, scale))
    big = interior(1e12)
    p = subprocess.run([str(lab01_ref), "--quiet", "--scene", str(big), "--width", "4",
                        "--height", "4", "--spp", "1"], capture_output=True, text=True)
    lines = p.stderr.strip().splitlines()
    assert p.returncode != 0 and len(lines) == 1 and "1e9" in lines[0], p.stderr
    settings = dict(width=8, height=8, spp=4, bounces=2)
    want = scenes.sphere_interior_radiance(**checks.INTERIOR, bounces=2)
    image = run_lab(lab01_ref_double, big, **settings).image
    assert abs(image / want - 1).max() < 3e-4


def test_lab05_double_builds(nvcc):
    """nvcc compiles the megakernel with real = double (CI has nvcc, not a GPU). Where a
    GPU is, test_lab05.py's test_double_build_passes renders with it (tools/gpu/check.sh
    runs that file)."""
    binary = build("lab05-ref-double")[0]
    assert os.access(binary, os.X_OK)


def test_mixing_double_and_float_objects_fails_to_link(tmp_path):
    """Lab 01's solution compiled in double and linked with the float driver (`make variant`
    with -DRT_DOUBLE) would read pixels of another layout: the link must fail instead."""
    (tmp_path / "render.cpp").write_text(
        (ROOT / "labs" / "01-serial" / "solution" / "render.cpp").read_text())
    p = subprocess.run(["make", "-s", "-C", str(ROOT), "variant", "VARIANT_LAB=01-serial",
                        f"VARIANT={tmp_path}", "VARIANT_FLAGS_01-serial=-DRT_DOUBLE"],
                       capture_output=True, text=True, timeout=300)
    assert p.returncode != 0 and "undefined reference to `render(" in p.stderr, \
        p.stdout + p.stderr
    assert not (tmp_path / "lab").exists()
