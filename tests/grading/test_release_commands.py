"""Every command a student is told to run works in a fresh release (`make release LAB=NN`) of
each CPU lab: the release's README and that lab's handout are read, their shell commands
extracted, and each run in the release, after the lab's solution has been copied over the
skeleton (a student who has finished). Then the release's `make render`, `make test`,
`make handin` and `make grade` (which defaults to its lab) pass there.

What counts as a command (`commands`): every ```sh block of the two files, run as one bash
script with `set -e`, and every inline code span that starts with `make ` or `python3 `.
Nothing is dropped silently: each command is either run as written, run at a reduced size
(REDUCED: the documented size flags below, for full-size renders and benchmarks that take
minutes), or not run for a reason named in NOT_HERE (several hosts, root); the test prints
every command and what it did with it, and fails on an entry of REDUCED or NOT_HERE that no
document names any more.

    RT_RELEASE_LABS=01,03  only those labs' releases (default: 01-04)

The GPU labs' releases (05-07, RT_RELEASE_GPU_LABS) are checked without a GPU: every command
their README and handout give must exist there (`missing_from`: a make target make knows,
a binary make can build, a Python module or file that ships), whether or not it can run on
this machine.
"""
from __future__ import annotations

import os
import pathlib
import re
import shlex
import shutil
import subprocess
import time

import pytest

from grading.releases import leaks
from labkit import registry
from labkit.harness import ROOT

LABS = os.environ.get("RT_RELEASE_LABS", "01,02,03,04").split(",")
GPU_LABS = [n for n in os.environ.get("RT_RELEASE_GPU_LABS", "05,06,07").split(",") if n]
FOLDERS = leaks.lab_folders(ROOT)
CLEAN_ENV = {k: v for k, v in os.environ.items()
             if k not in ("MAKEFLAGS", "MFLAGS", "MAKELEVEL", "PYTHONPATH", "GRADING_SECRET")}
if os.geteuid() == 0:  # OpenMPI refuses root unless told
    CLEAN_ENV.update(OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")

# The size flags that stand in for a full-size run. A lab binary's command line (`./labNN`,
# also under mpirun or with environment variables) that does not set both --width and --spp
# renders the full baseline for a minute or more: it runs with SMALL appended (the last of a
# repeated flag counts). Tools take their own options (REDUCED).
SMALL = "--width 48 --height 48 --spp 4"
LAB_BINARY = re.compile(r"^(\w+=\S+ )*(mpirun (-\S+ (\S+ )?)*)?\./lab0\d\S*( |$)")
QUICK_OPENMP = "--repeat 1 --width 48 --height 48 --spp 2 --threads 1,2"
QUICK_MPI = "--width 48 --height 48 --spp 4 --repeat 1 --no-capacity"
REDUCED = {
    "make bench-serial": "make bench-serial BENCH_ARGS='--repeat 1 --small'",
    "make tradeoff": "make tradeoff QUICK=1 PLOTS=0",
    "python3 -m tools.bench.openmp": f"python3 -m tools.bench.openmp {QUICK_OPENMP}",
    "python3 -m tools.bench.openmp --min-capacity 1.8":
        f"python3 -m tools.bench.openmp {QUICK_OPENMP}",
    "python3 -m tools.bench.openmp --mine": f"python3 -m tools.bench.openmp --mine {QUICK_OPENMP}",
    "python3 -m tools.bench.openmp --mine --no-rng":
        f"python3 -m tools.bench.openmp --mine --no-rng {QUICK_OPENMP}",
    "python3 -m tools.bench.simd": "python3 -m tools.bench.simd --size 32 --spp 8 --repeat 1",
    "python3 -m tools.bench.simd --full --only lab02-ref-avx2":
        "python3 -m tools.bench.simd --size 32 --spp 8 --repeat 1 --only lab02-ref-avx2",
    "python3 -m tools.bench.simd --cpu-time":
        "python3 -m tools.bench.simd --cpu-time --size 32 --spp 8 --repeat 1",
    "python3 -m tools.bench.simd --packets":
        "python3 -m tools.bench.simd --packets --size 32 --spp 8 --repeat 1",
    "python3 -m tools.bench.simd --full --only lab02":
        "python3 -m tools.bench.simd --size 32 --spp 8 --repeat 1 --only lab02",
    "python3 -m tools.bench.simd --only lab02 --only lab02a":
        "python3 -m tools.bench.simd --size 32 --spp 8 --repeat 1 --only lab02 --only lab02a",
    "python3 -m tools.bench.mpi table": f"python3 -m tools.bench.mpi table {QUICK_MPI} "
                                       f"--ranks 1,2 --hybrid 1x2",
    "python3 -m tools.bench.mpi table --repeat 5 --ranks 2 --hybrid 1x2":
        f"python3 -m tools.bench.mpi table {QUICK_MPI} --ranks 2 --hybrid 1x2",
    "python3 -m tools.bench.mpi table --ranks 1,2,4,8,16 --hybrid 1x16,2x8,4x4,8x2":
        f"python3 -m tools.bench.mpi table {QUICK_MPI} --ranks 1,2,4 --hybrid 1x2,2x1",
    "python3 -m tools.bench.mpi rows --bands 8 --width 600 --height 600 --spp 32":
        "python3 -m tools.bench.mpi rows --bands 4 --width 48 --height 48 --spp 4 --repeat 1",
    # run by the tests below, once each
    "make grade": None, "make grade LAB=01": None, "make grade LAB=02": None,
    "make grade LAB=03": None, "make grade LAB=04": None, "make test": None, "make render": None,
    # (in labs 03 and 04 with GRADE_ARGS='--budget-seconds 0': see GRADE_BUDGET)
    "make handin": None,
}
# Commands that cannot run on one test machine, and why (a block by its first line).
NOT_HERE = {
    "mpirun --hostfile hosts -np 16 ./lab04-ref --out cornell.ppm": "needs several hosts",
    "for h in node2 node3; do ssh $h mkdir -p $PWD/common/scenes; \\": "needs several hosts",
    "sudo labs/04-mpi/netns_hosts.sh up rt":
        "creates network namespaces: root, and a test of its own "
        "(tests/labs/test_lab04.py::test_two_hosts)",
    "mpirun -np 2 --map-by slot:PE=4 ./lab04 --threads 4": "needs 8 cores",
}
# Commands that must fail, with this exit status (showing what an error looks like).
EXPECTED_STATUS = {"RT_FORCE_NO_AVX2=1 ./lab02-ref": 2}


def bare(line: str) -> str:
    """A command without its trailing comment."""
    return re.sub(r"\s+#.*$", "", line.strip())


def blocks(text: str) -> list[str]:
    """The ```sh blocks of a Markdown text."""
    return [m.group(1).strip() for m in re.finditer(r"^```sh\n(.*?)^```", text, re.S | re.M)]


def inline(text: str) -> list[str]:
    """Inline code spans that are whole commands: `make ...` or `python3 ...` (not in HTML
    comments, where the generated tables name their generator)."""
    outside = re.sub(r"^```.*?^```|<!--.*?-->", "", text, flags=re.S | re.M)
    return [c for c in re.findall(r"`([^`\n]+)`", outside)
            if c.startswith(("make ", "python3 "))]


def commands(release: pathlib.Path, lab: str) -> list[str]:
    found = []
    for doc in (release / "README.md", release / "handouts" / f"{FOLDERS[lab]}.md"):
        text = doc.read_text()
        for block in blocks(text):
            lines = [line for line in block.splitlines()
                     if line.strip() and not line.lstrip().startswith("#")]
            # A block of one-line commands runs line by line (each is named on its own);
            # a block with a loop or continuation lines runs whole.
            if any(bare(line).endswith(("\\", "do", "then")) for line in lines):
                found.append("\n".join(lines))
            else:
                found.extend(bare(line) for line in lines)
        found.extend(inline(text))
    return list(dict.fromkeys(found))


def planned(command: str) -> tuple[str | None, str]:
    """(what to run, what the list says about it)."""
    first = command.splitlines()[0].strip()
    if first in NOT_HERE or bare(first) in NOT_HERE:
        return None, f"not run ({NOT_HERE.get(first) or NOT_HERE[bare(first)]})"
    if command in REDUCED:
        actual = REDUCED[command]
        return actual, "run by another test" if actual is None else f"reduced to `{actual}`"
    if "\n" not in command and LAB_BINARY.match(command) and not re.search(r"[;&|]", command) \
            and not ("--width" in command and "--spp" in command):
        return f"{command} {SMALL}", f"run with {SMALL}"
    if is_build(command):
        return f"make -j{os.cpu_count() or 1} {command[5:]}", "built on every core"
    return command, "run as written"


def is_build(command: str) -> bool:
    """`make` of lab binaries alone (and variables): what -jN changes only the speed of."""
    words = shlex.split(command) if "\n" not in command else []
    targets = set(registry.all_targets())
    return (len(words) > 1 and words[0] == "make" and not any(w.startswith("-") for w in words)
            and all(w in targets or re.fullmatch(r"[A-Z_]+=.*", w) for w in words[1:]))


def finish_lab(release: pathlib.Path, lab: str) -> None:
    """Copy lab `lab`'s solution over its skeleton, as a student who finished would have it."""
    name = FOLDERS[lab]
    skeleton = release / "labs" / name / "skeleton"
    for src in (ROOT / "labs" / name / "solution").rglob("*"):
        if src.is_file():
            dst = skeleton / src.relative_to(ROOT / "labs" / name / "solution")
            dst.parent.mkdir(parents=True, exist_ok=True)
            shutil.copy(src, dst)
    for shared in leaks.skeletons.SHARED_SOURCES.get(name, []):
        shutil.copy(ROOT / shared, skeleton / pathlib.Path(shared).name)


def released(lab: str, tmp_path_factory, timeout: int) -> pathlib.Path:
    """A fresh `make release LAB=lab`, as course staff make it."""
    out = tmp_path_factory.mktemp(f"release{lab}") / f"lab{lab}"
    p = subprocess.run(["make", "-s", "-C", str(ROOT), "release", f"LAB={lab}", f"OUT={out}"],
                       capture_output=True, text=True, timeout=timeout, env=CLEAN_ENV)
    assert p.returncode == 0, p.stdout + p.stderr
    return out


@pytest.fixture(scope="module", params=LABS)
def finished(request, tmp_path_factory):
    lab = request.param
    out = released(lab, tmp_path_factory, timeout=1800)
    finish_lab(out, lab)
    return lab, out


# The checks' budget of the release's `make grade` (its build is not counted): labs 03 and 04
# spend minutes measuring their speed on a busy machine, so there the grade builds ./labNN of
# the release's lab and stops before its checks; labs 01 and 02 are graded whole.
GRADE_BUDGET = {"03": 0, "04": 0}


def run(release, command, timeout=600):
    return subprocess.run(["bash", "-c", f"set -eo pipefail\n{command}"], cwd=release,
                          capture_output=True, text=True, timeout=timeout, env=CLEAN_ENV)


def test_every_command_of_readme_and_handout_runs(finished):
    lab, release = finished
    found = commands(release, lab)
    assert len(found) >= 5, found
    done, failed = [], []
    for command in found:
        actual, how = planned(command)
        if actual is None:
            done.append(f"{how}: {command}")
            continue
        start = time.monotonic()
        p = run(release, actual)
        expected = EXPECTED_STATUS.get(command, 0)
        done.append(f"{how}, exit {p.returncode}, {time.monotonic() - start:.0f} s: {command}")
        if p.returncode != expected:
            failed.append(f"{command}\n  ({how}) exit {p.returncode}, expected {expected}: "
                          f"{(p.stdout + p.stderr).strip()[-1500:]}")
    print(f"lab {lab} release, {len(found)} commands:\n  " + "\n  ".join(done))
    assert not failed, "\n".join(failed)


def test_no_stale_allowlist_entry():
    """Every entry of REDUCED and NOT_HERE is a command some shipped document names."""
    text = "\n".join(p.read_text() for p in (ROOT / "handouts").glob("0*.md"))
    text += "\n".join(p.read_text() for p in (ROOT / "labs").glob("0*/README.md"))
    text += "".join(f"\n{registry.lab(lab).try_command}" for lab in FOLDERS)
    text += "\nmake grade\nmake test\n"
    stale = [c for c in [*REDUCED, *NOT_HERE, *EXPECTED_STATUS] if c not in text]
    assert not stale, stale


def test_release_is_a_repository_with_one_commit(finished):
    lab, release = finished
    log = subprocess.run(["git", "log", "--format=%s"], cwd=release, capture_output=True,
                         text=True, check=True).stdout.splitlines()
    assert log == [f"Lab {lab} release"]
    shown = subprocess.run(["git", "show", "HEAD:README.md"], cwd=release, capture_output=True,
                           text=True, check=True).stdout
    assert shown.startswith(f"# Lab {lab}") and "make handin" in shown


def test_unit_tests_build_against_the_students_copies(finished):
    """In labs whose students write a shared file (lab 01's path_steps.h), the unit tests
    compile with the student's folder first on the include path, as the lab binary does."""
    lab, release = finished
    p = run(release, "make -n -B -s build/unit_tests")
    compiles = [line for line in p.stdout.splitlines() if "-c tests/unit/" in line]
    assert compiles, p.stdout + p.stderr
    own = f"-Ilabs/{FOLDERS[lab]}/skeleton"
    writes_shared = bool(leaks.skeletons.SHARED_SOURCES.get(FOLDERS[lab]))
    assert all((own in line) == writes_shared for line in compiles), compiles[0]


def test_render_and_test_pass(finished):
    lab, release = finished
    for command in ("make render", "make test"):
        p = run(release, command, timeout=1200)
        assert p.returncode == 0, f"{command}: " + (p.stdout + p.stderr)[-3000:]
    assert (release / "cornell.ppm").is_file()


def test_grade_defaults_to_the_lab_and_handin_packs_what_it_grades(finished):
    lab, release = finished
    p = run(release, "make handin")
    assert p.returncode == 0 and (release / f"handin-lab{lab}.zip").is_file(), p.stderr
    budget = f" GRADE_ARGS='--budget-seconds {GRADE_BUDGET[lab]}'" if lab in GRADE_BUDGET else ""
    p = run(release, f"make -s grade{budget}", timeout=1200)
    assert f"Lab {lab} " in p.stdout and "does not compile" not in p.stdout, p.stdout + p.stderr
    # the zip, unpacked into a folder inside a folder, grades as lab NN's sources
    sub = release / "submission" / "nested"
    sub.mkdir(parents=True)
    shutil.unpack_archive(release / f"handin-lab{lab}.zip", sub)
    p = run(release, f"python3 -m grading.grade {lab} --trusted --sources submission "
                     f"--results sub.json --budget-seconds 0", timeout=1200)
    assert f"Lab {lab} " in p.stdout and "does not compile" not in p.stdout, \
        p.stdout + p.stderr


def test_make_help_has_a_students_and_a_staff_section():
    out = subprocess.run(["make", "-s", "-C", str(ROOT), "help"], capture_output=True,
                         text=True, check=True, env=CLEAN_ENV).stdout
    students, staff = out.split("For course staff")
    assert students.startswith("For students")
    for target in ("make grade ", "make handin", "make render", "make test", "make bench-cpu"):
        assert target in students, target
    for target in ("make release", "make gradescope", "make grade-batch", "make grade-slurm"):
        assert target in staff and target not in students, target


def test_bench_cpu_builds_only_what_it_times():
    """Not every binary of the course (the CUDA labs for six architectures): `make -n` shows
    no prerequisite of bench-cpu, and the tool names the CPU binaries it builds."""
    p = subprocess.run(["make", "-n", "-C", str(ROOT), "bench-cpu"], capture_output=True,
                       text=True, check=True, env=CLEAN_ENV)
    assert [line for line in p.stdout.splitlines() if "tools.bench.cpu" in line] and \
        "nvcc" not in p.stdout and "g++" not in p.stdout, p.stdout
    source = (ROOT / "tools" / "bench" / "cpu.py").read_text()
    assert "load average" in source and "capacity" in source


# ---- the GPU labs: every command exists in the release ----------------------------------------

SYSTEM_TOOLS = {"cuobjdump", "ncu", "nsys", "nvidia-smi", "cat", "ls", "cd", "echo", "git"}


def simple_commands(command: str) -> list[list[str]]:
    """The simple commands of a command line or block, as words, environment settings and
    launchers (mpirun and its options) dropped."""
    found = []
    for part in re.split(r"&&|\|\||;|\||\n", command):
        words = part.replace("\\", " ").split()
        while words and re.fullmatch(r"\w+=\S*", words[0]):
            words.pop(0)
        if words and words[0] == "mpirun":
            words = [w for w in words if w.startswith("./")][:1] + words[1:]
        if words:
            found.append(words)
    return found


def missing_from(release: pathlib.Path, command: str) -> str | None:
    """Why `command` (a line of a README or handout) names something the release lacks, or
    None. A make goal must be one make knows how to make there (`make -n`); ./labNN one of
    its make targets; `python3 -m M` a module that ships, and every path it names."""
    for words in simple_commands(command):
        first = words[0]
        if first == "make" or first.startswith("./lab"):
            # A dry run: a goal make has no rule for (or a prerequisite without one, such as
            # a solution the release lacks) says so; a recipe that runs anyway under -n
            # (one that calls $(MAKE)) may fail for want of what -n did not build.
            goals = words[1:] if first == "make" else [first[2:]]
            p = run(release, "make -n -s " + " ".join(goals))
            said = p.stdout + p.stderr
            if "No rule to make target" in said:
                return f"make -n {' '.join(goals)}: " + said.strip()[-300:]
        elif first == "python3":
            if words[1:2] == ["-m"]:
                module = words[2].replace(".", "/")
                if not any((release / f).exists() for f in
                           (f"{module}.py", f"{module}/__main__.py")) and words[2] != "pytest":
                    return f"python3 -m {words[2]}: no such module in the release"
            paths = [w for w in words[1:] if "/" in w and not w.startswith("-")]
            absent = [w for w in paths if not (release / w.rstrip(":")).exists()]
            if absent:
                return f"{' '.join(words)}: {', '.join(absent)} not in the release"
        elif "/" in first and not (release / first).exists():
            return f"{first}: not in the release"
        elif "/" not in first and first not in SYSTEM_TOOLS and first not in ("for", "do",
                                                                               "done", "bash"):
            return f"{first}: not a command this check knows (add it to SYSTEM_TOOLS?)"
    return None


@pytest.fixture(scope="module", params=GPU_LABS)
def gpu_release(request, tmp_path_factory):
    return request.param, released(request.param, tmp_path_factory, timeout=3600)


def test_every_command_of_a_gpu_release_exists(gpu_release):
    lab, release = gpu_release
    found = commands(release, lab)
    assert "make grade-gpu" in found and "make kernel-report" in found, found
    absent = [f"{command}\n  {why}" for command in found
              if (why := missing_from(release, command))]
    print(f"lab {lab} release, {len(found)} commands:\n  " + "\n  ".join(found))
    assert not absent, "\n".join(absent)
