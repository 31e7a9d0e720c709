"""The lab registry (labs/labs.toml, read through labkit/registry.py) against the tree: every
lab folder is registered and every registered lab is complete, every registered make target
exists and every binary make builds is registered, the generated make fragment and the
.gitignore are current, and each reader of the registry agrees with it. A broken registry is
one error line, in Python, on the command line and in make.

The checks take the repository's root as an argument, so tests/tools/test_new_lab.py runs
them on a copy with a lab added, and the tests below show each of them failing on a tree that
is wrong."""
import pathlib
import re
import shutil
import subprocess
import sys

import pytest

from grading import grade
from grading.releases import handin, leaks, reference_bins, release
from labkit import gpu, registry

ROOT = registry.ROOT
LAB_FOLDER = re.compile(r"^\d\d-")


def labs_of(root: pathlib.Path) -> tuple[registry.Lab, ...]:
    return registry.parse((root / "labs" / "labs.toml").read_text())


def unregistered_folders(root: pathlib.Path) -> list[str]:
    """labs/NN-* folders that labs.toml does not declare."""
    declared = {lab.folder for lab in labs_of(root)}
    return sorted(p.name for p in (root / "labs").iterdir()
                  if p.is_dir() and LAB_FOLDER.match(p.name) and p.name not in declared)


def incomplete_labs(root: pathlib.Path) -> list[str]:
    """What each registered lab lacks: its folder's parts, its handout, its row in the
    README's table, a shared file; and a hand-in that is not exactly its skeleton's files."""
    problems = []
    readme = (root / "README.md").read_text()
    for lab in labs_of(root):
        folder = root / "labs" / lab.folder
        for part in ("lab.mk", "README.md", "solution", "skeleton"):
            if not (folder / part).exists():
                problems.append(f"labs/{lab.folder}/{part} is missing")
        if not (root / "handouts" / f"{lab.folder}.md").is_file():
            problems.append(f"handouts/{lab.folder}.md is missing")
        if f"| [{lab.folder}](labs/{lab.folder}/README.md) |" not in readme:
            problems.append(f"README.md's table has no row for {lab.folder}")
        problems += [f"{lab.folder}: shared file {s} is missing" for s in lab.shared
                     if not (root / s).is_file()]
        skeleton = folder / "skeleton"
        files = sorted(p.relative_to(skeleton).as_posix() for p in skeleton.rglob("*")
                       if p.is_file()) if skeleton.is_dir() else []
        if sorted(lab.handin) != files:
            problems.append(f"{lab.folder}: handin {sorted(lab.handin)} is not its "
                            f"skeleton's files {files}")
    return problems


def make_targets(root: pathlib.Path) -> set[str]:
    """Every target make knows in `root` (its database, nothing built)."""
    p = subprocess.run(["make", "-pn", "-C", str(root), "help"], capture_output=True, text=True,
                       check=True)
    return {m.group(1) for m in re.finditer(r"^([A-Za-z0-9_.+/-]+):", p.stdout, re.M)}


def make_variable(root: pathlib.Path, name: str, *settings: str) -> list[str]:
    rule = f"print-registry-var: ; @echo $({name})"
    p = subprocess.run(["make", "-s", "-C", str(root), *settings, f"--eval={rule}",
                        "print-registry-var"], capture_output=True, text=True, check=True)
    return p.stdout.split()


def cuda_disagreements(root: pathlib.Path) -> list[str]:
    """Where cuda.mk's view of the CUDA labs (cuda_lab's calls in their lab.mk, read as make
    reads them where nvcc is: HAVE_NVCC set) is not the registry's: the GPU labs, and the
    files their students write that stand in for shared ones (`shared`)."""
    gpu_labs = [lab for lab in labs_of(root) if lab.gpu]
    problems = []
    if make_variable(root, "CUDA_LAB_FOLDERS", "HAVE_NVCC=yes") != [lab.folder for lab in gpu_labs]:
        problems.append("cuda_lab's labs are not the registry's GPU labs")
    for lab in gpu_labs:
        written = make_variable(root, f"CUDA_STUDENT_FILES_{lab.folder}", "HAVE_NVCC=yes")
        if sorted(written) != sorted(pathlib.PurePath(s).name for s in lab.shared):
            problems.append(f"{lab.folder}: cuda_lab's student files {written} are not its "
                            f"shared files {list(lab.shared)}")
    return problems


def unknown_targets(root: pathlib.Path) -> list[str]:
    """Registered targets make does not know (make's list of lab binaries is the registry's,
    REGISTERED_TARGETS)."""
    declared = [t for lab in labs_of(root) for t in lab.targets]
    known = make_targets(root)
    return [f"{t}: registered, not a make target" for t in declared if t not in known]


def stale_generated(root: pathlib.Path) -> list[str]:
    """The generated make fragment differs from the registry, or make's view of it does."""
    problems = []
    labs = labs_of(root)
    if make_variable(root, "LABS") != [lab.number for lab in labs]:
        problems.append("make's LABS is not the registry's")
    if make_variable(root, "GPU_LABS") != [lab.number for lab in labs if lab.gpu]:
        problems.append("make's GPU_LABS is not the registry's")
    p = subprocess.run([sys.executable, "-m", "labkit.registry", "make"], cwd=root,
                       capture_output=True, text=True, check=True)
    fragment = root / "build" / "labs.mk"
    if not fragment.is_file() or fragment.read_text() != p.stdout:
        problems.append("build/labs.mk is not what the registry writes")
    return problems


def not_ignored(root: pathlib.Path) -> list[str]:
    """Registered binaries and hand-in zips that git would not ignore, and tracked files that
    .gitignore would hide."""
    names = [t for lab in labs_of(root) for t in lab.targets]
    names += [f"handin-lab{lab.number}.zip" for lab in labs_of(root)]
    p = subprocess.run(["git", "-C", str(root), "check-ignore", "--no-index", "--stdin"],
                       input="\n".join(names) + "\n", capture_output=True, text=True)
    ignored = set(p.stdout.split())
    hidden = subprocess.run(["git", "-C", str(root), "ls-files", "-ci", "--exclude-standard"],
                            capture_output=True, text=True, check=True).stdout.split()
    return ([f"{n}: not ignored" for n in names if n not in ignored]
            + [f"{f}: tracked, yet ignored" for f in hidden])


# ---- the repository -------------------------------------------------------------------------

def test_every_lab_folder_is_registered():
    assert unregistered_folders(ROOT) == []
    assert [lab.folder for lab in registry.labs()] == sorted(
        p.name for p in (ROOT / "labs").iterdir() if p.is_dir() and LAB_FOLDER.match(p.name))


def test_every_registered_lab_is_complete():
    assert incomplete_labs(ROOT) == []


def test_every_registered_target_is_a_make_target():
    assert unknown_targets(ROOT) == []


def test_the_cuda_rules_agree_with_the_registry():
    assert cuda_disagreements(ROOT) == []


def test_the_generated_pieces_are_current():
    assert stale_generated(ROOT) == []
    assert not_ignored(ROOT) == []


def test_the_readers_agree_with_the_registry():
    """Each reader's view is the registry's (a lab added later included: nothing here names
    all the labs), and the course's labs are in it as the course has them."""
    numbers = list(registry.numbers())
    assert ["01", "02", "03", "04", "05", "06", "07"] == numbers[:7]
    assert sorted(grade.RUBRICS) == numbers
    assert {"05", "06", "07"} <= gpu.GPU_LABS == set(registry.gpu_labs())
    assert handin.LAB_FOLDERS == registry.folders() == leaks.lab_folders(ROOT)
    assert reference_bins.REFERENCES == {lab.number: list(lab.ships) for lab in registry.labs()}
    assert leaks.skeletons.SHARED_SOURCES == registry.shared_sources()
    assert registry.owner("lab02a-ref").number == "02"
    # The rubric a lab names is the one it is graded on: lab 07's weighs the pool's layout.
    assert any(i.id == "structure-of-arrays" for i in grade.RUBRICS["07"])
    assert not any(i.id == "structure-of-arrays" for i in grade.RUBRICS["06"])
    assert grade.GPU_TIMED_SPP.keys() == gpu.GPU_LABS
    assert {"05": 10496, "06": 2816, "07": 3072}.items() <= grade.GPU_TIMED_SPP.items()
    readme = release.student_readme("02", registry.folders(), ["lab02-ref"])
    assert "make lab02a lab02" in readme and registry.lab("02").try_command in readme


def test_the_command_line_answers_for_shell_and_make():
    def ask(*args):
        return subprocess.run([sys.executable, "-m", "labkit.registry", *args], cwd=ROOT,
                              capture_output=True, text=True)
    assert ask("gpu-labs").stdout.split() == list(registry.gpu_labs())
    assert ask("folder", "04").stdout == "04-mpi\n"
    assert ask("targets", "07").stdout.split() == ["lab07", "lab07-ref", "lab07-bench"]
    for bad in (["folder", "99"], ["folder"], ["nonsense"], []):
        p = ask(*bad)
        assert p.returncode == 2 and p.stdout == "", bad
        assert len(p.stderr.splitlines()) == 1 and p.stderr.startswith("error: registry: "), bad


# ---- a registry or a tree that is wrong --------------------------------------------------

TEXT = (ROOT / "labs" / "labs.toml").read_text()


def first_entry_with(old: str, new: str) -> str:
    assert old in TEXT
    return TEXT.replace(old, new, 1)


@pytest.mark.parametrize("text, fragment", [
    (TEXT + TEXT[TEXT.index("\n[[lab]]"):TEXT.index("\n[[lab]]", TEXT.index("\n[[lab]]") + 1)],
     "declared once"),
    (first_entry_with('kind = "cpu"', 'kind = "fpga"'), "kind must be one of"),
    (first_entry_with('reference = ["lab01-ref"]', 'reference = ["lab02-ref"]'), "lab02-ref"),
    (first_entry_with('student = ["lab01"]', 'student = ["lab01-mine"]'), "lab01"),
    (first_entry_with('ships = ["lab01-ref"]', 'ships = ["lab01"]'), "ships only"),
    (first_entry_with('rubric = "serial"', 'rubric = "gpu"'), "gpu rubric"),
    (first_entry_with('folder = "01-serial"', 'folder = "1-serial"'), "two digits"),
    (first_entry_with('handin = ["path_steps.h", "render.cpp"]\n', ""), "needs handin"),
    (first_entry_with('number = "01"', 'number = "01"\ncolour = "red"'), "unknown field"),
    (first_entry_with("timed_spp = 10496\n", ""), "timed_spp"),
    (first_entry_with("speed_bar = 0.56", "speed_bar = 1.5"), "speed_bar"),
    (first_entry_with('number = "01"', 'number = "01"\nspeed_bar = 0.5'), "speed_bar"),
    ("[[lab]\n", "not TOML"),
    ("", "[[lab]] tables"),
])
@pytest.mark.parametrize("reader", ["tomllib", "subset"])
def test_a_broken_registry_is_one_clear_error(text, fragment, reader, monkeypatch):
    if reader == "subset":  # what a Python without tomllib reads (3.10)
        monkeypatch.setattr(registry, "tomllib", None)
    with pytest.raises(registry.RegistryError) as e:
        registry.parse(text)
    assert fragment in str(e.value) and "\n" not in str(e.value)


def test_without_tomllib_the_registry_reads_the_same():
    import tomllib
    assert registry.loads_subset(TEXT) == tomllib.loads(TEXT)
    assert registry.loads_subset('a = 3  # c\n[[lab]]\nb = "x # y"\nc = [\n  "d",\n]\n') == \
        {"a": 3, "lab": [{"b": "x # y", "c": ["d"]}]}
    for bad in ("[[lab]\n", 'x = ["a",\n', "a = 1\na = 2\n", "x = true\n", "x = \n"):
        with pytest.raises(ValueError):
            registry.loads_subset(bad)


def test_each_check_fails_on_a_tree_that_is_wrong(tmp_path):
    """The checks above can fail: an unregistered folder, a registered lab without its
    handout, README row or skeleton, a registered target make does not know, a binary outside
    .gitignore's patterns."""
    root = tmp_path / "repo"
    for rel in ("labs/labs.toml", "README.md", ".gitignore"):
        (root / rel).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy(ROOT / rel, root / rel)
    (root / "labs" / "09-stray").mkdir()
    assert unregistered_folders(root) == ["09-stray"]
    problems = incomplete_labs(root)
    assert any("handouts/01-serial.md is missing" in p for p in problems)
    assert any("labs/05-cuda-mega/skeleton is missing" in p for p in problems)
    (root / "README.md").write_text("no table\n")
    assert any("no row for 03-openmp" in p for p in incomplete_labs(root))

    subprocess.run(["git", "init", "-q", str(root)], check=True)
    (root / ".gitignore").write_text("/lab0[1-7]\n")
    assert "lab02-ref: not ignored" in not_ignored(root)


def test_make_stops_on_a_broken_registry_with_one_line(tmp_path):
    root = tmp_path / "repo"
    for rel in ("Makefile", "cuda.mk", "grading/grading.mk", "labkit/__init__.py",
                "labkit/registry.py", "labs/labs.toml"):
        (root / rel).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy(ROOT / rel, root / rel)
    (root / "labs" / "labs.toml").write_text(first_entry_with('kind = "cpu"', 'kind = "fpga"'))
    p = subprocess.run(["make", "-s", "-C", str(root), "help"], capture_output=True, text=True)
    assert p.returncode != 0 and p.stdout == ""
    # After the registry's line, only make's own: the fragment it could not write.
    errors = [line for line in p.stderr.splitlines() if not line.startswith(("make", "Makefile"))]
    assert len(errors) == 1 and "kind must be one of" in errors[0], p.stderr
    assert not (root / "build" / "labs.mk").exists()
    # Any program that reads the registry says the same, in one line.
    p = subprocess.run([sys.executable, "-m", "labkit.registry", "numbers"], cwd=root,
                       capture_output=True, text=True)
    assert p.returncode == 2 and p.stdout == "" and p.stderr.count("\n") == 1
    assert p.stderr.startswith("error: registry: ") and "kind must be one of" in p.stderr


def test_the_cuda_check_fails_where_a_lab_mk_disagrees(tmp_path):
    root = tmp_path / "repo"
    rels = ["Makefile", "cuda.mk", "grading/grading.mk", "labkit/__init__.py",
            "labkit/registry.py", "labs/labs.toml",
            *(f"labs/{lab.folder}/lab.mk" for lab in registry.labs())]
    for rel in rels:
        (root / rel).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy(ROOT / rel, root / rel)
    assert cuda_disagreements(root) == []
    toml = root / "labs" / "labs.toml"
    toml.write_text(toml.read_text().replace(
        'shared = ["common/wavefront/queue_reserve.cuh", "common/wavefront/stage_loop.cuh"]',
        'shared = ["common/wavefront/queue_reserve.cuh"]'))
    assert [p.split(":")[0] for p in cuda_disagreements(root)] == ["06-cuda-split"]
