"""Lab 07's lesson, which speed cannot grade: where its path pool puts neighbouring paths."""
from __future__ import annotations

from grading.checks.check_result import CheckResult
from labkit.harness import run_lab


def check_structure_of_arrays(binary) -> CheckResult:
    """Lab 07's lesson, which speed cannot grade: on the H200 lab 06's array of structures is
    within 10% of the structure of arrays (handouts/07-soa.md). The binary reports where its
    path pool puts the same field of two neighbouring queued paths (a probe that stores two
    paths with the submission's own code and searches the memory: common/wavefront/
    layout_probe.cuh); a structure of arrays puts them one 4-byte word apart."""
    json = run_lab(binary, width=4, height=4, spp=1).json or {}
    layout = json.get("layout") if isinstance(json.get("layout"), dict) else {}
    apart = layout.get("bytes_between_neighbours")
    if not isinstance(apart, int) or isinstance(apart, bool):
        return CheckResult("structure of arrays", False,
                           "the program does not report its pool's layout (--json has no layout)")
    if apart < 0:
        return CheckResult("structure of arrays", False,
                           "a queued path stored at places 0 and 1 was not found in the pool's "
                           "memory: the pool does not store what it is given")
    verdict = "a structure of arrays" if apart == 4 else "want 4: one array per field"
    return CheckResult("structure of arrays", apart == 4,
                       f"the same field of neighbouring paths lies {apart} bytes apart "
                       f"({verdict})")
