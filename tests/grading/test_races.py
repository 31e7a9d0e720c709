"""Lab 03's race check (grading/checks/races.py): the hand-in built for ThreadSanitizer with
LLVM's OpenMP, in the sandbox, and run on a small render. The classic mistake whose every
image is right, a pixel index declared outside the parallel loop (the optimiser keeps it in a
register), is caught and named by its line; the solution is clean; a serial hand-in is never
reached (the check waits for the parallel speedup)."""
import shutil

import pytest

from grading.checks import races
from grading.grade import RUBRICS
from labkit.harness import RunPolicy, policy
from labkit.sandbox import Limits
from labkit.variants import lab_sources

UNTRUSTED = RunPolicy(trusted=False, limits=Limits(wall_seconds=60))
pytestmark = pytest.mark.skipif(shutil.which("clang++") is None,
                                reason="clang++ is missing (make deps installs it)")

LOOP = "#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)"
INNER = "        for (int x = 0; x < width; ++x) image.at(x, y) = pixel(x, y);"


def shared_index_sources() -> dict[str, str]:
    """The solution with its pixel index declared once, before the parallel loop: every thread
    writes the same `x`."""
    sources = lab_sources("03-openmp")
    render = sources["render.cpp"]
    assert render.count(LOOP) == 1 and render.count(INNER) == 1
    render = render.replace("#if defined(RT_RUNTIME_SCHEDULE)",
                            "    int x;\n#if defined(RT_RUNTIME_SCHEDULE)", 1)
    sources["render.cpp"] = render.replace(INNER, INNER.replace("int x = 0", "x = 0"))
    return sources


def built(tmp_path, sources: dict[str, str]):
    folder = tmp_path / "handin"
    folder.mkdir()
    for name, text in sources.items():
        (folder / name).write_text(text)
    binary, errors = races.build("03-openmp", folder, trusted=False)
    assert binary is not None, errors
    return binary


@pytest.mark.timed
def test_the_shared_index_is_a_race_named_by_its_line(tmp_path, mode):
    """In bubblewrap; in the user sandbox (where namespaces are refused), which gives LLVM's
    OpenMP no /dev/shm or /tmp to start with, the check is left to a regrade, never failed."""
    binary = built(tmp_path, shared_index_sources())
    with policy(UNTRUSTED):
        result = races.check_races(binary)
    if mode == "user":
        assert result.regrade and result.credit == 0 and result.provisional == 1, result
        return
    assert not result.passed and result.credit == 0, result
    line = next(i + 1 for i, text in enumerate(shared_index_sources()["render.cpp"].splitlines())
                if text == INNER.replace("int x = 0", "x = 0"))
    assert f"render.cpp line {line}" in result.detail, result.detail
    assert ("rerun: make lab03-race && TSAN_OPTIONS=ignore_noninstrumented_modules=1 "
            "./lab03-race --threads") in result.detail, result.detail


def test_the_solution_is_clean(tmp_path):
    binary = built(tmp_path, lab_sources("03-openmp"))
    with policy(UNTRUSTED):
        for _ in range(2):
            result = races.check_races(binary)
            assert result.passed and result.credit == 1, result


def test_the_race_check_waits_for_the_speedup_and_has_points():
    item = next(i for i in RUBRICS["03"] if i.id == "races")
    assert item.points > 0 and item.requires == ("parallel-speedup",) and item.part == "race"
