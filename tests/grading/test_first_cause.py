"""The first cause a failing check gives is the true one, and comes with a command the student
can rerun at home: an MPI error by name with mpirun's own text, a deadlock as a rank waiting
for a message, lab 04's missing gather as rows never gathered (not as a work split)."""
import pytest

from grading import grade
from grading.checks import draws, symptoms
from grading.checks.golden import check_golden
from labkit.harness import (
    ROOT,
    RunError,
    RunPolicy,
    build,
    cpu_has_avx2,
    failure_message,
    policy,
    rerun_as,
    run_lab,
)
from labkit.mpi import mpirun
from labkit.sandbox import Limits
from labkit.variants import build_pristine_skeleton, build_variant, lab_sources

UNTRUSTED = RunPolicy(trusted=False, limits=Limits(wall_seconds=30))


@pytest.fixture(autouse=True)
def mpirun_as_root(monkeypatch):
    monkeypatch.setenv("OMPI_ALLOW_RUN_AS_ROOT", "1")
    monkeypatch.setenv("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")


def rerun_words(message: str) -> list[str]:
    return message.split("; rerun: ", 1)[1].split(";", 1)[0].split()


def test_an_mpi_type_mismatch_is_named_with_a_command_to_rerun(tmp_path):
    build("lab04-ref")  # the driver objects the mutant links
    source = lab_sources("04-mpi")["render.cpp"]
    old = "MPI_Recv(message, 2, MPI_INT, 0, kTagWork"
    assert old in source
    mutant = build_variant("04-mpi", tmp_path,
                           {"render.cpp": source.replace(old, old.replace(", 2,", ", 1,"))})
    # OpenMPI's own report of the error reaches mpirun cut short now and then when the rank
    # aborts at once (most often on a busy machine); lab 04's driver writes the error to the
    # rank's stderr first (mpi_main.cpp), so it is named every time, in one run.
    with policy(UNTRUSTED), rerun_as("./lab04"), pytest.raises(RunError) as failed:
        run_lab(mutant, scene=ROOT / "common/scenes/cornell.json", width=16, height=12,
                spp=2, launcher=mpirun(2))
    message = str(failed.value)
    assert "MPI_ERR_TRUNCATE" in message.split("; rerun: ")[0], message  # named first
    assert "An error occurred in MPI_Recv" in message  # the rank's own words reach the student
    words = rerun_words(message)
    assert words[:1] == ["mpirun"] and "./lab04" in words, message
    scene = words[words.index("--scene") + 1]
    assert (ROOT / scene).is_file(), message


def test_a_check_on_a_scene_made_for_it_names_a_scene_that_exists(tmp_path):
    """A scene written for one check is deleted when the check ends: the command names the
    public scene it varies."""
    made = tmp_path / "drawn.json"
    made.write_text((ROOT / "common/scenes/cornell.json").read_text())
    with policy(UNTRUSTED), rerun_as("./lab01"), pytest.raises(RunError) as failed:
        run_lab(ROOT / "lab01-ref", scene=made, width=8, height=8, spp=1,
                extra=["--bounces", "-3"])
    words = rerun_words(str(failed.value))
    assert words[0] == "./lab01", failed.value
    assert (ROOT / words[words.index("--scene") + 1]).is_file(), failed.value
    assert str(tmp_path) not in str(failed.value).split("; it said")[0]


def test_a_deadlock_is_a_rank_waiting_for_a_message():
    message = failure_message("timed out after 20 s", "", mpirun(2), "mpirun ./lab04")
    assert "a rank waits for a message that never comes" in message


def test_the_missing_gather_is_rows_never_gathered_not_a_work_split(tmp_path):
    build("lab04-ref")
    skeleton = build_pristine_skeleton("04-mpi", tmp_path)
    item = next(i for i in grade.RUBRICS["04"] if i.id == "bitwise")
    with draws.secret("first-cause"), symptoms.grading("04"), policy(UNTRUSTED):
        result = item.run(skeleton)
    assert not result.passed
    cause = result.detail.split("; ", 1)[1]
    assert "never gathered" in cause and "work split" not in cause, result.detail


def test_a_wrong_lane_mask_in_lab02_is_named_by_its_kind_before_the_statistics(tmp_path):
    """Lab 02's rectangle test keeping hits behind the ray (its `crosses` mask dropped) and its
    triangle test accepting one winding only: the golden check names the lanes, which lab
    01's bits show, and the two kinds whose scenes alone differ, not the sphere or the convex
    quad, before "too noisy", which would point at a loop over paths lab 02 students never
    write."""
    if not cpu_has_avx2():
        pytest.skip("this CPU has no AVX2/FMA: lab 02's Part B cannot run")
    source = (ROOT / "common/simd/packet_hits.h").read_text()
    mutations = {"return select(crosses & inside, t, t_max);": "return select(inside, t, t_max);",
                 "inside = and_not(candidates, any_negative & any_positive);":
                     "inside = and_not(candidates, any_negative);"}
    for old, new in mutations.items():
        assert source.count(old) == 1, old
        source = source.replace(old, new)
    mutant = build_variant("02-simd", tmp_path, {"packet_hits.h": source})
    with draws.secret("lanes"), symptoms.grading("02"), policy(UNTRUSTED), rerun_as("./lab02"):
        result = check_golden(mutant, "showcase")
    assert not result.passed
    cause = result.detail.split("; ", 1)[0]
    assert cause.startswith("lanes: ") and "lane mask" in cause, result.detail
    assert "axis-aligned rectangles" in cause and "triangles" in cause, cause
    assert "spheres" not in cause and "convex quads" not in cause, cause
    # and the command to see it again at home, on the scene the check rendered
    assert "rerun: ./lab02 --scene common/scenes/showcase.json " in result.detail, result.detail
