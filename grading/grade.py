"""The autograder: build a lab, run its correctness checks, print a score table and write a
Gradescope-style results.json.

    make grade LAB=01                  grade your own lab-01 code (./lab01)
    python3 -m grading.grade 01 --binary ./lab01-ref --results out.json

The table is the student's first sight: each check, its points, and what it saw.
"""
from __future__ import annotations

import argparse
import json
import os
import pathlib
import sys
import tempfile
import time

from grading import checks
from grading.harness import ROOT, available_cores, build

LAB01_REFERENCE = ROOT / "lab01-ref"

# Points per check, per lab. The checks are described in grading/checks.py.
RUBRICS = {
    "02": [
        ("analytic sphere interior", 10, checks.check_sphere_interior),
        ("analytic lit plane", 10, checks.check_lit_plane),
        ("analytic glass pane (Fresnel)", 10, checks.check_glass_slab),
        ("golden image 'cornell'", 15, lambda b, **k: checks.check_golden(b, "cornell", **k)),
        ("golden image 'showcase'", 15, lambda b, **k: checks.check_golden(b, "showcase", **k)),
        ("scale invariance 1e-4..1e5", 10, checks.check_scale_invariance),
        # The handout's bar is 2.5x on the full baseline; graded here is what holds on a busy
        # two-core machine in a short run.
        ("speedup >= 1.5x", 30, lambda b: checks.check_speedup(b, LAB01_REFERENCE, 1.5)),
    ],
    "03": [
        ("bit-identical to lab 01", 30, lambda b: checks.check_bitwise_equal(b, LAB01_REFERENCE)),
        ("golden image 'cornell'", 20, lambda b, **k: checks.check_golden(b, "cornell", **k)),
        ("golden image 'showcase'", 10, lambda b, **k: checks.check_golden(b, "showcase", **k)),
        # 75% of the cores' worth of throughput the machine gives during the run; the
        # handout's bar, 0.9 x cores, is measured by tools/bench_openmp.py on a quiet machine.
        ("parallel speedup", 40, lambda b: checks.check_parallel_speedup(b, LAB01_REFERENCE)),
    ],
    "04": [
        ("bit-identical to lab 01", 30, lambda b: checks.check_bitwise_equal(
            b, LAB01_REFERENCE, runs={f"{n} ranks": {"launcher": checks.mpirun(n), "threads": 1}
                                      for n in (1, 2, 3, 5)})),
        ("golden image 'cornell'", 20, lambda b, **k: checks.check_golden(
            b, "cornell", launcher=checks.mpirun(2), **k)),
        ("golden image 'showcase'", 10, lambda b, **k: checks.check_golden(
            b, "showcase", launcher=checks.mpirun(2), **k)),
        ("parallel speedup", 40, lambda b: checks.check_parallel_speedup(
            b, LAB01_REFERENCE, threads=1, launcher=checks.mpirun(available_cores()))),
    ],
    "01": [
        ("analytic sphere interior", 15, checks.check_sphere_interior),
        ("analytic lit plane", 15, checks.check_lit_plane),
        ("analytic glass pane (Fresnel)", 10, checks.check_glass_slab),
        ("golden image 'cornell'", 20, lambda b, **k: checks.check_golden(b, "cornell", **k)),
        ("golden image 'showcase'", 20, lambda b, **k: checks.check_golden(b, "showcase", **k)),
        # Robustness counts only for a renderer that renders light: a flat-colour skeleton is
        # trivially scale-invariant.
        ("scale invariance 1e-4..1e5", 10, checks.check_scale_invariance),
        ("reproducible", 10, checks.check_reproducible),
    ],
}


def grade(lab: str, binary: pathlib.Path, heatmap_dir: pathlib.Path) -> dict:
    tests, total, earned = [], 0, 0
    passed_by_name = {}
    for name, points, check in RUBRICS[lab]:
        start = time.perf_counter()
        if name == "scale invariance 1e-4..1e5" and not passed_by_name.get(
                "golden image 'cornell'"):
            passed, output = False, "not graded until the golden 'cornell' image passes"
        else:
            passed, output = run_check(check, name, binary, heatmap_dir)
        passed_by_name[name] = passed
        score = points if passed else 0
        total += points
        earned += score
        tests.append({"name": name, "score": score, "max_score": points, "output": output,
                      "execution_time": round(time.perf_counter() - start, 3),
                      "visibility": "visible"})
    return {"score": earned, "max_score": total, "tests": tests}


def run_check(check, name, binary, heatmap_dir) -> tuple[bool, str]:
    try:
        kwargs = {"heatmap_dir": heatmap_dir} if "golden" in name else {}
        result = check(binary, **kwargs)
        return result.passed, result.detail
    except Exception as e:  # a crash, a timeout, a missing image: no points, say why
        return False, f"could not run: {e}"


def passed_by_check(results: dict) -> dict[str, bool]:
    """Check name -> whether it earned all its points."""
    return {t["name"]: t["score"] == t["max_score"] for t in results["tests"]}


def describe(results: dict) -> str:
    """One line per check: its name and what it saw."""
    return "\n".join(f"{t['name']}: {t['output']}" for t in results["tests"])


def unmeasurable(results: dict, check: str = "parallel speedup") -> str | None:
    """What the speedup check said when the machine was too busy to measure it, else None."""
    output = next(t["output"] for t in results["tests"] if t["name"] == check)
    return output if output.startswith("not measurable") else None


def print_table(lab: str, binary: pathlib.Path, results: dict) -> None:
    print(f"Lab {lab} — {binary}")
    print(f"{'check':<32} {'points':>7}  what it saw")
    for t in results["tests"]:
        mark = "PASS" if t["score"] == t["max_score"] else "FAIL"
        print(f"{t['name']:<32} {t['score']:>3}/{t['max_score']:<3}  {mark} {t['output']}")
    print(f"{'total':<32} {results['score']:>3}/{results['max_score']}")


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("lab", choices=sorted(RUBRICS))
    p.add_argument("--binary", help="lab binary to grade (default: build ./labNN)")
    p.add_argument("--results", default="results.json", help="where to write results.json")
    p.add_argument("--heatmaps", default="grading-heatmaps",
                   help="folder for diff heatmaps of failing image comparisons")
    a = p.parse_args()
    build("lab01-ref")  # the baseline of every speedup
    if os.geteuid() == 0:  # OpenMPI refuses root unless told; graders often run as root
        os.environ.setdefault("OMPI_ALLOW_RUN_AS_ROOT", "1")
        os.environ.setdefault("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
    binary = pathlib.Path(a.binary) if a.binary else build(f"lab{a.lab}")[0]
    if not binary.exists():
        print(f"error: {binary}: no such binary", file=sys.stderr)
        return 2
    heatmaps = pathlib.Path(a.heatmaps)
    heatmaps.mkdir(parents=True, exist_ok=True)
    results = grade(a.lab, binary.resolve(), heatmaps)
    print_table(a.lab, binary, results)
    out = pathlib.Path(a.results)
    with tempfile.NamedTemporaryFile("w", dir=out.parent.resolve(), delete=False) as f:
        json.dump(results, f, indent=2)
    os.replace(f.name, out)
    if not any(heatmaps.iterdir()):
        heatmaps.rmdir()
    print(f"wrote {out}" + (f"; diff heatmaps in {heatmaps}/" if heatmaps.exists() else ""))
    return 0


if __name__ == "__main__":
    sys.exit(main())
