"""Lab 06 (CUDA split kernels: a wavefront path tracer).

Host-side tests run wherever nvcc is (CI has it, and no GPU): the targets build, a machine
without nvcc gets one line from them, the skeleton is what the generator makes, bad input
and a missing GPU give one line and a non-zero exit. GPU tests (the `gpu` fixture) render:
every correctness check of the CPU labs, agreement with labs 01 and 05 (the same random
numbers per path), no NaN/Inf at the baseline, the image independent of how the work is cut
into waves and bands, and the pristine skeleton's visible failure. Without a GPU they skip
and say why. The time bar (BAR_MARGIN times the kernel time this card's record holds for the
baseline, reference/gpu/<card>/) runs on every card the course has a record of; the lab's
real bar is a speed target that lab06-bench prints.

Host side too, for every CUDA lab: no lab's build reads another lab's folder (what they share
is in common/cuda and common/wavefront), the files students write are the ones the build
requires of a hand-in, and the benchmarks end a failure with one line."""
import json
import os
import pathlib
import subprocess

import numpy as np
import pytest
from cuda_env import gpu_name, missing_gpu

from grading.checks.golden import check_golden
from grading.checks.renderer import CHECKS
from labkit.compare import compare
from labkit.harness import ROOT, build, golden, run_lab

LAB = "06-cuda-split"
# The time bar: the AoS pool's best time in this card's record (lab06-bench on the baseline)
# times this, so that a slower clock of the same GPU fails nothing that works (lab06-ref's
# run times more than the benchmark's best launch: 90 ms on the H200 of a 55.6 ms record).
BAR_MARGIN = 1.6
CUDA_LABS = {"05-cuda-mega": "lab05", "06-cuda-split": "lab06", "07-soa": "lab07"}


def make(*args, **kwargs):
    return subprocess.run(["make", "-s", "-C", str(ROOT), *args], capture_output=True,
                          text=True, timeout=900, **kwargs)


def targets_fail_without_nvcc(targets):
    for target in targets:
        p = make(target, "NVCC=/no/such/nvcc")
        assert p.returncode != 0, target
        lines = p.stderr.strip().splitlines()
        assert lines and "needs the CUDA toolkit" in lines[0], p.stderr
        assert len([ln for ln in lines if not ln.startswith("make")]) == 1, p.stderr


def no_gpu_is_one_line(binary, tmp_path):
    out = tmp_path / "out.pfm"
    env = {**os.environ, "CUDA_VISIBLE_DEVICES": ""}
    p = subprocess.run([str(binary), "--quiet", "--width", "8", "--height", "8", "--spp", "1",
                        "--pfm", str(out)], capture_output=True, text=True, env=env, timeout=60)
    assert p.returncode == 3, (p.returncode, p.stderr)  # the machine's fault: kExitDeviceError
    lines = p.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: GPU: "), p.stderr
    assert p.stdout == "" and not out.exists()


def cuda_variant(lab, folder, files: dict[str, str]):
    """`files` (name -> text) written into `folder` and built as `make labNN` builds a lab."""
    for name, text in files.items():
        (folder / name).write_text(text)
    p = make("cuda-variant", f"VARIANT_LAB={lab}", f"VARIANT={folder}")
    assert p.returncode == 0, p.stdout + p.stderr
    return folder / "lab"


def pristine_skeleton(lab, tmp_path_factory):
    """The skeleton as generated from the solution, built as `make labNN` builds it."""
    from labkit.variants import pristine_skeleton_sources
    return cuda_variant(lab, tmp_path_factory.mktemp(lab + "-skeleton"),
                        pristine_skeleton_sources(lab))


def same_paths_as(binary, other, seed=22):
    """Two GPU builds drawing the same random numbers for each path: (median relative
    difference, fraction of values more than 1% apart) on the golden Cornell setup."""
    g = golden("cornell")
    size = dict(width=g.meta["width"], height=g.meta["height"], bounces=g.meta["bounces"])
    a = run_lab(binary, g.scene, spp=64, seed=seed, **size).image
    b = run_lab(other, g.scene, spp=64, seed=seed, **size).image
    rel = np.abs(a - b) / (np.abs(b) + 1e-3)
    return float(np.median(rel)), float((rel > 1e-2).mean())


def statistically_agrees_with(binary, other):
    """The other renderer's image at 256 spp stands in for the golden mean (with the golden
    per-path variance); this one at 64 spp with another seed must pass the comparison."""
    g = golden("cornell")
    size = dict(width=g.meta["width"], height=g.meta["height"], bounces=g.meta["bounces"])
    base = run_lab(other, g.scene, spp=256, seed=21, **size).image
    image = run_lab(binary, g.scene, spp=64, seed=22, **size).image
    return compare(image, 64, base, g.variance, 256)


def waves_do_not_change_the_image(binary):
    """Bands of 25 rows and waves of one sample (RT_LAB06_WAVE_PATHS=1000 at 40x45) give the
    same bits as one wave of the whole image: each pixel's sum is taken in sample order."""
    settings = dict(width=40, height=45, spp=8, seed=4, bounces=6)
    whole = run_lab(binary, **settings).image
    os.environ["RT_LAB06_WAVE_PATHS"] = "1000"
    try:
        cut = run_lab(binary, **settings).image
    finally:
        del os.environ["RT_LAB06_WAVE_PATHS"]
    return cut.tobytes() == whole.tobytes()


def recorded_card():
    """This GPU's record folder (tools/gpu/record.py), whose figures the time bars read:
    skips without a GPU, or on a card the course has no record of."""
    from tools.gpu import record as rec
    if reason := missing_gpu():
        pytest.skip(reason)
    card = rec.card_of(gpu_name())
    if card is None:
        pytest.skip(f"the bars are read from a card's record (reference/gpu/); there is none "
                    f"of a {gpu_name()}")
    return card


def recorded_ms(bench, config):
    """A configuration's best time in this card's record; skips where it holds none."""
    from tools.gpu import record as rec
    card = recorded_card()
    ms = rec.best_ms(card, bench, config)
    if ms is None:
        pytest.skip(f"reference/gpu/{card}/ records no {config} of {bench}-bench")
    return ms


def best_seconds(binary, n=3, **settings):
    return min(run_lab(binary, **settings).json["seconds"] for _ in range(n))


@pytest.fixture(scope="module")
def lab06_ref(nvcc):
    return build("lab06-ref")[0]


# ---- host side -------------------------------------------------------------------------

def test_without_nvcc_the_targets_fail_with_one_line():
    targets_fail_without_nvcc(("lab06", "lab06-ref", "lab06-bench"))
    assert make("-n", "lab01-ref", "NVCC=/no/such/nvcc").returncode == 0


def test_targets_build_with_nvcc(lab06_ref):
    lab06, bench = build("lab06", "lab06-bench")
    assert all(os.access(b, os.X_OK) for b in (lab06_ref, lab06, bench))


def test_skeleton_in_sync():
    """The committed skeleton is exactly what labkit/skeletons.py makes from the solution:
    the queue's reserve and the stage loop are what students write."""
    from labkit.variants import pristine_skeleton_sources
    expected = pristine_skeleton_sources(LAB)
    assert set(expected) == {"queue_reserve.cuh", "render.cu", "stage_loop.cuh"}
    for name, text in expected.items():
        assert (ROOT / "labs" / LAB / "skeleton" / name).read_text() == text, name
    reserve = (
        expected["queue_reserve.cuh"]
        .split("int reserve(int* size, bool wants) {")[1]
        .split("\n}\n")[0]
    )
    code = "\n".join(line for line in reserve.splitlines() if not line.strip().startswith("//"))
    assert "atomicAdd" not in code and "__syncthreads" not in code, code
    assert "for (int bounce" not in expected["stage_loop.cuh"]


def test_no_gpu_is_one_line(lab06_ref, tmp_path):
    no_gpu_is_one_line(lab06_ref, tmp_path)


def make_commands(*targets):
    """What make would run to build `targets` from nothing (-B), one command a line."""
    p = make("-n", "-B", *targets, "CUDA_ARCH=-arch=sm_90")
    assert p.returncode == 0, p.stderr
    return p.stdout.replace("\\\n", " ").splitlines()


@pytest.mark.parametrize("folder", sorted(CUDA_LABS))
def test_no_lab_reads_another_labs_folder(nvcc, folder):
    """Every CUDA target of a lab compiles sources of its own folder or of common/ only, with
    no other lab's folder on the include path: what labs share lives in common/ (and what
    their benchmarks share in bench/gpu/, on the benchmarks' include path alone)."""
    stem = CUDA_LABS[folder]
    targets = [stem, stem + "-ref", stem + "-bench"]
    others = [f for f in CUDA_LABS if f != folder]
    # (make test compiles through ccache: the command may start with it)
    compiles = [c for c in make_commands(*targets)
                if " -c " in c and "nvcc" in c.removeprefix("ccache ").split()[0]]
    assert compiles
    for command in compiles:
        words = command.split()
        source = words[words.index("-c") + 1]
        assert source.startswith((f"labs/{folder}/", "common/")), command
        includes = [w[2:] for w in words if w.startswith("-I")]
        assert not [i for i in includes if any(o in i for o in others)], command
        bench = ("bench/gpu",) if source == f"labs/{folder}/bench.cu" else ()
        assert all(i.startswith((f"labs/{folder}", "common/", *bench)) for i in includes), command


@pytest.mark.parametrize("folder", sorted(CUDA_LABS))
def test_student_files_are_what_the_build_requires(folder):
    """The files a hand-in must hold (cuda.mk's CUDA_STUDENT_FILES_<lab>) are the shared files
    the lab's students write (labkit/skeletons.py's SHARED_SOURCES), each of which their
    skeleton/ holds and no solution/ does: the shared file is the reference."""
    from grading.releases.leaks import skeletons
    p = make("--eval", f"print-student-files: ; @echo $(CUDA_STUDENT_FILES_{folder})",
             "print-student-files")
    required = set(p.stdout.split())
    shared = {pathlib.Path(path).name for path in skeletons.SHARED_SOURCES[folder]}
    assert required == shared and shared, (required, shared)
    for name in shared:
        assert (ROOT / "labs" / folder / "skeleton" / name).is_file(), name
        assert not (ROOT / "labs" / folder / "solution" / name).exists(), name


@pytest.mark.parametrize("bench", ["lab05-bench", "lab06-bench", "lab07-bench"])
def test_benchmarks_end_a_failure_with_one_line(nvcc, bench):
    """A benchmark with no GPU (none visible) or with bad input: one error line, the status
    the lab binaries give (3 for the machine, 2 for the input), nothing on stdout."""
    binary = build(bench)[0]
    env = {**os.environ, "CUDA_VISIBLE_DEVICES": ""}
    for args, status, fragment in [
        (["--width", "8", "--height", "8", "--spp", "1"], 3, "error: GPU: "),
        (["--spp", "0"], 2, "error: --spp: "),
        (["--scene", "/no/such/scene.json"], 2, "error: "),
    ]:
        p = subprocess.run([str(binary), *args], capture_output=True, text=True, env=env,
                           timeout=120)
        lines = p.stderr.strip().splitlines()
        assert p.returncode == status, (args, p.returncode, p.stderr)
        assert len(lines) == 1 and lines[0].startswith(fragment), (args, p.stderr)
        assert p.stdout == "", (args, p.stdout)


@pytest.mark.parametrize("case", ["malformed json", "negative radius", "undefined material"])
def test_bad_scene(lab06_ref, tmp_path, case):
    from test_bad_input import GOOD, SCENE_ERRORS, assert_one_line_error, run, scene_with
    transform, fragments = SCENE_ERRORS[case]
    path = scene_with(tmp_path, transform(json.dumps(GOOD, indent=2)))
    assert_one_line_error(run(lab06_ref, "--scene", str(path)), str(path), *fragments)


@pytest.mark.parametrize("flags, fragment", [
    (["--width", "0"], "--width: expected an integer in 1..16384"),
    (["--bounces", "65"], "--bounces: expected an integer in 1..64"),
])
def test_bad_flags(lab06_ref, flags, fragment):
    from test_bad_input import assert_one_line_error, run
    assert_one_line_error(run(lab06_ref, *flags), fragment)


# ---- on the GPU ------------------------------------------------------------------------

@pytest.mark.parametrize("check", list(CHECKS.values()), ids=list(CHECKS))
def test_reference_passes(gpu, lab06_ref, check):
    result = check(lab06_ref)
    assert result.passed, str(result)


def test_agrees_with_lab01(gpu, lab06_ref):
    """Lab 01's image is the same estimator: with other seeds the two pass the noise-aware
    comparison; with the same seed each path draws the same numbers, so the pixels agree far
    inside the noise (fused multiply-adds aside)."""
    lab01_ref = build("lab01-ref")[0]
    report = statistically_agrees_with(lab06_ref, lab01_ref)
    assert report.passed, report.summary()
    median, far = same_paths_as(lab06_ref, lab01_ref)
    assert median < 1e-4 and far < 0.02, (median, far)


def test_agrees_with_lab05(gpu, lab06_ref):
    """The megakernel and the wavefront trace the same paths with the same code (the core's
    bounce step, compiled by nvcc for both), so at the same seed the images agree to
    rounding; at other seeds they pass the noise-aware comparison."""
    lab05_ref = build("lab05-ref")[0]
    report = statistically_agrees_with(lab06_ref, lab05_ref)
    assert report.passed, report.summary()
    median, far = same_paths_as(lab06_ref, lab05_ref)
    assert median < 1e-5 and far < 0.01, (median, far)


def test_waves_and_bands_do_not_change_the_image(gpu, lab06_ref):
    assert waves_do_not_change_the_image(lab06_ref)


def reserve_replaced(body: str) -> str:
    """common/wavefront/queue_reserve.cuh with the reserve's solution replaced by `body`."""
    text = (ROOT / "common" / "wavefront" / "queue_reserve.cuh").read_text()
    start = text.index("    // BEGIN SOLUTION")
    end = text.index("    // END SOLUTION") + len("    // END SOLUTION")
    return text[:start] + body + text[end:]


def test_a_reserve_of_one_atomic_per_thread_gives_the_same_image(gpu, lab06_ref, tmp_path):
    """The reference writes a block's records out together through shared memory when its
    reserve gave the block one run of places. A student's reserve with one atomic per thread
    is correct too, but the blocks' places interleave: every record must still land where it
    was reserved, the same bits as lab06-ref. (The skeleton's racy reserve, which repeats
    places, is test_skeleton_is_visibly_incomplete's.)"""
    binary = cuda_variant(LAB, tmp_path, {
        "render.cu": (ROOT / "labs" / LAB / "solution" / "render.cu").read_text(),
        "stage_loop.cuh": (ROOT / "common" / "wavefront" / "stage_loop.cuh").read_text(),
        "queue_reserve.cuh": reserve_replaced("    return wants ? atomicAdd(size, 1) : -1;")})
    settings = dict(width=96, height=64, spp=16, seed=5)
    mine = run_lab(binary, **settings).image
    assert np.array_equal(mine, run_lab(lab06_ref, **settings).image)


def test_deep_paths_are_finite(gpu, lab06_ref):
    """64 bounces (the most the command line allows) through the showcase's glass and
    mirrors: every queue drains, every value is finite."""
    run = run_lab(lab06_ref, ROOT / "common" / "scenes" / "showcase.json", width=64, height=48,
                  spp=16, bounces=64)
    assert np.isfinite(run.image).all() and run.image.mean() > 0


def test_baseline_is_finite_and_summarised(gpu, lab06_ref):
    """The report's baseline (600x600, 512 spp, 4 bounces): no NaN or Inf anywhere, and the
    summary names the GPU and times the kernels only (well under the process's wall time)."""
    import time
    start = time.perf_counter()
    run = run_lab(lab06_ref)
    wall = time.perf_counter() - start
    assert run.image.shape == (600, 600, 3)
    assert np.isfinite(run.image).all(), f"{(~np.isfinite(run.image)).sum()} non-finite values"
    assert run.image.mean() > 0
    assert gpu_name() in run.json["device"], run.json
    assert 0 < run.json["seconds"] < wall
    assert "kernel only" in run.json["timing"], run.json  # the JSON says what seconds covers


def test_time_bar(lab06_ref):
    """The baseline's kernels stay under BAR_MARGIN times the card's recorded AoS time (best
    of 3): a loose guard, which a slower clock of the card still passes; the lab's bar is
    lab06-bench's speed target."""
    bar_ms = BAR_MARGIN * recorded_ms("lab06", "AoS")
    seconds = best_seconds(lab06_ref)
    assert seconds * 1e3 <= bar_ms, f"{seconds * 1e3:.1f} ms against {bar_ms:.1f}"


@pytest.fixture(scope="module")
def lab06_pristine_skeleton(nvcc, tmp_path_factory):
    return pristine_skeleton(LAB, tmp_path_factory)


def test_skeleton_is_visibly_incomplete(gpu, lab06_pristine_skeleton):
    """Until students write the reserve and the stage loop, the skeleton builds and renders, but
    not the right image: its racy reserve loses nearly every path (measured on an H200: a black
    32x32 image), and only the first interaction runs."""
    skeleton = lab06_pristine_skeleton
    assert not check_golden(skeleton, "cornell").passed
    image = run_lab(skeleton, width=32, height=32, spp=4).image
    assert image is not None and np.isfinite(image).all()


def test_students_build_runs(gpu):
    lab06 = build("lab06")[0]
    assert run_lab(lab06, width=8, height=8, spp=1).image.shape == (8, 8, 3)
