"""The classic image mistakes, each handed in as lab 01's reference with its image changed the
way the mistake changes it, graded by lab 01's rubric: each loses the points it should, and a
failing check's message names the symptom (grading/checks/symptoms.py). The table of these
mistakes, the check that catches each and its message is in grading/README.md."""
import numpy as np
import pytest

from grading.checks import symptoms
from grading.grade import describe, grade, passed_by_check
from labkit.harness import build
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


# ---- closed forms identify; guesses defer; hints speak the lab's words ----------------------

def interior(bounces: int) -> float:
    """The sphere interior's closed form (albedo 0.6, radius 2, intensity 3)."""
    from labkit.scenes import sphere_interior_radiance
    return sphere_interior_radiance(0.6, 2.0, 3.0, bounces)


@pytest.mark.parametrize("value, words", [
    (lambda b: interior(b + 1), "one bounce too many"),
    (lambda b: interior(b - 1), "one bounce too few"),
    (lambda b: interior(b) * np.pi, "1/pi is missing"),
    (lambda b: interior(b) / np.pi, "an extra 1/pi"),
    (lambda b: interior(b) ** (1 / 2.2), "gamma-encoded"),
])
def test_a_closed_form_identifies_the_mistake(value, words):
    for b in (2, 4):
        image = np.full((4, 4, 3), value(b), dtype=np.float32)
        assert words in symptoms.identified(image, interior, b)


def test_a_closed_form_identifies_nothing_else():
    """Off by 1% (no known mistake), or all black: nothing is identified."""
    for image in (np.full((4, 4, 3), interior(2) * 1.01), np.zeros((4, 4, 3))):
        assert symptoms.identified(image, interior, 2) == ""


def test_guesses_defer_to_what_a_closed_form_identified():
    rng = np.random.default_rng(7)
    want = rng.uniform(0.05, 0.5, size=(32, 32, 3))
    gamma_like = want ** (1 / 2.2)
    assert "gamma" in symptoms.named(gamma_like, want)  # a guess, alone
    with symptoms.grading("01"):
        symptoms.record(symptoms.PI_MISSING)
        hint = symptoms.named(gamma_like, want)
    assert "1/pi is missing" in hint and "gamma" not in hint, hint


def test_a_factor_of_pi_on_a_per_pixel_closed_form_is_not_called_gamma():
    rng = np.random.default_rng(8)
    want = rng.uniform(0.05, 0.3, size=(24, 24))
    noisy = want[..., None] * np.pi * rng.normal(1.0, 1e-3, size=(24, 24, 3))
    hint = symptoms.named(noisy, want, closed_form=True)
    assert "1/pi is missing" in hint and "gamma" not in hint, hint


@pytest.mark.parametrize("lab, said, unsaid", [
    ("01", "loop bound", ("rank", "thread", "kernel", "gathered")),
    ("03", "threads", ("rank", "kernel", "gathered")),
    ("04", "ranks", ("kernel",)),
])
def test_black_rows_are_named_in_the_lab_s_words(lab, said, unsaid):
    want = np.full((16, 16, 3), 0.5)
    image = want.copy()
    image[-3:] = 0
    with symptoms.grading(lab):
        hint = symptoms.named(image, want)
    assert "rows are exactly black" in hint and said in hint, hint
    for word in unsaid:
        assert word not in hint, hint
