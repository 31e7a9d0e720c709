"""What a wrong image looks like, in words a student can act on: given an image that failed
a comparison and what it should have been, the classic mistakes it matches. Each test
transforms the image back the way the mistake would have changed it (flip it, undo a gamma,
divide by pi) and asks whether the result is much closer to what it should be; only a clear
match is named (a hint, never a verdict: the check itself decided pass or fail).

    named(image, want)   "; <symptom>" for a failing check's detail, or ""
"""
from __future__ import annotations

import math

import numpy as np

# A transform must bring the image this much closer to `want` (mean absolute difference) to
# be named: noise alone never does that, a real match does by far (a flipped Cornell box
# flipped back drops to the noise, a tenth or less of the error).
CLEARLY_CLOSER = 0.35
GAMMA = 2.2


def _gray(image: np.ndarray) -> np.ndarray:
    return image.mean(axis=2) if image.ndim == 3 else image


def _distance(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.mean(np.abs(a - b)))


def black_rows(image: np.ndarray, want: np.ndarray) -> str:
    """Rows exactly black where the expected image is not: rows never rendered, or never
    gathered (an uneven division of rows among ranks or threads that drops the remainder)."""
    gray, expected = _gray(image), _gray(want)
    rows = [y for y in range(gray.shape[0]) if np.all(gray[y] == 0) and np.any(expected[y] > 0)]
    if not rows:
        return ""
    where = (f"rows {rows[0]}-{rows[-1]}" if rows == list(range(rows[0], rows[-1] + 1))
             else f"{len(rows)} rows, the first {rows[0]}")
    return (f"{len(rows)} of {gray.shape[0]} rows are exactly black ({where}): rows never "
            f"rendered or never gathered (the remainder of rows divided among ranks?)")


def _factor(gray: np.ndarray, expected: np.ndarray) -> str:
    ratio = float(gray.sum() / max(expected.sum(), 1e-30))
    if abs(ratio / math.pi - 1) < 0.05:
        return "the image is about pi times too bright: the diffuse BRDF's 1/pi is missing?"
    if abs(ratio * math.pi - 1) < 0.05:
        return "the image is about pi times too dark: an extra 1/pi?"
    return ""


def named(image: np.ndarray, want: np.ndarray) -> str:
    """The mistakes `image` (H x W x 3, linear radiance) matches against `want` (the closed
    form or the golden mean, same shape or H x W), as "; ..." to append to a check's detail,
    or "" when none is clear."""
    if image is None or want is None or image.shape[:2] != want.shape[:2]:
        return ""
    gray, expected = _gray(image), _gray(want)
    if not np.all(np.isfinite(gray)):
        return ""  # the checks count NaN and Inf themselves
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
