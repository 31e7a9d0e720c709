"""What a wrong image looks like, in words a student can act on: given an image that failed
a comparison and what it should have been, the classic mistakes it matches. Each test
transforms the image back the way the mistake would have changed it (flip it, undo a gamma,
divide by pi) and asks whether the result is much closer to what it should be; only a clear
match is named (a hint, never a verdict: the check itself decided pass or fail).

    named(image, want)   "; <symptom>" for a failing check's detail, or ""

Closed forms identify, statistics guess: an analytic check whose image is exactly its closed
form changed one known way (B+1 or B-1 bounces, a factor of pi, a gamma curve: `identified`)
records what it found for the grade (`grading`), and every later statistical guess defers to
it, so a missing 1/pi named by the sphere interior is never also called a gamma curve by the
golden images. Hints speak of what the lab has: no kernels or ranks in lab 01.
"""
from __future__ import annotations

import contextlib
import contextvars
import math

import numpy as np

from labkit import registry

# A transform must bring the image this much closer to `want` (mean absolute difference) to
# be named: noise alone never does that, a real match does by far (a flipped Cornell box
# flipped back drops to the noise, a tenth or less of the error).
CLEARLY_CLOSER = 0.35
GAMMA = 2.2


# What the closed-form checks of this grade identified, and the lab being graded.
_found: contextvars.ContextVar[list[str] | None] = contextvars.ContextVar("found", default=None)
_lab: contextvars.ContextVar[str | None] = contextvars.ContextVar("lab", default=None)
_part: contextvars.ContextVar[str] = contextvars.ContextVar("part", default="")
# An exact closed form matches to float rounding (~1e-5 relative); a transformed one to 1e-3.
EXACT = 1e-3


@contextlib.contextmanager
def grading(lab: str, part: str = ""):
    """One grade of lab `lab` (of its `part`, lab 02's "a"): hints fit the lab, and identified
    causes outrank guesses."""
    found, lab_token, part_token = _found.set([]), _lab.set(lab), _part.set(part)
    try:
        yield
    finally:
        _found.reset(found)
        _lab.reset(lab_token)
        _part.reset(part_token)


def record(cause: str) -> None:
    """A closed-form check identified `cause`: later guesses of this grade defer to it."""
    found = _found.get()
    if found is not None and cause not in found:
        found.append(cause)


# Who renders which rows, by how the lab's work is split: a GPU lab's grid, else its rubric in
# labs/labs.toml.
_GPU_SPLIT = "a grid that does not cover the image, or blocks that return early?"
_SPLIT_BY_RUBRIC = {
    "openmp": "the remainder of rows divided among threads?",
    "mpi": "the remainder of rows divided among ranks, or rows never gathered?",
}


def _graded_lab() -> registry.Lab | None:
    """The registry's entry of the lab being graded (None: a check run outside a grade)."""
    number = _lab.get()
    return None if number is None else registry.lab(number)


def _where_work_is_split() -> str:
    """Who renders which rows in the lab being graded, for the hints that depend on it."""
    lab = _graded_lab()
    if lab is None:  # a check run outside a grade: every lab's cause
        return "a loop bound that stops short, or the remainder of rows divided among ranks?"
    if lab.gpu:
        return _GPU_SPLIT
    return _SPLIT_BY_RUBRIC.get(lab.rubric, "a loop bound that stops short?")


def packet_lab() -> bool:
    """The lab being graded traces packets, one path a SIMD lane (its rubric "simd"; not a
    part of it that does not, as lab 02's Part A)."""
    lab = _graded_lab()
    return lab is not None and lab.rubric == "simd" and not _part.get()


def gpu_lab() -> bool:
    """The lab renders on a GPU, or is not known (a check run outside a grade): kernels and
    their synchronisation may then be named."""
    lab = _graded_lab()
    return lab is None or lab.gpu


def _matches(image: np.ndarray, want: np.ndarray) -> bool:
    """`image` is `want` to EXACT relative error at every pixel (zero-variance closed forms)."""
    scale = np.maximum(np.abs(want), 1e-30)
    return bool(np.all(np.abs(image - want) <= EXACT * scale))


def matching_causes(image: np.ndarray, want_at, bounces: int) -> list[str]:
    """Every mistake that a render of a zero-variance closed form is, to float rounding:
    `want_at(b)` is the closed form's radiance with b interactions (`bounces` was asked for).
    Candidates are B+1 or B-1 bounces, a missing or extra 1/pi, a gamma-encoded PFM, in that
    order. One render can match two by coincidence (for some albedos the right value raised
    to 1/2.2 is also, to 1e-3, the value of one bounce more), so a check that renders several
    bounce counts keeps the cause they all match (check_sphere_interior)."""
    gray = np.asarray(_gray(image), dtype=np.float64)
    want = want_at(bounces)
    candidates = [
        (want_at(bounces + 1), "one bounce too many: B+1 surface interactions where B were "
                               "asked for (check where the path's loop ends)"),
        (want_at(bounces - 1) if bounces > 1 else None,  # 0 bounces is black: not identified
         "one bounce too few: B-1 surface interactions where B were asked for (check where "
         "the path's loop ends)"),
        (want * math.pi, PI_MISSING),
        (want / math.pi, PI_EXTRA),
        (want ** (1 / GAMMA) if want > 0 else None, GAMMA_ENCODED),
    ]
    return [cause for value, cause in candidates
            if value is not None and _matches(gray, np.full_like(gray, value))]


def identified(image: np.ndarray, want_at, bounces: int) -> str:
    """What one render of a zero-variance closed form is, exactly, when it is not right: the
    first of matching_causes, "" when none fits. Each is identified, not guessed: the
    estimator has no noise here."""
    causes = matching_causes(image, want_at, bounces)
    return causes[0] if causes else ""


PI_MISSING = "pi times too bright: the diffuse BRDF's 1/pi is missing"
PI_EXTRA = "pi times too dark: an extra 1/pi in the diffuse BRDF"
GAMMA_ENCODED = (f"gamma-encoded: the values are the right ones raised to 1/{GAMMA}; a PFM "
                 f"holds linear radiance, gamma belongs in the PPM only")


def _factor_exact(gray: np.ndarray, expected: np.ndarray) -> str:
    """A per-pixel closed form (the lit plane) off by a constant factor of pi, or by a gamma
    curve, at nearly every pixel: identified, not guessed (the noise there is ~1e-3)."""
    lit = expected > 1e-6 * max(float(expected.max()), 1e-30)
    if not np.any(lit):
        return ""
    ratio = gray[lit] / expected[lit]
    gamma = np.clip(gray[lit], 0, None) ** GAMMA / expected[lit]
    for values, target, cause in (
            (ratio, math.pi, PI_MISSING), (ratio, 1 / math.pi, PI_EXTRA),
            (gamma, 1.0, GAMMA_ENCODED)):
        if float(np.median(np.abs(values / target - 1))) < 0.01:
            return cause
    return ""


def _gray(image: np.ndarray) -> np.ndarray:
    return image.mean(axis=2) if image.ndim == 3 else image


def _distance(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.mean(np.abs(a - b)))


def black_rows(image: np.ndarray, want: np.ndarray) -> str:
    """Rows exactly black where the expected image is lit: rows never rendered, or never
    gathered (an uneven division of rows that drops the remainder), in the lab's words. A row
    counts where most of the expected row's pixels are lit: a dim row of a few lit pixels can
    come out black from other random numbers (a shared generator at one thread), which is not
    a row left unrendered."""
    gray, expected = _gray(image), _gray(want)
    rows = [y for y in range(gray.shape[0])
            if np.all(gray[y] == 0) and np.count_nonzero(expected[y] > 0) * 2 > expected.shape[1]]
    if not rows:
        return ""
    where = (f"rows {rows[0]}-{rows[-1]}" if rows == list(range(rows[0], rows[-1] + 1))
             else f"{len(rows)} rows, the first {rows[0]}")
    lab = _graded_lab()
    gathered = lab is None or lab.rubric == "mpi"  # ranks send their rows to be gathered
    return (f"{len(rows)} of {gray.shape[0]} rows are exactly black ({where}): rows never "
            f"rendered{' or never gathered' if gathered else ''} "
            f"({_where_work_is_split()})")


def _factor(gray: np.ndarray, expected: np.ndarray) -> str:
    ratio = float(gray.sum() / max(expected.sum(), 1e-30))
    if abs(ratio / math.pi - 1) < 0.05:
        return "the image is about pi times too bright: the diffuse BRDF's 1/pi is missing?"
    if abs(ratio * math.pi - 1) < 0.05:
        return "the image is about pi times too dark: an extra 1/pi?"
    return ""


def named(image: np.ndarray, want: np.ndarray, closed_form: bool = False) -> str:
    """The mistakes `image` (H x W x 3, linear radiance) matches against `want` (the closed
    form or the golden mean, same shape or H x W), as "; ..." to append to a check's detail,
    or "" when none is clear. `closed_form`: `want` is exact, not a noisy mean, so a factor of
    pi or a gamma curve is identified there first, before any transform is guessed."""
    if image is None or want is None or image.shape[:2] != want.shape[:2]:
        return ""
    gray, expected = _gray(image), _gray(want)
    if not np.all(np.isfinite(gray)):
        return ""  # the checks count NaN and Inf themselves
    exact = _factor_exact(gray, expected) if closed_form else ""
    if exact:
        record(exact)
        return f"; {exact}"
    known = _found.get()
    if known:  # a closed form said what is wrong: it explains this image too, no guessing
        return f"; the analytic checks identified: {'; '.join(known)}"
    # A transform first: a flipped image also moves the scene's own black rows (a black sky
    # at the top lands at the bottom), which alone would look like rows never rendered.
    base = _distance(gray, expected)
    candidates = {
        "the image is upside down (row 0 is the top: check the y index or the file's row "
        "order)": gray[::-1],
        "the image is mirrored left to right (check the x index)": gray[:, ::-1],
        "the image is right with x and y swapped: check the pixel index arithmetic": gray.T
        if gray.shape[0] == gray.shape[1] else None,
        f"the PFM looks gamma-encoded (right after raising it to {GAMMA}): a PFM holds linear "
        "radiance; gamma belongs in the PPM only": np.clip(gray, 0, None) ** GAMMA,
    }
    distances = {text: _distance(undone, expected) for text, undone in candidates.items()
                 if undone is not None}
    best = min(distances, key=distances.get)
    if distances[best] < CLEARLY_CLOSER * base:
        return f"; {best}"
    found = black_rows(image, want) or _factor(gray, expected)
    return f"; {found}" if found else ""
