"""Correctness checks of a lab binary, shared by the pytest suites, the mutation tests and the
grader. Each returns a CheckResult: whether it passed and a line saying what it saw.

How often a correct renderer fails each check (its false-failure rate), and why:
- golden images: at most alpha = 1e-4 per comparison, by the Bonferroni bound over every
  block and global z-test (labkit/compare.py explains the model and its assumptions).
- sphere interior: the estimator has zero variance there (every next-event estimate is the
  same), so only float rounding differs from the closed form: ~1e-5 relative, bound 3e-4.
- millions of samples: the same zero-variance scene at 2^22 and 2^12 spp; a double sum keeps
  the two means equal to float rounding (~1e-7), bound 1e-5; a float sum drifts by ~1e-2.
- lit plane: the only noise is where the pixel jitter lands; at 256 spp the per-pixel error
  is ~1e-3, bounds 3e-3 (mean) and 2e-2 (max) are far outside it.
- glass pane: the mean of 262,144 Bernoulli(~4-5%) paths has a relative standard error of
  ~1%; the 5% bound is five standard errors (two-sided rate ~6e-7) at each of 4 renders.
- scale invariance: the scaled and unscaled renders use the same random numbers, so they
  differ only where rounding sends a path another way: measured 0.00% for the reference.
A renderer whose float roundings differ (SIMD, GPU) is another random draw of the same
estimator, so these rates apply to it too. Which bugs each check catches is shown by
tests/labs/test_lab01_mutants.py.

The checks live by concern in check_result, golden_checks, analytic_checks,
invariance_checks, speed_checks, identity_checks, mpi_checks, layout_check and lanes; this
module names them all for the grader and the tests."""
from __future__ import annotations

from grading.analytic_checks import (
    INTERIOR,
    black_pixels,
    check_glass_slab,
    check_lit_plane,
    check_million_samples,
    check_sphere_interior,
    drawn_interior,
    render_interior,
)
from grading.check_result import LAB01_REFERENCE, CheckResult, image_checked, worst_of
from grading.golden_checks import GOLDEN_TEST_SPP, check_golden, stored_golden_copied
from grading.identity_checks import check_bitwise_equal, row_ranges, rows_differing, why_different
from grading.invariance_checks import (
    LARGE_FLOORS,
    SCALE_FACTORS,
    TRANSLATIONS,
    check_large_primitives,
    check_reproducible,
    check_scale_invariance,
    check_translation_invariance,
    render_floor,
)
from grading.lanes import lanes_not_lab01
from grading.layout_check import check_structure_of_arrays
from grading.mpi_checks import DISTRIBUTIONS, check_distributions, mpirun, report_rows
from grading.speed_checks import (
    BUSY,
    IMPOSSIBLE,
    ONE_THREAD,
    QUOTA_TOO_SMALL,
    SERIAL_CORES,
    SERIAL_TELLABLE,
    TIMED_SCENE,
    ZERO_CREDIT_AT,
    box_filtered,
    busiest_thread_share,
    check_parallel_speedup,
    check_speedup,
    cores_used,
    credit_note,
    drawn_timed_scene,
    launch_overhead,
    one_cpu,
    one_thread_did_it,
    serial_by_thread,
    speed_credit,
    timed_golden,
    timed_scene,
    timed_settings,
    together_launcher,
    wrong_timed_image,
)

__all__ = [
    "LAB01_REFERENCE",
    "CheckResult",
    "worst_of",
    "image_checked",
    "lanes_not_lab01",
    "GOLDEN_TEST_SPP",
    "check_golden",
    "stored_golden_copied",
    "INTERIOR",
    "drawn_interior",
    "render_interior",
    "black_pixels",
    "check_sphere_interior",
    "check_million_samples",
    "check_lit_plane",
    "check_glass_slab",
    "SCALE_FACTORS",
    "check_scale_invariance",
    "check_reproducible",
    "TRANSLATIONS",
    "render_floor",
    "check_translation_invariance",
    "LARGE_FLOORS",
    "check_large_primitives",
    "check_structure_of_arrays",
    "TIMED_SCENE",
    "drawn_timed_scene",
    "timed_scene",
    "timed_settings",
    "timed_golden",
    "box_filtered",
    "wrong_timed_image",
    "ZERO_CREDIT_AT",
    "speed_credit",
    "credit_note",
    "cores_used",
    "one_cpu",
    "SERIAL_CORES",
    "check_speedup",
    "launch_overhead",
    "BUSY",
    "SERIAL_TELLABLE",
    "QUOTA_TOO_SMALL",
    "ONE_THREAD",
    "IMPOSSIBLE",
    "busiest_thread_share",
    "one_thread_did_it",
    "serial_by_thread",
    "check_parallel_speedup",
    "together_launcher",
    "check_bitwise_equal",
    "row_ranges",
    "rows_differing",
    "why_different",
    "mpirun",
    "DISTRIBUTIONS",
    "report_rows",
    "check_distributions",
]
