"""The precision switch (common/core/real.h): `make lab01-ref-double` and `make
lab05-ref-double` build the same renderer with `real` = double, from the same scene files and
command line. The double build passes every correctness check lab 01's reference passes, says
"double" in --json, and really computes in double (tests/precision/test_double.cpp); the
float build says "float". The double build accepts the wider scenes double can hold
(common/host/scene_limits.h); the students' float build refuses them in one line, and the
references render them in double by themselves (common/host/double_twin.h)."""
import os
import shutil
import subprocess
import time

import numpy as np
import pytest

from grading.checks import graded_scenes
from grading.checks.renderer import CHECKS
from labkit import harness, scenes
from labkit.harness import ROOT, build, make_in_root, run_lab


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


def test_the_reference_renders_wider_scales_in_double(lab01_ref, lab01_ref_double, tmp_path):
    """The sphere interior scaled to radius 1e12: past float's bounds (1e9), within double's
    (1e30). The students' float build refuses it in one line; the reference renders it in
    double by itself, as the double build does, like the unit-size scene, and says why."""
    def interior(scale):
        scene = scenes.sphere_interior(**graded_scenes.INTERIOR)
        return scenes.write_scene(tmp_path / f"scaled-{scale:g}.json",
                                  scenes.scaled(scene, scale))
    big = interior(1e12)
    student = build("lab01")[0]
    p = subprocess.run([str(student), "--quiet", "--scene", str(big), "--width", "4",
                        "--height", "4", "--spp", "1"], capture_output=True, text=True)
    lines = p.stderr.strip().splitlines()
    assert p.returncode == 2 and len(lines) == 1 and "1e9" in lines[0], p.stderr
    assert "double places it" in lines[0] and "lab01-ref" in lines[0], lines[0]
    settings = dict(width=8, height=8, spp=4, bounces=2)
    want = scenes.sphere_interior_radiance(**graded_scenes.INTERIOR, bounces=2)
    for binary in (lab01_ref, lab01_ref_double):
        run = run_lab(binary, big, **settings)
        assert abs(run.image / want - 1).max() < 3e-4, binary.name
        assert run.json["precision"] == "double"
    assert "1e9" in run_lab(lab01_ref, big, **settings).json["precision_reason"]


def test_a_piped_scene_only_double_places_is_refused_in_one_line(lab01_ref, tmp_path):
    """The double build reads the scene again, which a pipe drained by the float process
    cannot give: the reference says so in one line (a file renders: the test above); a scene
    float places renders from a pipe as from a file."""
    big = scenes.write_scene(tmp_path / "big.json", scenes.scaled(
        scenes.sphere_interior(**graded_scenes.INTERIOR), 1e12))
    small = scenes.write_scene(tmp_path / "small.json",
                               scenes.sphere_interior(**graded_scenes.INTERIOR))
    args = ["--scene", "/dev/stdin", "--width", "4", "--height", "4", "--spp", "1", "--quiet",
            "--out", str(tmp_path / "out.ppm")]
    p = subprocess.run([str(lab01_ref), *args], input=big.read_text(), capture_output=True,
                       text=True)
    lines = p.stderr.strip().splitlines()
    assert p.returncode == 2 and len(lines) == 1 and "no regular file" in lines[0], p.stderr
    assert not (tmp_path / "out.ppm").exists()
    p = subprocess.run([str(lab01_ref), *args], input=small.read_text(), capture_output=True,
                       text=True)
    assert p.returncode == 0 and (tmp_path / "out.ppm").is_file(), p.stderr


def test_a_mixed_scale_scene_is_rendered_right_by_the_reference(lab01_ref, tmp_path):
    """A sphere of radius 1e-4 on a floor of half-size 1e4, lit from the side: float cannot
    place the sphere, so lab01-ref renders it in double, and its image is the image of the
    same view on a floor of half-size 1 (one bounce: the floor out of view adds nothing) to
    rounding: the same mean, every shadow pixel dark. (That view renders in double too: its
    light, 1e4 radii from the sphere, counts in the scene's reach.) With ray offsets of 2^-20
    of the scene's size in double too, the shadow rays started above the sphere and 97 of the
    192 shadow pixels were lit."""
    settings = dict(width=64, height=64, spp=64, bounces=1, seed=5)
    far = scenes.write_scene(tmp_path / "mixed.json", scenes.mixed_scale(1e4))
    near = scenes.write_scene(tmp_path / "near.json", scenes.mixed_scale(1.0))
    mixed = run_lab(lab01_ref, far, **settings)
    plain = run_lab(lab01_ref, near, **settings)
    assert mixed.json["precision"] == "double" and plain.json["precision"] == "double"
    assert "reach (1e+04" in mixed.json["precision_reason"]
    assert "/spheres/0/radius" in mixed.json["precision_reason"]
    assert abs(mixed.image.mean() / plain.image.mean() - 1) < 1e-3
    luminance, want = mixed.image.mean(axis=2), plain.image.mean(axis=2)
    shadow = want < 0.02 * want.mean()
    assert shadow.sum() > 100, "the scene lost its shadow"
    assert (luminance[shadow] < 0.1 * want.mean()).all(), \
        f"{(luminance[shadow] >= 0.1 * want.mean()).sum()} of {shadow.sum()} shadow pixels lit"
    assert float(abs(luminance - want).mean()) < 2e-3 * float(want.mean())


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
    p = make_in_root("variant", "VARIANT_LAB=01-serial", f"VARIANT={tmp_path}",
                     "VARIANT_FLAGS_01-serial=-DRT_DOUBLE", capture_output=True, text=True,
                     timeout=300)
    assert p.returncode != 0 and "undefined reference to `render(" in p.stderr, \
        p.stdout + p.stderr
    assert not (tmp_path / "lab").exists()


def _nan_cornell(tmp_path, intensity):
    """The Cornell box with white walls of albedo (1, 0, 1), the green wall (0, 1, 0) and the
    light at `intensity` 0.01 from the green wall: a light sample's product overflowed float
    and met the zero channel of a path's throughput (0 * inf), NaN in dozens of pixels."""
    scene = scenes.load("cornell")
    scene["materials"]["white"]["albedo"] = [1, 0, 1]
    scene["materials"]["green"]["albedo"] = [0, 1, 0]
    scene["light"] = {"position": [0.99, 0.5, -0.5], "intensity": [intensity] * 3}
    return scenes.write_scene(tmp_path / f"bright-{intensity:g}.json", scene)


@pytest.mark.parametrize("target", ["lab01-ref", "lab01-ref-double", "lab02-ref", "lab03-ref",
                                    "lab04-ref"])
def test_no_nan_up_to_the_largest_intensity(target, tmp_path, monkeypatch):
    """Intensities up to float's largest with zero albedo channels, 4 bounces: every CPU lab
    either renders an image without NaN or, where float's products could overflow, renders
    in double (the references) or refuses in one line that double places it (labs 02, 04)."""
    if target in ("lab02-ref", "lab04-ref") and not harness.cpu_has_avx2():
        pytest.skip("this CPU has no AVX2/FMA")
    launcher = ()
    if target == "lab04-ref":  # two ranks, as root where CI runs (test_lab04.py)
        if shutil.which("mpirun") is None:
            pytest.skip("no mpirun here")
        monkeypatch.setenv("OMPI_ALLOW_RUN_AS_ROOT", "1")
        monkeypatch.setenv("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
        launcher = ("mpirun", "-q", "--oversubscribe", "--bind-to", "none", "-np", "2")
    binary = build(target)[0]
    for intensity in (1e30, 3e38, 3.4e38):
        run = run_lab(binary, _nan_cornell(tmp_path, intensity), width=16, height=16, spp=4,
                      bounces=4, seed=1, check=False, launcher=launcher)
        if run.returncode != 0:
            lines = run.stderr.strip().splitlines()
            assert run.returncode == 2 and len(lines) == 1, (intensity, run.stderr)
            assert "double places it" in lines[0], lines[0]
            continue
        assert run.image is not None, intensity
        assert not np.isnan(run.image).any(), \
            f"{target} at intensity {intensity:g}: {int(np.isnan(run.image).sum())} NaN values"


def test_a_triangle_on_a_line_is_left_out_alike_everywhere(tmp_path):
    """A triangle whose written points lie on a line to within double's rounding (0.1, 0.2,
    0.3 and its multiples are not exactly collinear as doubles) has no area at any precision:
    every lab and precision leaves it out and renders the scene without it, to the bit, and
    --json counts it. It used to send the references to double and make lab 02 refuse it."""
    plain = scenes.load("cornell")
    lined = scenes.load("cornell")
    lined["triangles"] = [{"vertices": [[0.1, 0.2, -0.3], [0.2, 0.4, -0.6], [0.3, 0.6, -0.9]],
                           "material": "white"}]
    plain_path = scenes.write_scene(tmp_path / "plain.json", plain)
    lined_path = scenes.write_scene(tmp_path / "lined.json", lined)
    settings = dict(width=12, height=12, spp=2, bounces=2, seed=4)
    targets = ["lab01-ref", "lab01-ref-double", "lab01"]
    if harness.cpu_has_avx2():
        targets.append("lab02-ref")
    for target in targets:
        binary = build(target)[0]
        with_line = run_lab(binary, lined_path, **settings)
        assert with_line.json["scene_uses"]["lines_left_out"] == 1, target
        assert with_line.json["precision"] == ("double" if "double" in target else "float")
        assert (with_line.image == run_lab(binary, plain_path, **settings).image).all(), target


# ---- where the switch sits: each ratio swept across its limit (common/host/scene_limits.h) --
# Below a limit, lab01-ref renders in double and a student's float build refuses in one line;
# just above it, lab01-ref's float image is its double image's, by the criterion of the scale
# check (grading/checks/invariance.py: same seed, mean within 1%, at most 2% of pixel values
# off by more than 5%).

OFFSET = 2.0**-20  # float's ray offset, relative to the distance scale (common/core/ray.h)
SWEEP = dict(width=24, height=24, spp=16, seed=5)


def _switched(scene_path, lab01_ref, pointer, bounces=1):
    run = run_lab(lab01_ref, scene_path, bounces=bounces, **SWEEP, check=False)
    assert run.returncode == 0 and np.isfinite(run.image).all(), run.stderr
    assert run.json["precision"] == "double", run.json
    assert pointer in run.json["precision_reason"], run.json["precision_reason"]
    p = subprocess.run([str(build("lab01")[0]), "--quiet", "--scene", str(scene_path),
                        "--width", "24", "--height", "24", "--spp", "1", "--bounces",
                        str(bounces)], capture_output=True, text=True)
    lines = p.stderr.strip().splitlines()
    assert p.returncode == 2 and len(lines) == 1, p.stderr
    assert pointer in lines[0] and "double places it" in lines[0], lines[0]


def _float_is_right(scene_path, lab01_ref, lab01_ref_double, bounces=1):
    # check=False: run_lab's sanity bound (1e9) is for ordinary scenes, not for a light near
    # float's range; the run must still succeed with a finite image.
    single = run_lab(lab01_ref, scene_path, bounces=bounces, **SWEEP, check=False)
    double = run_lab(lab01_ref_double, scene_path, bounces=bounces, **SWEEP, check=False)
    assert single.returncode == 0 and double.returncode == 0, single.stderr + double.stderr
    assert single.json["precision"] == "float", single.json
    assert np.isfinite(single.image).all()
    a, b = single.image.astype(np.float64), double.image.astype(np.float64)
    mean_err = abs(a.mean() / b.mean() - 1)
    bad = float((~(np.abs(a - b) / (np.abs(b) + 1e-3) <= 0.05)).mean())
    assert mean_err <= 0.01 and bad <= 0.02, \
        f"float against double: mean off by {mean_err:.2%}, {bad:.2%} of values off by > 5%"


def test_a_detail_switches_below_128_offsets_of_the_scene(lab01_ref, lab01_ref_double,
                                                           tmp_path):
    """A sphere of radius k ray offsets on a floor of half-size 1e4 (float's image was wrong at
    k = 1.1 .. 64, docs/precision.md): at k = 100 the reference renders in double, at 160
    float renders it right."""
    for k in (100, 160):
        r = k * OFFSET * 1e4
        scene = scenes.mixed_scale(1e4, r)
        scene["light"] = {"position": [5 * r, 10 * r, 0], "intensity": [r * r] * 3}
        path = scenes.write_scene(tmp_path / f"mixed-{k}.json", scene)
        if k < 128:
            _switched(path, lab01_ref, "/spheres/0/radius")
        else:
            _float_is_right(path, lab01_ref, lab01_ref_double)


def test_the_cameras_distance_counts(lab01_ref, lab01_ref_double, tmp_path):
    """A sphere of radius 0.2 on a floor of half-size 1 seen from D away, the view narrowed to
    frame the floor: its first hits leave surfaces by offsets that grow with D, so the limit is
    128 offsets of D (D = 1638). At D = 2000 the reference renders in double, at 1300 float
    renders it right."""
    for distance in (2000, 1300):
        scene = scenes.mixed_scale(1.0, 0.2)
        look_at = np.array([0, 0.2, 0])
        away = np.array([0, 0.5, 1.0]) / np.linalg.norm([0, 0.5, 1.0])
        scene["camera"] = {"position": list(look_at + away * distance),
                           "look_at": list(look_at),
                           "vfov": float(np.degrees(2 * np.arctan(1.0 / distance)))}
        path = scenes.write_scene(tmp_path / f"far-{distance}.json", scene)
        if distance > 1638:
            _switched(path, lab01_ref, "/spheres/0/radius")
        else:
            _float_is_right(path, lab01_ref, lab01_ref_double)


def test_a_narrow_view_switches_below_256_ulps_a_pixel(lab01_ref, lab01_ref_double, tmp_path):
    """The Cornell box through a view whose 24 pixels span u ulps of a unit direction each
    (2^-23 rad), aimed at the corner of the floor and the back wall: at u = 200 the reference
    renders in double, at 320 float renders it right."""
    for ulps in (200, 320):
        scene = scenes.load("cornell")
        scene["camera"]["look_at"] = [0.3, 0.0, -1.0]
        scene["camera"]["vfov"] = float(np.degrees(2 * np.arctan(12 * ulps * 2.0**-23)))
        path = scenes.write_scene(tmp_path / f"view-{ulps}.json", scene)
        if ulps < 256:
            _switched(path, lab01_ref, "/camera/vfov", bounces=2)
        else:
            _float_is_right(path, lab01_ref, lab01_ref_double, bounces=2)


def test_a_light_whose_paths_leave_floats_range_switches(lab01_ref, lab01_ref_double,
                                                         tmp_path):
    """A light 0.01 from the Cornell box's green wall gives a falloff up to 1/(pi 1e-4); at
    2 bounces an intensity past 5.35e34 could carry a path past float's largest value: at 6e34
    the reference renders in double, at 4e34 float renders it right."""
    for intensity in (6e34, 4e34):
        scene = scenes.load("cornell")
        scene["light"] = {"position": [0.99, 0.5, -0.5], "intensity": [intensity] * 3}
        path = scenes.write_scene(tmp_path / f"bright-{intensity:g}.json", scene)
        if intensity > 5.35e34:
            _switched(path, lab01_ref, "/light/intensity", bounces=2)
        else:
            _float_is_right(path, lab01_ref, lab01_ref_double, bounces=2)


def test_numbers_are_judged_as_written(lab01_ref, lab01_ref_double, tmp_path):
    """A range is checked on the number the file writes, in every build with the same message
    (float rounds an albedo of 1 + 1e-9 to 1); a number only float cannot hold (an intensity
    of 1e39) renders in double in the reference and is refused in one line by a student's
    float build; nesting past any scene's is refused at once, at its line and column."""
    def student(path):
        p = subprocess.run([str(build("lab01")[0]), "--quiet", "--scene", str(path), "--width",
                            "4", "--height", "4", "--spp", "1"], capture_output=True, text=True)
        return p.returncode, p.stderr.strip().splitlines()

    over = scenes.load("cornell")
    over["materials"]["white"]["albedo"] = [0.5, 1.000000001, 0.5]
    over_path = scenes.write_scene(tmp_path / "over.json", over)
    messages = set()
    for binary in (lab01_ref, lab01_ref_double):
        run = run_lab(binary, over_path, width=4, height=4, spp=1, check=False)
        lines = run.stderr.strip().splitlines()
        assert run.returncode == 2 and len(lines) == 1 and "in [0, 1]" in lines[0], run.stderr
        messages.add(lines[0])
    assert len(messages) == 1, messages

    bright = scenes.load("cornell")
    bright["light"]["intensity"] = [1e39, 1, 1]
    bright_path = scenes.write_scene(tmp_path / "bright.json", bright)
    run = run_lab(lab01_ref, bright_path, width=4, height=4, spp=1, check=False)
    assert run.returncode == 0 and run.json["precision"] == "double", run.stderr
    assert "/light/intensity/0: 1e+39 is beyond float's range" in run.json["precision_reason"]
    status, lines = student(bright_path)
    assert status == 2 and len(lines) == 1 and "double places it" in lines[0], lines

    deep = tmp_path / "deep.json"
    deep.write_text('{"camera":\n' + "[" * 100000 + "]" * 100000 + "}")
    start = time.monotonic()
    status, lines = student(deep)
    assert time.monotonic() - start < 2
    assert status == 2 and len(lines) == 1 and "line 2, column 32: nesting deeper than 32" \
        in lines[0], lines
