"""Correctness checks of a lab binary, shared by the pytest suites, the mutation tests and the
grader. Each returns a CheckResult: whether it passed, a line saying what it saw, and the
images it compared.

They live by concern, each module with the false-failure rates of its checks:
check_result (what a check returns), golden_checks (the golden images), analytic_checks (the
closed forms), invariance_checks (scale, moves, size, reproducibility), speed_checks (timed
renders), identity_checks (lab 01's bits), mpi_checks (lab 04's distributions), layout_check
(lab 07's pool) and lanes (lab 02's lanes); this module names them all for the grader and the
tests. A renderer whose float roundings differ (SIMD, GPU) is another random draw of the same
estimator, so the rates apply to it too. Which bugs each check catches is shown by
tests/labs/test_lab01_mutants.py."""
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
from grading.mpi_checks import (
    DISTRIBUTIONS,
    HYBRID_SHARED,
    check_distributions,
    check_hybrid_threads,
    mpirun,
    report_rows,
)
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
    "check_hybrid_threads",
    "HYBRID_SHARED",
]
