"""An untouched skeleton scores at most 10% in every lab: lab 01's renders a flat colour,
lab 02's lacks the packet intersections, lab 03's is a correct serial renderer (lab 03 is
about the parallel loop), lab 04's renders only its own rows. Lab 01's skeleton is graded in
test_grade.py, lab 04's in tests/labs/test_lab04.py (one grade of it serves both)."""
import pytest

from grading.grade import describe, grade
from labkit.harness import build, cpu_has_avx2
from labkit.variants import build_pristine_skeleton

# Lab 03's skeleton renders lab 01's bits on one core, as lab01-ref does, and lab01-ref handed
# in for lab 03 is graded in test_grade.py: not again here, a speedup measurement is slow.
LAB_FOLDERS = {"02": "02-simd"}


@pytest.mark.timed
@pytest.mark.parametrize("lab", sorted(LAB_FOLDERS))
def test_skeleton_scores_at_most_ten_percent(lab, tmp_path):
    if lab == "02" and not cpu_has_avx2():
        pytest.skip("this CPU has no AVX2/FMA: lab 02's Part B cannot run")
    build("lab01-ref")  # the baseline of the speedup
    skeleton = build_pristine_skeleton(LAB_FOLDERS[lab], tmp_path)
    results = grade(lab, skeleton, tmp_path)
    regrade = [t["name"] for t in results["tests"] if t["extra_data"]["regrade"]]
    if regrade:
        pytest.skip(f"the machine was too busy to measure: {regrade}")
    assert results["score"] <= 0.1 * results["max_score"], describe(results)
