"""Bit identity with lab 01: a parallel renderer computes every pixel as lab 01 does, so its
image is lab 01's bits; where it is not, which rows and under which thread counts."""
from __future__ import annotations

import numpy as np

from grading.checks import draws, symptoms
from grading.checks.check_result import CheckResult, image_checked
from grading.checks.graded_scenes import timed_scene
from labkit.harness import run_lab


@image_checked("bit-identical to lab 01")
def check_bitwise_equal(binary, baseline, *, runs=None) -> CheckResult:
    """The image is the baseline's, bit for bit, for every way of running it (thread counts,
    rank counts), on the timed scene drawn for this grade: what a counter-based RNG and a
    race-free parallel loop guarantee. `runs`
    maps a label to run_lab keyword arguments; default: 1, 2, 3 and 7 threads. On a mismatch
    it says which of the two causes it is (why_different)."""
    runs = runs or {f"{t} threads": {"threads": t} for t in (1, 2, 3, 7)}
    with timed_scene() as scene:  # the scene drawn for this grade: nobody's stored image
        settings = dict(scene=scene, width=48, height=40, spp=8, seed=draws.seed("bitwise"))
        want = run_lab(baseline, **settings).image
        images = {label: run_lab(binary, **settings, **how).image for label, how in runs.items()}
        differing = [label for label, image in images.items()
                     if image.tobytes() != want.tobytes()]
        if not differing:
            return CheckResult("bit-identical to lab 01", True,
                               "identical for " + ", ".join(runs))
        return CheckResult("bit-identical to lab 01", False,
                           f"differs for {', '.join(differing)}; "
                           + why_different(binary, settings, runs, images, differing, want))


# The race probe's renders (why_different): how many at each count, and how much larger.
RACE_RUNS = 4
RACE_SCALE = 3


def row_ranges(rows: list[int]) -> str:
    """[0, 1, 2, 7, 9, 10] -> "0-2, 7, 9-10"."""
    spans: list[list[int]] = []
    for r in rows:
        if spans and r == spans[-1][1] + 1:
            spans[-1][1] = r
        else:
            spans.append([r, r])
    return ", ".join(f"{a}-{b}" if b > a else f"{a}" for a, b in spans)


def rows_differing(a: np.ndarray, b: np.ndarray) -> list[int]:
    return [int(y) for y in np.nonzero(np.any((a != b).reshape(a.shape[0], -1), axis=1))[0]]


def why_different(binary, settings: dict, runs: dict, images: dict, differing: list[str],
                  want: np.ndarray | None = None) -> str:
    """Tells the causes of other bits apart. Identified first: rows exactly black where lab
    01's image (`want`) is not, rows never rendered or never gathered (lab 04's skeleton),
    which would otherwise read as a work split below. Then, by rendering RACE_RUNS times each
    way that differed, the most threads or ranks first: renders that change from run to run at
    one count (a data race, a generator shared by threads), or the same image every time that
    depends on the count (random numbers drawn by thread, rank or chunk instead of by pixel:
    how the work is split). A race need not show in every run, so every differing count is
    tried before an image is called deterministic, on a render RACE_SCALE times larger a side:
    at the check's size each thread's share takes well under a time slice, and on a busy
    machine the threads then run one after another, which hides a shared generator."""
    if want is not None:
        for label in differing:
            black = symptoms.black_rows(images[label], want)
            if black:
                return f"at {label}, {black}"
    larger = dict(settings, width=settings["width"] * RACE_SCALE,
                  height=settings["height"] * RACE_SCALE)
    for label in reversed(differing):
        first, *again = [run_lab(binary, **larger, **runs[label]).image
                         for _ in range(RACE_RUNS)]
        rows = sorted({y for image in again for y in rows_differing(first, image)})
        if rows:
            return (f"nondeterministic: a data race or shared generator: renders at {label} "
                    f"differ from each other in {len(rows)} of {first.shape[0]} rows (rows "
                    f"{row_ranges(rows)}, at {larger['width']}x{larger['height']}); each "
                    f"pixel's random numbers must depend on the pixel alone, and each pixel be "
                    f"written by one thread")
    same = [label for label in runs if label not in differing]
    if not same:  # even the first way (1 thread, 1 rank) is not lab 01's image
        return (f"deterministic but different from lab 01 even at {differing[0]}: the same "
                f"image run after run at each count, but not lab 01's: are the random numbers "
                f"drawn by pixel and sample as lab 01 draws them?")
    return (f"deterministic but different: work split: the same image run after run at each "
            f"count, but {', '.join(differing)} give other bits than lab 01 ({', '.join(same)} "
            f"match): the random numbers depend on how the rows are split (drawn by thread, "
            f"rank or chunk, not by pixel?)")
