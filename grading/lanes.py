"""Lab 02's identified cause of a wrong image: lanes whose bits are not lab 01's."""
from __future__ import annotations

import numpy as np

from grading import draws, symptoms
from grading.check_result import LAB01_REFERENCE
from labkit.harness import run_lab


def lanes_not_lab01(binary, **how) -> str:
    """Lab 02's identified cause of a wrong image, "" elsewhere or where it does not apply:
    every lane of a packet computes lab 01's path with lab 01's roundings (handout 02), so a
    render whose bits differ from lab01-ref's on the public scene has lanes whose hit, miss
    or bounce is not their own: a mask. Told before the comparison's statistics, whose "too
    noisy" would otherwise point at a loop over paths lab 02 students never write."""
    if not symptoms.packet_lab():
        return ""
    settings = dict(width=32, height=32, spp=8, seed=draws.seed("lanes"))
    try:
        want = run_lab(LAB01_REFERENCE, **settings).image
        image = run_lab(binary, **settings, **how).image
    except Exception:  # the check itself reports a crash or a bad image
        return ""
    if image.shape != want.shape or image.tobytes() == want.tobytes():
        return ""
    pixels = int(np.count_nonzero(np.any(image != want, axis=2)))
    return (f"lanes: {pixels} of {want.shape[0] * want.shape[1]} pixels of the Cornell box "
            f"are not lab 01's bits, which every lane computes exactly: a lane mask keeps a "
            f"hit, a miss or a finished path for lanes it does not belong to (each intersect "
            f"returns t only where the ray crosses the surface in front of t_max and inside "
            f"it; a dead lane adds nothing)")
