"""Adding a lab touches only its folder, its handout, the registry and the README's table.

In a scratch copy of the repository (its tracked and not-ignored files, with lab 01's objects
and reference from build/ so that little is compiled again), lab 01's folder is copied as
labs/08-throwaway with its lab.mk renamed, a handout stub, a [[lab]] entry in labs/labs.toml
and a row in README.md's table. Then nothing else is edited, and lab 08 is: generated (`make
skeletons` writes its skeleton, `make check-skeletons` passes), built (`make lab08 lab08-ref`),
known to make and to every drift check, graded (the reference 100 on lab 01's rubric, the
skeleton less), handed in, released (its skeleton and prebuilt reference, no solution) and
ignored (`git status` shows no binary)."""
import json
import os
import pathlib
import shutil
import subprocess
import sys
import zipfile

import pytest

from labkit.registry import ROOT
from tests.tools import test_registry as drift

LAB, FOLDER = "08", "08-throwaway"
# What adding the lab may change, and nothing else.
ADDED = (f"labs/{FOLDER}/", f"handouts/{FOLDER}.md", "labs/labs.toml", "README.md")
ENTRY = f"""
[[lab]]
number = "{LAB}"
folder = "{FOLDER}"
kind = "cpu"
student = ["lab{LAB}"]
reference = ["lab{LAB}-ref"]
extras = []
ships = ["lab{LAB}-ref"]
handin = ["render.cpp"]
handin_kib = 64
shared = []
rubric = "serial"
try = "./lab{LAB} --width 128 --height 128 --spp 16 --out quick.ppm"
"""
LAB_MK = f"""# Lab {LAB}: a throwaway copy of lab 01: ./lab{LAB} (skeleton) and ./lab{LAB}-ref.
$(eval $(call cpu_lab,lab{LAB},{FOLDER},))
VARIANT_DRIVER_{FOLDER} := $(COMMON_OBJ)
"""
GIT_ENV = {"GIT_AUTHOR_NAME": "t", "GIT_AUTHOR_EMAIL": "t@t.invalid",
           "GIT_COMMITTER_NAME": "t", "GIT_COMMITTER_EMAIL": "t@t.invalid"}


def run(root, *args, check=True, timeout=600):
    env = {k: v for k, v in os.environ.items() if k not in ("MAKEFLAGS", "MFLAGS", "MAKELEVEL")}
    p = subprocess.run(list(args), cwd=root, capture_output=True, text=True, timeout=timeout,
                       env={**env, **GIT_ENV})
    if check:
        assert p.returncode == 0, f"{' '.join(args)}: {(p.stdout + p.stderr)[-3000:]}"
    return p


def scratch_copy(dest: pathlib.Path) -> pathlib.Path:
    """The repository's files as a checkout holds them, committed, with lab 01's objects and
    reference copied with their times (make sees them up to date)."""
    files = subprocess.run(["git", "-C", str(ROOT), "ls-files", "-co", "--exclude-standard",
                            "-z"], capture_output=True, check=True).stdout.decode().split("\0")
    for f in (f for f in files if f and (ROOT / f).is_file()):
        (dest / f).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(ROOT / f, dest / f)
    for folder in ("build/common", "build/labs/01-serial"):
        if (ROOT / folder).is_dir():
            shutil.copytree(ROOT / folder, dest / folder)
    shutil.copy2(ROOT / "lab01-ref", dest / "lab01-ref")
    run(dest, "git", "init", "-q")
    run(dest, "git", "add", "-A")
    run(dest, "git", "commit", "-q", "--no-verify", "--no-gpg-sign", "-m", "scratch copy")
    return dest


def add_lab(root: pathlib.Path) -> None:
    """Everything a new lab needs: its folder, handout, registry entry and README row."""
    folder = root / "labs" / FOLDER
    shutil.copytree(root / "labs" / "01-serial", folder, ignore=shutil.ignore_patterns("skeleton"))
    (folder / "lab.mk").write_text(LAB_MK)
    (root / "handouts" / f"{FOLDER}.md").write_text(
        f"# Lab {LAB}: a throwaway lab\n\nLab 01 again, to show how a lab is added.\n\n"
        f"## Hand in\n\n`make handin` writes `handin-lab{LAB}.zip` with `render.cpp`.\n")
    with open(root / "labs" / "labs.toml", "a") as registry:
        registry.write(ENTRY)
    readme = root / "README.md"
    last = "| [07-soa](labs/07-soa/README.md) |"
    lines = readme.read_text().splitlines(keepends=True)
    at = next(i for i, line in enumerate(lines) if line.startswith(last)) + 1
    lines.insert(at, f"| [{FOLDER}](labs/{FOLDER}/README.md) | lab 01 again | throwaway |\n")
    readme.write_text("".join(lines))


@pytest.fixture(scope="module")
def repo(tmp_path_factory, lab01_ref):
    """The scratch copy with lab 08 added, its skeleton generated and its binaries built."""
    root = scratch_copy(tmp_path_factory.mktemp("new-lab") / "repo")
    add_lab(root)
    changed = run(root, "git", "status", "--porcelain", "--untracked-files=all").stdout
    run(root, "make", "-s", "skeletons")
    run(root, "make", "-s", "-j2", f"lab{LAB}", f"lab{LAB}-ref")
    return root, changed


def test_adding_the_lab_touched_only_its_own_files(repo):
    _, changed = repo
    paths = [line[3:] for line in changed.splitlines()]
    assert f"labs/{FOLDER}/lab.mk" in paths and "labs/labs.toml" in paths
    assert all(p.startswith(ADDED) for p in paths), paths


def test_its_skeleton_is_generated_from_its_solution(repo):
    root, _ = repo
    skeleton = root / "labs" / FOLDER / "skeleton" / "render.cpp"
    solution = root / "labs" / FOLDER / "solution" / "render.cpp"
    assert skeleton.read_text().startswith(f"// Lab {LAB}: your copy")
    assert "BEGIN SOLUTION" in solution.read_text() and "SOLUTION" not in skeleton.read_text()
    run(root, "make", "-s", "check-skeletons")


def test_make_and_every_drift_check_know_it(repo):
    """The drift checks pass on the copy, and so does the drift test itself, unedited."""
    root, _ = repo
    assert f"lab{LAB}-ref" in run(root, "make", "-s", "help").stdout
    assert run(root, sys.executable, "-m", "labkit.registry", "folder", LAB).stdout == f"{FOLDER}\n"
    assert drift.unregistered_folders(root) == []
    assert drift.incomplete_labs(root) == []
    assert drift.unknown_targets(root) == []
    assert drift.stale_generated(root) == []
    assert drift.not_ignored(root) == []
    run(root, sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider",
        "tests/tools/test_registry.py")


def test_it_is_graded_on_its_rubric(repo, tmp_path):
    """Lab 01's rubric, named in the registry: the reference earns every point, the skeleton
    (half the picture) does not."""
    root, _ = repo
    scores = {}
    for binary in (f"lab{LAB}-ref", f"lab{LAB}"):
        results = tmp_path / f"{binary}.json"
        run(root, sys.executable, "-m", "grading.grade", LAB, "--binary", f"./{binary}",
            "--trusted", "--results", str(results), "--heatmaps", str(tmp_path / binary))
        scores[binary] = json.loads(results.read_text())["score"]
    assert scores[f"lab{LAB}-ref"] == 100 and scores[f"lab{LAB}"] < 60, scores


def test_it_is_handed_in(repo, tmp_path):
    root, _ = repo
    out = tmp_path / "handin.zip"
    run(root, sys.executable, "-m", "grading.releases.handin", LAB, "--out", str(out))
    with zipfile.ZipFile(out) as z:
        assert z.namelist() == ["render.cpp"]


def test_it_is_released(repo, tmp_path):
    """Lab 08's release: its skeleton and its prebuilt reference, no solution of it; the
    earlier labs' solutions; a README that says how to build and try it."""
    root, _ = repo
    out = tmp_path / "release"
    run(root, "make", "-s", "release", f"LAB={LAB}", f"OUT={out}")
    assert (out / "labs" / FOLDER / "skeleton" / "render.cpp").is_file()
    assert not (out / "labs" / FOLDER / "solution").exists()
    assert (out / "labs" / "07-soa" / "solution").is_dir()
    assert (out / "reference-bin" / f"lab{LAB}-ref").is_file()
    assert (out / "labkit" / "registry.py").is_file()
    readme = (out / "README.md").read_text()
    assert f"make lab{LAB}" in readme and f"./lab{LAB} --width 128" in readme


def test_its_binaries_are_ignored(repo):
    root, _ = repo
    for binary in (f"lab{LAB}", f"lab{LAB}-ref"):
        assert (root / binary).is_file()
    status = run(root, "git", "status", "--porcelain", "--untracked-files=all").stdout
    paths = [line[3:] for line in status.splitlines()]
    assert all(p.startswith(ADDED) for p in paths), paths
