"""The classic image mistakes, each handed in as lab 01's reference with its image changed the
way the mistake changes it, graded by lab 01's rubric: each loses the points it should, and a
failing check's message names the symptom (grading/symptoms.py). The table of these
mistakes, the check that catches each and its message is in grading/README.md."""
import numpy as np
import pytest

from grading import symptoms
from grading.grade import describe, grade, passed_by_check
from grading.harness import build
from tests.grading.submissions import altered_reference

# mistake -> (the change to the image, a check that must fail, words its message must hold).
# The golden images count only after the hidden scene passes, so a mistake that shows in any
# scene is named by the hidden scene's check.
MISTAKES = {
    "upside down": ("image[::-1]", "hidden", "upside down"),
    "mirrored": ("image[:, ::-1]", "hidden", "mirrored left to right"),
    "gamma in the PFM": ("image ** (1 / 2.2)", "lit-plane", "gamma-encoded"),
    "missing 1/pi": ("image * 3.14159265", "lit-plane", "1/pi is missing"),
    "lost remainder rows": ("np.concatenate([image[:-5], 0 * image[-5:]])", "hidden",
                            "rows are exactly black"),
}


@pytest.fixture(scope="module")
def lab01_ref():
    return build("lab01-ref")[0]


@pytest.mark.parametrize("mistake", sorted(MISTAKES))
def test_a_classic_mistake_is_named(lab01_ref, mistake, tmp_path):
    change, check, words = MISTAKES[mistake]
    altered = altered_reference(tmp_path, change, lab01_ref)
    results = grade("01", altered, tmp_path, trusted=True)
    passed = passed_by_check(results)
    assert not passed[check], describe(results)
    output = next(t["output"] for t in results["tests"] if t["extra_data"]["check"] == check)
    assert words in output, describe(results)
    assert results["score"] <= 70, describe(results)


def test_the_reference_is_named_nothing(lab01_ref, tmp_path):
    """No symptom is made up: the reference's own image, and the golden mean against itself
    with noise, match none of the mistakes."""
    results = grade("01", lab01_ref, tmp_path, trusted=True)
    assert results["score"] == 100, describe(results)
    rng = np.random.default_rng(5)
    want = rng.uniform(0.1, 1.0, size=(32, 32, 3))
    noisy = want * rng.normal(1.0, 0.1, size=want.shape)
    assert symptoms.named(noisy, want) == ""
    assert "upside down" in symptoms.named(noisy[::-1], want)
