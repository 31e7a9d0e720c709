"""Lab 02's Part A, graded beside Part B: lab 01's renderer on the student's SSE Vec3
(part-a/vec3.h), the binary ./lab02a, on which the rubric runs lab 01's checks.

How it is built follows the grade: at home (`make grade LAB=02`) `make lab02a`; a hand-in
(--sources) in the sandbox, in lab 02's students' tree, as `make variant VARIANT_LAB=02-simd-a`
builds it (the hand-in's part-a/vec3.h and the lab's pixel loop, render_vec3_sse.cpp, linked
with driver objects built with the skeleton's vec3.h); a binary (--binary) with --part-a.
"""
from __future__ import annotations

import os
import pathlib

from grading import students_tree
from labkit.harness import ROOT, make_in_root

LABS = {"02"}  # the labs with a Part A
HANDIN_NAME = "part-a/vec3.h"
LOOP = ROOT / "labs" / "02-simd" / "render_vec3_sse.cpp"
MAX_DEPTH = 6


def has_part_a(lab: str) -> bool:
    return lab in LABS


def find(handin: pathlib.Path) -> pathlib.Path | None:
    """The hand-in's part-a/vec3.h, the shallowest, found without following links."""
    best = None
    for dirpath, dirs, files in os.walk(handin, followlinks=False):
        depth = len(pathlib.Path(dirpath).relative_to(handin).parts)
        dirs[:] = sorted(d for d in dirs if not d.startswith(".") and depth < MAX_DEPTH)
        if pathlib.Path(dirpath).name == "part-a" and "vec3.h" in files:
            if best is None or depth < best[0]:
                best = (depth, pathlib.Path(dirpath) / "vec3.h")
    return best[1] if best else None


def skeleton_vec3() -> bytes:
    return (ROOT / "labs" / "02-simd" / "skeleton" / HANDIN_NAME).read_bytes()


def build(sources: pathlib.Path | None, trusted: bool,
          notes: list[str] | None = None) -> tuple[pathlib.Path | None, str]:
    """(Part A's binary, "") or (None, why): the compiler's first errors or a refusal."""
    if sources is None:
        p = make_in_root("lab02a", capture_output=True, text=True, errors="replace")
        return (ROOT / "lab02a", "") if p.returncode == 0 else (None, p.stdout + p.stderr)
    from grading.compile import build_in_sandbox
    found = find(sources)
    try:
        vec3 = students_tree.read_regular(found, HANDIN_NAME) if found else skeleton_vec3()
    except students_tree.HandInError as e:
        return None, f"refused: {e}"
    if found is None and notes is not None:
        notes.append(f"Part A: not handed in, the skeleton's copy used: {HANDIN_NAME}")
    binary, errors, _ = build_in_sandbox("02-simd-a", sources, trusted=trusted,
                                         files={"vec3.h": vec3,
                                                "render_vec3_sse.cpp": LOOP.read_bytes()},
                                         tree_lab="02-simd")
    return binary, errors


def check_part_a(binary, secret: str, reference: pathlib.Path):
    """Lab 01's checks on Part A's binary, a quarter of the points each: the three closed
    forms (a Vec3 operator that drops a lane, a dot without its z term, shows there) and the
    hidden scene (drawn from the secret, so a stored image cannot pass it). They count only
    once the Vec3 is no longer the skeleton's scalar fallback (the summary's "device", from
    vec3.h's kVec3Kind): the skeleton is correct, so correctness alone is not the task. Its
    own symptom context: what it identifies is Part A's, never said of Part B's images."""
    from grading.checks import analytic, check_result, hidden, symptoms
    from labkit.harness import run_lab
    parts = [("sphere interior", lambda: analytic.check_sphere_interior(binary)),
             ("lit plane", lambda: analytic.check_lit_plane(binary)),
             ("glass pane", lambda: analytic.check_glass_slab(binary)),
             ("hidden scene", lambda: hidden.check_hidden(binary, reference, secret))]
    said, passed = [], 0
    with symptoms.grading("02", part="a"):  # not Part B's packets: no lane masks here
        for name, run in parts:
            try:
                result = run()
            except Exception as e:  # a crash, a timeout: that part fails, the others run
                result = check_result.CheckResult(name, False, f"could not run: {e}")
            passed += result.passed
            said.append(f"{'PASS' if result.passed else 'FAIL'} {name}"
                        + ("" if result.passed else f": {result.detail}"))
        try:
            device = str((run_lab(binary, width=1, height=1, spp=1).json or {}).get("device"))
        except Exception as e:
            device = f"(could not run: {e})"
    if SCALAR in device:
        said.insert(0, f"not counted: its Vec3 says \"{SCALAR}\" (kVec3Kind in part-a/vec3.h): "
                       f"the skeleton's scalar Vec3 earns none of Part A's points, SSE does")
        passed = 0
    return check_result.CheckResult("Part A", passed == len(parts), "; ".join(said),
                                    credit=passed / len(parts))


SCALAR = "scalar fallback"  # what the skeleton's kVec3Kind says
