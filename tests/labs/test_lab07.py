"""Lab 07 (structure of arrays): lab 06's wavefront kernels on an SoA path pool.

Host side (wherever nvcc is): the targets build, one line without nvcc, the skeleton in
sync, bad input and no GPU give one line. On a GPU: every correctness check, the same image
bit for bit as lab 06's AoS pool (the same kernels and arithmetic; only where the fields lie
differs), reproducible across waves and bands, the pristine skeleton visibly wrong, and on
every card the course has a record of the bar: faster than lab 06 on the baseline."""
import os

import numpy as np
import pytest
from test_lab06 import (
    CHECKS,
    no_gpu_is_one_line,
    pristine_skeleton,
    recorded_card,
    statistically_agrees_with,
    targets_fail_without_nvcc,
    waves_do_not_change_the_image,
)

from grading.checks.golden import check_golden
from labkit.harness import ROOT, build, golden, run_lab

LAB = "07-soa"


@pytest.fixture(scope="module")
def lab07_ref(nvcc):
    return build("lab07-ref")[0]


# ---- host side -------------------------------------------------------------------------

def test_without_nvcc_the_targets_fail_with_one_line():
    targets_fail_without_nvcc(("lab07", "lab07-ref", "lab07-bench"))


def test_targets_build_with_nvcc(lab07_ref):
    lab07, bench = build("lab07", "lab07-bench")
    assert all(os.access(b, os.X_OK) for b in (lab07_ref, lab07, bench))


def test_skeleton_in_sync():
    from labkit.variants import pristine_skeleton_sources
    expected = pristine_skeleton_sources(LAB)
    assert set(expected) == {"path_pool_soa.cuh", "render.cu"}
    for name, text in expected.items():
        assert (ROOT / "labs" / LAB / "skeleton" / name).read_text() == text, name
    assert "Vec3Array" not in expected["path_pool_soa.cuh"]
    assert "c.take<float>()" not in expected["path_pool_soa.cuh"]


def test_no_gpu_is_one_line(lab07_ref, tmp_path):
    no_gpu_is_one_line(lab07_ref, tmp_path)


def test_bad_flags(lab07_ref):
    from test_bad_input import assert_one_line_error, run
    assert_one_line_error(run(lab07_ref, "--spp", "0"), "--spp: expected an integer")


# ---- on the GPU ------------------------------------------------------------------------

@pytest.mark.parametrize("check", list(CHECKS.values()), ids=list(CHECKS))
def test_reference_passes(gpu, lab07_ref, check):
    result = check(lab07_ref)
    assert result.passed, str(result)


@pytest.mark.parametrize("scene", ["cornell", "showcase"])
def test_same_image_as_lab06(gpu, lab07_ref, scene):
    """The layout changes where each field lies, not what is computed: bit for bit lab 06's
    image, on both golden scenes."""
    lab06_ref = build("lab06-ref")[0]
    g = golden(scene)
    settings = dict(width=g.meta["width"], height=g.meta["height"], bounces=g.meta["bounces"],
                    spp=32, seed=5)
    a = run_lab(lab07_ref, g.scene, **settings).image
    b = run_lab(lab06_ref, g.scene, **settings).image
    assert a.tobytes() == b.tobytes(), float(np.abs(a - b).max())


def test_agrees_with_lab01(gpu, lab07_ref):
    report = statistically_agrees_with(lab07_ref, build("lab01-ref")[0])
    assert report.passed, report.summary()


def test_waves_and_bands_do_not_change_the_image(gpu, lab07_ref):
    assert waves_do_not_change_the_image(lab07_ref)


def test_baseline_is_finite(gpu, lab07_ref):
    run = run_lab(lab07_ref)
    assert run.image.shape == (600, 600, 3) and np.isfinite(run.image).all()
    assert 0 < run.json["seconds"]
    assert "kernel only" in run.json["timing"], run.json  # the JSON says what seconds covers


def test_faster_than_lab06(lab07_ref):
    """The SoA pool's baseline is faster than lab 06's AoS pool (best of 3 each, measured
    alternately): a ratio in one run, which a slower clock of the GPU leaves as it is; on any
    card the course has a record of. lab07-bench prints the same bar as a speed target."""
    recorded_card()
    lab06_ref = build("lab06-ref")[0]
    soa, aos = [], []
    for _ in range(3):
        aos.append(run_lab(lab06_ref).json["seconds"])
        soa.append(run_lab(lab07_ref).json["seconds"])
    assert min(soa) < min(aos), (min(soa), min(aos))


def test_each_layout_reports_where_neighbours_lie(gpu, lab07_ref, lab07_pristine_skeleton):
    """The probe in --json (common/wavefront/layout_probe.cuh), which lab 07's grader reads:
    the same field of neighbouring queued paths lies 4 bytes apart in the SoA pool, a 48-byte
    record apart in lab 06's AoS pool, and nowhere in the skeleton's pool, which stores
    nothing."""
    def layout(binary):
        return run_lab(binary, width=4, height=4, spp=1).json["layout"]
    assert layout(lab07_ref) == {"name": "SoA", "bytes_between_neighbours": 4}
    assert layout(build("lab06-ref")[0]) == {"name": "AoS", "bytes_between_neighbours": 48}
    assert layout(lab07_pristine_skeleton)["bytes_between_neighbours"] == -1


@pytest.fixture(scope="module")
def lab07_pristine_skeleton(nvcc, tmp_path_factory):
    return pristine_skeleton(LAB, tmp_path_factory)


def test_skeleton_is_visibly_incomplete(gpu, lab07_pristine_skeleton):
    """Until students write the SoA pool, nothing is stored: the skeleton builds and renders
    a black image."""
    skeleton = lab07_pristine_skeleton
    assert not check_golden(skeleton, "cornell").passed
    image = run_lab(skeleton, width=32, height=32, spp=4).image
    assert image is not None and np.isfinite(image).all() and image.max() == 0


def test_students_build_runs(gpu):
    lab07 = build("lab07")[0]
    assert run_lab(lab07, width=8, height=8, spp=1).image.shape == (8, 8, 3)
