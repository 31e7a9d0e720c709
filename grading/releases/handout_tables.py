"""Each handout's grading table, generated from the grader's rubrics (grading/grade.py's
RUBRICS): the checks, their points, what each needs before it counts and what it takes to
pass, so that a handout cannot say other numbers than the grader uses.

    python3 -m grading.releases.handout_tables           rewrite the tables in handouts/NN-*.md
    python3 -m grading.releases.handout_tables --check   exit 1 naming the handouts that differ

A handout holds its table between the two marker lines BEGIN and END below; everything
between them is generated. tests/grading/test_handout_tables.py fails when a handout's table
is not what this module makes of the rubric.
"""
from __future__ import annotations

import argparse
import inspect
import pathlib
import re
import sys

from grading import grade
from grading.checks import analytic, identity, invariance, mpi, races, speed
from grading.checks.golden import GOLDEN_TEST_SPP
from labkit import harness
from labkit.harness import ROOT

BEGIN = ("<!-- grading table: generated from grading/grade.py's RUBRICS by "
         "`python3 -m grading.releases.handout_tables`; edit the rubric, not this table -->")
END = "<!-- end of the generated grading table -->"
HANDOUTS = ROOT / "handouts"


def closure(fn, name: str, default=None):
    """The value a rubric item's lambda closed over as `name` (its options), or default."""
    names = getattr(getattr(fn, "__code__", None), "co_freevars", ())
    cells = getattr(fn, "__closure__", None) or ()
    return dict(zip(names, (c.cell_contents for c in cells))).get(name, default)


def default_bitwise_threads() -> str:
    """The thread counts check_bitwise_equal uses when a rubric names none."""
    m = re.search(r"for t in \(([\d, ]+)\)", inspect.getsource(identity.check_bitwise_equal))
    counts = [c.strip() for c in m.group(1).split(",")] if m else []
    return f"{', '.join(counts[:-1])} and {counts[-1]} threads" if counts else "several threads"


def parameter(fn, name: str):
    return inspect.signature(fn).parameters[name].default


def speed_curve(lab: str, item: grade.Item) -> str:
    """How speed points fall short of the bar: the grader's partial-credit curve
    (speed.speed_credit)."""
    return (f"all points at the bar, falling linearly to none at {speed.ZERO_CREDIT_AT:g} x "
            f"the bar")


def passes_when(lab: str, item: grade.Item) -> str:
    """What the check runs and what it takes, from the rubric and the checks' parameters."""
    options = closure(item.run, "options", {}) or {}
    launcher = options.get("launcher")
    ranks = f", under `mpirun -np {launcher[-1]}`" if launcher else ""
    if item.id.startswith("golden-"):
        scene = item.id.removeprefix("golden-")
        return (f"`{scene}` at {GOLDEN_TEST_SPP} spp{ranks} matches the converged golden "
                f"image within its noise (per-pixel z-scores; a heatmap where it does not)")
    if item.id == "sphere-interior":
        bounces = ", ".join(map(str, parameter(analytic.check_sphere_interior, "bounces")))
        return (f"inside a diffuse sphere the radiance has a closed form: matched at "
                f"{bounces} bounces")
    if item.id == "lit-plane":
        return "a plane under the point light matches its closed form (direct light)"
    if item.id == "glass-pane":
        return "light through a glass pane matches Fresnel's closed form"
    if item.id == "hidden":
        return ("a scene drawn from a secret when grading matches lab 01's reference: worth "
                "nothing itself, but the golden images count only when it passes")
    if item.id == "scale":
        factors = ", ".join(f"{f:g}" for f in invariance.SCALE_FACTORS)
        return f"the Cornell box scaled by {factors} gives the same image"
    if item.id == "reproducible":
        return "two runs with the same seed give the same bits"
    if item.id == "structure-of-arrays":
        return "the path pool (`--json`'s `layout`) is a structure of arrays"
    if item.id == "bitwise":
        runs = options.get("runs")
        how = ", ".join(runs) if runs else default_bitwise_threads()
        return f"the image is `lab01-ref`'s bit for bit with {how}"
    if item.id == "part-a":
        return ("`./lab02a` (your `part-a/vec3.h` in lab 01's renderer) passes lab 01's sphere "
                "interior, lit plane, glass pane and the hidden scene, a quarter of the points "
                "each, once its Vec3 no longer says \"scalar fallback\" (the skeleton's, "
                "correct but not SSE, earns none)")
    if item.id == "distributions":
        ranks = parameter(mpi.check_distributions, "ranks")
        return (f"with `RT_MPI_DISTRIBUTION=interleaved` rank r of {ranks} renders "
                f"rows r, r + {ranks}, r + {2 * ranks}, ..., with `dynamic` the rows are not "
                f"block's fixed bands (as `RT_MPI_REPORT=1` lists them); half the points each")
    if item.id == "races":
        counts = " and ".join(str(t) for t in races.RACE_THREADS)
        return (f"your sources built for ThreadSanitizer (`make lab03-race`: clang, LLVM's "
                f"OpenMP and its Archer tool, your files at -O0) report no data race at "
                f"{counts} threads on a small render: a variable the threads share where each "
                f"needs its own is found even where every image is right")
    if item.id == "hybrid":
        threads = parameter(mpi.check_hybrid_threads, "threads")
        return (f"one rank with `--threads {threads}` under `mpirun`: no thread did "
                f"{mpi.HYBRID_SHARED:.0%} of the CPU time (each thread's measured by the "
                f"grader): the rank's rows are shared among its threads")
    if item.id == "parallel-speedup":
        fraction = parameter(speed.check_parallel_speedup, "fraction")
        who = ("`mpirun -np N` (N = the cores), 1 thread a rank" if launcher
               else "every core")
        return (f"on {who}, wall-clock speedup over `lab01-ref` (interleaved, best of rounds) "
                f"at least {fraction:g} x the capacity measured alongside, and at least "
                f"{harness.NOISE_FLOOR:g}x; every timed image `lab01-ref`'s bits. Speed: "
                f"{speed_curve(lab, item)}. A machine too busy to measure gives only the points "
                f"it measured, marked for regrade")
    if item.id in ("speedup", "speed"):
        return (f"{item.label}, in wall-clock time against the reference, interleaved, best "
                f"of rounds; the timed images must pass the golden test. Speed: "
                f"{speed_curve(lab, item)}")
    return item.label


def table(lab: str) -> str:
    rubric = grade.RUBRICS[lab]
    labels = {i.id: i.label for i in rubric}
    lines = [BEGIN, "", "| check | points | counts only when | passes when |", "|---|---:|---|---|"]
    for item in rubric:
        gate = ", ".join(f"{labels[r]} passes" for r in item.requires) or "always"
        lines.append(f"| {item.label} | {item.points} | {gate} | {passes_when(lab, item)} |")
    total = sum(i.points for i in rubric)
    lines += [f"| **total** | **{total}** | | |", "",
              f"`make grade LAB={lab}` prints these checks with what each saw; a check that counts "
              f"only when another passes earns its points once that one does.", "", END]
    return "\n".join(lines)


def handout(lab: str) -> pathlib.Path:
    return next(HANDOUTS.glob(f"{lab}-*.md"))


def current(text: str) -> str | None:
    """The table a handout holds now, markers included, or None."""
    m = re.search(re.escape(BEGIN) + r".*?" + re.escape(END), text, re.S)
    return m.group(0) if m else None


def differing() -> list[str]:
    return [handout(lab).relative_to(ROOT).as_posix() for lab in sorted(grade.RUBRICS)
            if current(handout(lab).read_text()) != table(lab)]


def rewrite() -> list[str]:
    """Replace each handout's table with the generated one; returns the files changed. A
    handout without the markers is left alone (and --check names it)."""
    changed = []
    for lab in sorted(grade.RUBRICS):
        path = handout(lab)
        text = path.read_text()
        old = current(text)
        if old is not None and old != table(lab):
            path.write_text(text.replace(old, table(lab)))
            changed.append(path.relative_to(ROOT).as_posix())
    return changed


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--check", action="store_true", help="exit 1 naming handouts that differ")
    a = p.parse_args(argv)
    if a.check:
        bad = differing()
        if bad:
            print(f"grading tables out of date (python3 -m grading.releases.handout_tables): "
                  f"{', '.join(bad)}", file=sys.stderr)
            return 1
        return 0
    for path in rewrite():
        print(f"rewrote the grading table of {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
