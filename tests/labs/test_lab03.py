"""Lab 03 (OpenMP): the reference renders lab 01's image bit for bit for any thread count and
is faster by a margin scaled to the cores present; the skeleton is correct but serial (same
bits, no speedup); the SIMD+OpenMP variant renders lab 01's bits too, at the CPU's width and
at 8 lanes; the shared-RNG variant, the classic mistake, renders but not lab 01's image."""
import os

import pytest

from grading.checks.golden import check_golden
from labkit.harness import (
    available_cores,
    build,
    cpu_has_avx2,
    measure_parallel,
    render_seconds,
    run_lab,
)
from labkit.variants import build_pristine_skeleton, build_variant, lab_sources

# Small renders for the bitwise comparisons: every pixel, sample and bounce is exercised.
SMALL = dict(width=48, height=40, spp=8, seed=3)
# The timed render: about a second serially on the course's two-core VM.
TIMED = dict(width=256, height=256, spp=32, seed=1)
ROUNDS = 5  # best of 5: on a shared machine, some round of each is usually undisturbed


@pytest.fixture(scope="module")
def lab03_ref():
    return build("lab03-ref")[0]


@pytest.fixture(scope="module")
def lab03_skeleton(tmp_path_factory):
    """The skeleton exactly as generated from the solution, whatever a student has done to
    labs/03-openmp/skeleton/ since: its expected failures stay expected."""
    return build_pristine_skeleton("03-openmp", tmp_path_factory.mktemp("lab03-skeleton"))


@pytest.fixture(scope="module")
def lab01_bits(lab01_ref):
    """lab01-ref's PFM of the small render: what every thread count must reproduce."""
    return run_lab(lab01_ref, **SMALL).image.tobytes()


# --- correctness: bit for bit -------------------------------------------------------------

@pytest.mark.parametrize("threads", [1, 2, 3, 4, 7, 64, None],
                         ids=lambda t: f"threads={t or 'default'}")
def test_reference_is_lab01_bit_for_bit(lab03_ref, lab01_bits, threads):
    """Counter-based random numbers: a pixel's value cannot depend on which thread rendered
    it, so any thread count (64 threads: more than the 40 rows) gives lab 01's bits."""
    run = run_lab(lab03_ref, threads=threads, **SMALL)
    assert run.image.tobytes() == lab01_bits, \
        f"--threads {threads}: image differs from lab01-ref's bits"


@pytest.mark.parametrize("schedule", ["static", "static,1", "dynamic,3", "guided"])
def test_every_schedule_is_lab01_bit_for_bit(lab01_bits, schedule, monkeypatch):
    """lab03-bench takes its schedule from OMP_SCHEDULE (the handout's table): any schedule
    gives the same bits."""
    bench = build("lab03-bench")[0]
    monkeypatch.setenv("OMP_SCHEDULE", schedule)
    run = run_lab(bench, threads=3, **SMALL)
    assert run.image.tobytes() == lab01_bits, f"OMP_SCHEDULE={schedule}: image differs"


def test_reference_passes_golden(lab03_ref):
    result = check_golden(lab03_ref, "cornell")
    assert result.passed, str(result)


def test_device_names_the_thread_count(lab03_ref):
    """--threads T is used as given; the default is every core this process may use."""
    assert run_lab(lab03_ref, threads=3, **SMALL).json["device"].endswith(", 3 threads")
    if "OMP_NUM_THREADS" not in os.environ:  # which would override "every core"
        cores = available_cores()
        want = f", {cores} thread" + ("s" if cores > 1 else "")
        device = run_lab(lab03_ref, **SMALL).json["device"]
        assert device.endswith(want), f"default threads: {device!r}, wanted {want!r}"


@pytest.mark.parametrize("bad", ["0", "-1", "two", "1.5", ""])
def test_bad_thread_count_is_rejected(lab03_ref, bad):
    run = run_lab(lab03_ref, extra=["--threads", bad], check=False, **SMALL)
    assert run.returncode == 2 and "--threads" in run.stderr, (run.returncode, run.stderr)


# --- the skeleton: correct but serial -------------------------------------------------------

@pytest.mark.parametrize("threads", [1, 2, None], ids=lambda t: f"threads={t or 'default'}")
def test_skeleton_is_correct(lab03_skeleton, lab01_bits, threads):
    """The skeleton renders lab 01's image from the start (what it lacks is speed)."""
    run = run_lab(lab03_skeleton, threads=threads, **SMALL)
    assert run.image.tobytes() == lab01_bits


# --- speed ----------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def lab03_ordered(tmp_path_factory):
    """The reference with its row loop `ordered`: every row body waits for the one before,
    so the threads share the work but run one at a time."""
    source = lab_sources("03-openmp")["render.cpp"]
    loop = "#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)"
    body = "        for (int x = 0; x < width; ++x) image.at(x, y) = pixel(x, y);"
    assert source.count(loop) == 1 and source.count(body) == 1
    source = source.replace(loop, loop.replace("parallel for", "parallel for ordered")).replace(
        body, "#pragma omp ordered\n" + body)
    return build_variant("03-openmp", tmp_path_factory.mktemp("lab03-ordered"),
                         {"render.cpp": source})


@pytest.fixture(scope="module")
def speedups(lab01_ref, lab03_ref, lab03_skeleton, lab03_ordered):
    """Speedups over lab01-ref of lab03-ref, of the skeleton and of the ordered loop with every
    core, measured with the machine's capacity alongside (labkit.harness.measure_parallel)."""
    if available_cores() < 2:
        pytest.skip("only one core available to this process: no parallel speedup to measure")
    timing = measure_parallel(lambda: render_seconds(lab01_ref, **TIMED),
                              {"lab03-ref": lambda: render_seconds(lab03_ref, **TIMED),
                               "skeleton": lambda: render_seconds(lab03_skeleton, **TIMED),
                               "ordered": lambda: render_seconds(lab03_ordered, **TIMED)},
                              rounds=ROUNDS)
    if timing.capacity < 1.5:
        pytest.skip(f"the machine is too busy to measure a parallel speedup: "
                    f"{timing.cores} serial renders at once ran only {timing.capacity:.2f}x "
                    f"as fast as one")
    return timing


@pytest.mark.timed
def test_reference_speedup(speedups):
    assert speedups.speedup("lab03-ref") >= speedups.required(), speedups.describe("lab03-ref")


@pytest.mark.timed
def test_skeleton_fails_the_speedup_bar(speedups):
    """Correct but serial: until the parallel loop is written (TODO(lab03) in
    labs/03-openmp/skeleton/render.cpp) the skeleton fails the speedup test above. How much
    faster or slower than lab01-ref it runs is not asserted: the two are different binaries,
    and on a busy machine one serial program timed against another differs by up to the noise
    floor that required() never goes below."""
    assert speedups.speedup("skeleton") < speedups.required(), speedups.describe("skeleton")


def test_skeleton_runs_on_one_thread(lab03_skeleton, lab03_ref):
    """What makes the skeleton serial, told apart from the machine's load as the grader tells
    it (grading/checks/speed.py): one thread does the whole render, whatever --threads says,
    while the reference's busiest thread does about half of it on two threads."""
    from grading.checks.speed import ONE_THREAD
    # The timed size: the grader samples each thread's CPU time every SAMPLE_SECONDS
    # (labkit/sandbox.py), and a render of a few tenths of a second is sampled several times.
    skeleton = run_lab(lab03_skeleton, threads=2, **TIMED)
    assert skeleton.thread_share >= ONE_THREAD, \
        f"the skeleton's busiest thread did {skeleton.thread_share:.0%} of its CPU time"
    reference = run_lab(lab03_ref, threads=2, **TIMED)
    assert reference.thread_share < ONE_THREAD, \
        f"the reference's busiest thread did {reference.thread_share:.0%} of its CPU time"


@pytest.mark.timed
def test_threads_taking_turns_stay_below_the_grader_s_turns_bar(speedups):
    """An ordered row loop, where the machine has room for a parallel program: over the same
    lab's serial build (the skeleton, timed in the same rounds: the same code but the loop, so
    the ratio is the loop's alone) no faster than the grader's bar for threads that ran one at
    a time (grading/checks/speed.py), while the reference, in the same rounds, is well above
    that bar over lab01-ref."""
    from grading.checks.speed import TURNS_SPEEDUP
    over_serial = speedups.best["skeleton"] / speedups.best["ordered"]
    assert over_serial <= TURNS_SPEEDUP, \
        (f"the ordered loop {over_serial:.2f}x over the serial skeleton "
         f"({speedups.best['skeleton']:.3f} s -> {speedups.best['ordered']:.3f} s)")
    assert speedups.speedup("lab03-ref") > TURNS_SPEEDUP, speedups.describe("lab03-ref")


# --- variants -------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def lab03_simd_ref():
    if not cpu_has_avx2():
        pytest.skip("lab03-simd-ref needs a CPU with AVX2 and FMA; this one has not")
    return build("lab03-simd-ref")[0]


def test_simd_variant_passes_golden(lab03_simd_ref):
    result = check_golden(lab03_simd_ref, "cornell")
    assert result.passed, str(result)


@pytest.mark.parametrize("force_8_lanes", [False, True], ids=["widest", "8-lanes"])
def test_simd_variant_is_lab01_bit_for_bit(lab03_simd_ref, lab01_bits, monkeypatch,
                                           force_8_lanes):
    """Lab 02's packets (the widest the CPU runs, or 8 AVX2 lanes as on a CPU without AVX-512)
    under OpenMP: lab 01's image for any thread count, and the summary names the width."""
    if force_8_lanes:
        monkeypatch.setenv("RT_FORCE_NO_AVX512", "1")
    for threads in (1, 3):
        run = run_lab(lab03_simd_ref, threads=threads, **SMALL)
        assert run.image.tobytes() == lab01_bits, f"{threads} threads: not lab 01's bits"
        assert "paths per packet, compacted" in run.json["device"], run.json["device"]
    if force_8_lanes:
        assert "AVX2, 8 paths per packet" in run.json["device"], run.json["device"]


@pytest.mark.parametrize("variant", ["lab03-shared-rng", "lab03-shared-rng-race"])
def test_shared_rng_is_not_lab01(variant, lab01_bits):
    """The classic mistake renders a plausible image, but not lab 01's: a stateful generator
    cannot give each (pixel, sample, dimension) its own number. (It is also slower and not
    repeatable from run to run; tools/bench/openmp.py measures that rather than a test,
    since neither is guaranteed on every machine.)"""
    binary = build(variant)[0]
    run = run_lab(binary, threads=2, **SMALL)
    assert run.image is not None and float(run.image.mean()) > 0
    assert run.image.tobytes() != lab01_bits
