"""`make release LAB=NN OUT=DIR` (grading/releases/release.py): releases for labs 01 and 03 are
made in a scratch folder, searched for solutions, and used there as a student would: the public
tests (`make test-labs` in lab 03's), `make grade` (lab 01), the references built or served
prebuilt. Then every way it must refuse, and the leak check on leaks planted in a copy.

Lab 03's `make grade` is not run here: its skeleton is a correct serial renderer, graded on
parallel speedup, which a busy machine cannot measure (it then awards provisional points)
and which takes over a minute. What lab 03's grade needs from a release (lab01-ref built from
the shipped lab-01 solution, the prebuilt lab03-ref) is checked instead."""
import fnmatch
import json
import os
import pathlib
import re
import shutil
import signal
import subprocess
import sys
import time

import pytest

from grading.releases import leaks
from labkit import registry
from labkit.harness import ROOT

FOLDERS = leaks.lab_folders(ROOT)
# A make that runs this test passes its command line on (MAKEFLAGS); the release and its
# grader must behave as when a person types the command.
CLEAN_ENV = {k: v for k, v in os.environ.items()
             if k not in ("MAKEFLAGS", "MFLAGS", "MAKELEVEL", "PYTHONPATH", "GRADING_SECRET")}


def make_release(lab, out):
    return subprocess.run(["make", "-s", "-C", str(ROOT), "release", f"LAB={lab}", f"OUT={out}"],
                          capture_output=True, text=True, timeout=900, env=CLEAN_ENV)


@pytest.fixture(scope="module")
def scratch(tmp_path_factory):
    return tmp_path_factory.mktemp("releases")


def built(scratch, lab):
    """Lab `lab`'s release in scratch/labNN, which the tests then use as students would, and
    an untouched copy in scratch/pristine-NN for the tests that read it."""
    out = scratch / f"lab{lab}"
    p = make_release(lab, out)
    assert p.returncode == 0, p.stdout + p.stderr
    shutil.copytree(out, scratch / f"pristine-{lab}", symlinks=True)
    return out


@pytest.fixture(scope="module")
def release01(scratch):
    # First: lab 01's release needs every reference binary, so lab 03's then only relinks.
    return built(scratch, "01")


@pytest.fixture(scope="module")
def release03(scratch, release01):
    return built(scratch, "03")


@pytest.fixture(scope="module")
def pristine01(release01):
    return release01.parent / "pristine-01"


@pytest.fixture(scope="module")
def pristine03(release03):
    return release03.parent / "pristine-03"


def region_lines(text: str) -> set[str]:
    """The stripped lines of a file's solution regions (between BEGIN and SKELETON)."""
    lines, inside = set(), False
    for line in text.splitlines():
        if leaks.skeletons.BEGIN.match(line):
            inside = True
        elif leaks.skeletons.SKELETON.match(line) or leaks.skeletons.END.match(line):
            inside = False
        elif inside:
            lines.add(line.strip())
    return lines


def solution_files(name: str) -> list[pathlib.Path]:
    return [p for p in sorted((ROOT / "labs" / name / "solution").rglob("*")) if p.is_file()] + \
           [ROOT / s for s in leaks.skeletons.SHARED_SOURCES.get(name, [])]


def distinctive_lines() -> dict[str, set[str]]:
    """Lab -> lines of its solution regions long enough to mean something and found in no file
    of the repository outside the solutions: such a line in a release is a solution's."""
    solutions = {p for name in FOLDERS.values() for p in solution_files(name)}
    elsewhere = set()
    for p in ROOT.rglob("*"):
        if p.is_file() and p not in solutions and ".git" not in p.parts and "build" not in p.parts:
            elsewhere.update(line.strip() for line in p.read_text(errors="replace").splitlines())
    return {lab: {line for p in solution_files(name) for line in region_lines(p.read_text())
                  if len(line) >= 20 and line not in elsewhere}
            for lab, name in FOLDERS.items()}


def text_of(release: pathlib.Path) -> str:
    return "\n".join(p.read_text(errors="replace") for p in sorted(release.rglob("*"))
                     if p.is_file() and leaks.REFERENCE_BIN not in p.parts)


@pytest.mark.parametrize("which", ["01", "03"])
def test_no_solution_source_of_the_lab_or_later(which, pristine01, pristine03):
    release = {"01": pristine01, "03": pristine03}[which]
    shipped = {line.strip() for line in text_of(release).splitlines()}
    for lab, lines in distinctive_lines().items():
        assert len(lines) >= 3, f"lab {lab}: too few distinctive solution lines to search for"
        found = lines & shipped
        if lab >= which:
            assert not found, \
                f"lab {which}'s release holds lab {lab}'s solution: {sorted(found)[:3]}"
        else:  # earlier labs' solutions ship: the search finds them, so it can find a leak
            assert found == lines, f"lab {which}'s release lacks lab {lab}'s solution"
    assert not leaks.leaks(release, which, FOLDERS)


# What a release of lab 01 ships of the GPU labs (their `ships` in labs/labs.toml), built
# where nvcc is.
GPU_SHIPS = [t for n in registry.gpu_labs() for t in registry.lab(n).ships]


def test_lab01_release_layout(pristine01):
    release01 = pristine01
    assert not any((release01 / "labs" / name / "solution").exists() for name in FOLDERS.values())
    assert all((release01 / "labs" / name / "skeleton").is_dir() for name in FOLDERS.values())
    # lab 01 writes common/core/path_steps.h's regions: the release has its skeleton form
    skeleton = (ROOT / "labs/01-serial/skeleton/path_steps.h").read_text()
    assert (release01 / "common/core/path_steps.h").read_text() == skeleton.split("\n", 1)[1]
    assert sorted(p.name for p in (release01 / "reference-bin").iterdir()) == sorted(
        [
            "lab01-ref",
            "lab02-ref",
            "lab02-ref-avx2",
            "lab02a-ref",
            "lab02-prims",
            "lab03-ref",
            "lab03-bench",
            "lab03-simd-ref",
            "lab04-ref",
            "lab04-simd-ref",
        ]
        + (GPU_SHIPS if shutil.which("nvcc") else [])
    )
    for gone in ("tests/grading", "labkit/skeletons.py", "grading/releases/release.py", "ref",
                 ".ci"):
        assert not (release01 / gone).exists(), gone
    assert not list(pristine01.parent.glob(".*partial*")), "a partial release was left behind"


def test_lab03_release_layout(pristine03):
    release03 = pristine03
    for lab, name in FOLDERS.items():
        assert (release03 / "labs" / name / "solution").is_dir() == (lab < "03"), name
    assert (release03 / "common/core/path_steps.h").read_bytes() == \
        (ROOT / "common/core/path_steps.h").read_bytes()
    assert not (release03 / "reference-bin" / "lab01-ref").exists()


def run_public_tests(release):
    return subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "tests"],
                          cwd=release, capture_output=True, text=True, timeout=300, env=CLEAN_ENV)


def test_lab01_release_grades_in_student_mode(release01):
    """`make grade LAB=01` there: the skeleton scores low, with the prebuilt lab01-ref; the
    same grader gives that reference full marks, so the low score is the skeleton's."""
    p = subprocess.run(["make", "-s", "grade", "LAB=01"], cwd=release01, capture_output=True,
                       text=True, timeout=600, env=CLEAN_ENV)
    assert p.returncode == 0, p.stdout + p.stderr
    assert json.loads((release01 / "results.json").read_text())["score"] <= 10, p.stdout
    assert (release01 / "lab01-ref").read_bytes() == \
        (release01 / "reference-bin" / "lab01-ref").read_bytes()
    p = subprocess.run([sys.executable, "-m", "grading.grade", "01", "--trusted", "--binary",
                        "lab01-ref", "--results", "reference.json"], cwd=release01,
                       capture_output=True, text=True, timeout=600, env=CLEAN_ENV)
    assert json.loads((release01 / "reference.json").read_text())["score"] == 100, p.stdout


def test_lab01_public_tests_pass(release01):
    p = run_public_tests(release01)
    assert p.returncode == 0 and " passed" in p.stdout, p.stdout + p.stderr


def test_lab03_release_builds_earlier_references_and_serves_its_own(release03):
    p = subprocess.run(["make", "-s", "lab01-ref", "lab03-ref", "lab03"], cwd=release03,
                       capture_output=True, text=True, timeout=600, env=CLEAN_ENV)
    assert p.returncode == 0, p.stdout + p.stderr
    assert (release03 / "lab03-ref").read_bytes() == \
        (release03 / "reference-bin" / "lab03-ref").read_bytes()
    for binary in ("lab01-ref", "lab03-ref", "lab03"):  # each renders, from the release's root
        r = subprocess.run([f"./{binary}", "--quiet", "--width", "4", "--height", "4", "--spp",
                            "1", "--json"], cwd=release03, capture_output=True, text=True)
        assert r.returncode == 0 and json.loads(r.stdout.splitlines()[-1])["width"] == 4, r.stderr
    # as students run them: the release's GNUmakefile runs its own tests, not the course's
    p = subprocess.run(["make", "test-labs"], cwd=release03, capture_output=True, text=True,
                       timeout=300, env=CLEAN_ENV)
    assert p.returncode == 0 and " passed" in p.stdout, p.stdout + p.stderr


def test_without_nvcc_the_gpu_references_are_left_out(tmp_path, release01):
    """Where the CUDA toolkit is missing, a release still comes, saying what it lacks."""
    path = os.pathsep.join(d for d in os.environ["PATH"].split(os.pathsep)
                           if not (pathlib.Path(d) / "nvcc").exists())
    p = subprocess.run([sys.executable, "-m", "grading.releases.release", "05",
                        str(tmp_path / "out")], cwd=ROOT, capture_output=True, text=True,
                       timeout=900, env={**CLEAN_ENV, "PATH": path})
    assert p.returncode == 0, p.stderr
    left_out = p.stderr.split("left out ", 1)[-1].split(" (", 1)[0].split(", ")
    assert left_out == GPU_SHIPS, p.stderr
    assert list((tmp_path / "out" / "reference-bin").iterdir()) == []


# ---- refusals: one line, exit status 2, nothing written ---------------------------------

def run_tool(*args, env=None):
    return subprocess.run([sys.executable, "-m", "grading.releases.release", *args], cwd=ROOT,
                          capture_output=True, text=True, timeout=900,
                          env={**CLEAN_ENV, **(env or {})})


def assert_refused(p, fragment, out):
    assert p.returncode == 2, p.stdout + p.stderr
    assert len(p.stderr.strip().splitlines()) == 1 and fragment in p.stderr, p.stderr
    assert not list(out.parent.glob(f".{out.name}.partial-*"))


@pytest.mark.parametrize("lab", ["08", "1", "abc", "00", ""])
def test_bad_lab(tmp_path, lab):
    out = tmp_path / "out"
    assert_refused(run_tool(lab, str(out)), "LAB must be one of", out)
    assert not out.exists()


def test_missing_arguments(tmp_path):
    assert_refused(run_tool("01"), "usage", tmp_path / "x")
    for args in (["OUT=x"], ["LAB=01"], ["LAB=01", "OUT="]):  # make's own message follows
        p = subprocess.run(["make", "-s", "-C", str(ROOT), "release", *args], capture_output=True,
                           text=True, env=CLEAN_ENV)
        assert p.returncode != 0 and p.stderr.startswith("release: needs LAB=NN and OUT=DIR"), \
            p.stderr


def test_refuses_a_non_empty_out(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    (out / "mine.txt").write_text("keep me")
    assert_refused(run_tool("01", str(out)), "is not empty", out)
    assert [p.name for p in out.iterdir()] == ["mine.txt"]
    (tmp_path / "file").write_text("")
    assert_refused(run_tool("01", str(tmp_path / "file")), "is not a folder", tmp_path / "file")


def test_stale_skeletons_refuse_the_release(tmp_path, monkeypatch):
    """A solution edited without `make skeletons`: its students would get the old skeleton."""
    from grading.releases import release
    generated = list(leaks.skeletons.generated_files())
    path, text = generated[0]
    monkeypatch.setattr(leaks.skeletons, "generated_files",
                        lambda: [(path, text + "// changed\n"), *generated[1:]])
    with pytest.raises(release.ReleaseError, match="skeletons out of date .*" + path.name):
        release.make_release("01", tmp_path / "out")
    assert list(tmp_path.iterdir()) == []


def test_a_leaked_secret_refuses_the_release(tmp_path, release01):
    """A secret that a shipped file holds (as if the instructor's GRADING_SECRET had been
    committed in one): the release is refused and nothing is left."""
    out = tmp_path / "out"
    p = run_tool("01", str(out), env={"GRADING_SECRET": "def hidden_scene(secret: str)"})
    assert_refused(p, "grading/checks/hidden.py: holds the hidden scene's secret", out)
    assert not out.exists()


def test_interrupted_release_leaves_nothing(tmp_path, release01):
    """SIGTERM as soon as the partial folder appears (the release then has about a second to
    go): nothing is left, or, had the signal come during the final rename, the whole release."""
    for attempt in range(3):
        out = tmp_path / f"out{attempt}"
        p = subprocess.Popen([sys.executable, "-m", "grading.releases.release", "01", str(out)],
                             cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                             env=CLEAN_ENV)
        deadline = time.monotonic() + 60
        while not list(tmp_path.glob(f".{out.name}.partial-*")) and time.monotonic() < deadline:
            time.sleep(0.001)
        p.send_signal(signal.SIGTERM)
        _, err = p.communicate(timeout=120)
        assert not list(tmp_path.glob(f".{out.name}.partial-*")), err
        if p.returncode == 0:
            assert (out / "GNUmakefile").is_file() and (out / ".git").is_dir()
        else:
            assert p.returncode == 130 and not out.exists(), err
            assert err.strip() == "error: release: interrupted; nothing written"


# ---- the leak check on planted leaks ----------------------------------------------------

PLANTS = {
    "a later lab's solution": ("labs/03-openmp/solution/render.cpp", None,
                               "labs/03-openmp/solution/"),
    "a solution region in a shared file": (
        "common/host/timer.h",
        "\n// BEGIN SOLUTION\nint x;\n// SKELETON\n//> int x;\n// END SOLUTION\n",
        "common/host/timer.h:"),
    "an instructor-only line": ("labs/01-serial/skeleton/render.cpp", "\n//! solution: x\n",
                                "labs/01-serial/skeleton/render.cpp:"),
    "the grader's own test": ("tests/grading/test_hostile.py", None, "never shipped"),
    "a test that is not public": ("tests/labs/test_extremes.py", None, "not a public test"),
    "a binary outside reference-bin": ("lab01-ref", None, "an executable outside"),
}


@pytest.mark.parametrize("plant", PLANTS)
def test_leak_check_finds_a_planted_leak(tmp_path, pristine01, plant):
    release = tmp_path / "release"
    shutil.copytree(pristine01, release, symlinks=True)
    path, appended, expected = PLANTS[plant]
    target = release / path
    target.parent.mkdir(parents=True, exist_ok=True)
    if appended is None:
        source = release / "reference-bin" / "lab01-ref" if path == "lab01-ref" else ROOT / path
        shutil.copy(source, target)
    else:
        target.write_text(target.read_text() + appended)
    problems = leaks.leaks(release, "01", FOLDERS)
    assert any(expected in line for line in problems), problems


GIT_PLANTS = {
    "an object no commit reaches": (["hash-object", "-w", "labs/03-openmp/solution/render.cpp"],
                                    "objects beyond the release's commit"),
    "a second commit": (["commit", "-q", "--allow-empty", "-m", "more"], "2 commits"),
}


@pytest.mark.parametrize("plant", GIT_PLANTS)
def test_leak_check_reads_the_releases_repository_through_git(tmp_path, pristine01, plant):
    """The release's .git is compressed, so its bytes are not searched (by chance they hold a
    marker now and then); what git holds must be the one commit of the files checked."""
    release = tmp_path / "release"
    shutil.copytree(pristine01, release, symlinks=True)
    args, expected = GIT_PLANTS[plant]
    if "hash-object" in args:
        args = [*args[:-1], str(ROOT / args[-1])]
    subprocess.run(["git", "-c", "user.name=x", "-c", "user.email=x@x.invalid", *args],
                   cwd=release, check=True)
    problems = leaks.leaks(release, "01", FOLDERS)
    assert any(expected in line for line in problems), problems


def test_leak_check_finds_the_hidden_scene(tmp_path, pristine01):
    """The secret's scene saved among the scenes leaks the secret as surely as the secret."""
    from grading.checks import hidden
    from labkit import scenes
    release = tmp_path / "release"
    shutil.copytree(pristine01, release, symlinks=True)
    secret = "0123456789abcdef0123456789abcdef"
    assert not leaks.leaks(release, "01", FOLDERS, secret)
    scenes.write_scene(release / "common" / "scenes" / "mine.json", hidden.hidden_scene(secret))
    assert leaks.leaks(release, "01", FOLDERS, secret) == \
        ["common/scenes/mine.json: is the hidden scene made from the secret"]


def test_lab_readmes_in_a_release_name_nothing_it_lacks():
    """A lab's README as a release ships it (its course-repository-only parts left out) names
    no test the release does not ship and no `make gpu-check`, which runs those tests."""
    from grading.releases import leaks, release
    for readme in sorted(ROOT.glob("labs/*/README.md")):
        text = release.for_students(readme.read_text())
        named = set(re.findall(r"tests/[\w/]+\.(?:py|cpp|cu)", text))
        absent = [t for t in named if not any(fnmatch.fnmatch(t, p) for p in leaks.PUBLIC_TESTS)]
        assert not absent and "gpu-check" not in text, (readme, absent)
    course = (ROOT / "labs/05-cuda-mega/README.md").read_text()
    assert "tests/labs/test_lab05.py" in course and "make gpu-check" in course
