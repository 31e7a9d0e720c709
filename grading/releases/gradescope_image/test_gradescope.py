"""`make test-gradescope`: the Gradescope bundle graded as Gradescope runs it.

A Debian base image made with debootstrap from the Debian archive this machine uses (once;
kept as prt-debian-base:bookworm), the lab-01 bundle built into an image on it
(grading/releases/gradescope_image/Dockerfile: setup.sh at build time), and run_autograder
run in fresh containers with Docker's default seccomp profile and capabilities at 0.5 CPU and
768 MB:

    reference (render.cpp, path_steps.h)           100
    skeleton (as generated)                         at most 10
    a render.cpp including the solution, a link     at most 10, a complete results.json

Needs Docker (a running daemon: it tries `dockerd` when none answers) and debootstrap; prints
one line and exits 2 without them. Not part of `make test`: it downloads packages and takes
minutes.
"""
from __future__ import annotations

import json
import pathlib
import re
import shutil
import subprocess
import sys
import tempfile
import time
import zipfile

ROOT = pathlib.Path(__file__).resolve().parents[3]  # make test-gradescope: on the import path
BASE = "prt-debian-base:bookworm"
IMAGE = "prt-gradescope-lab01"
LIMITS = ["--cpus=0.5", "--memory=768m"]  # Gradescope's defaults


def fail(line: str) -> None:
    print(f"test-gradescope: {line}", file=sys.stderr)
    sys.exit(2)


def run(cmd, **kwargs) -> subprocess.CompletedProcess:
    return subprocess.run(cmd, check=True, **kwargs)


def docker_ready() -> None:
    if not shutil.which("docker"):
        fail("docker is not installed")
    if subprocess.run(["docker", "info"], capture_output=True).returncode == 0:
        return
    if not shutil.which("dockerd"):
        fail("no Docker daemon answers and dockerd is not installed")
    log = open(tempfile.gettempdir() + "/test-gradescope-dockerd.log", "ab")
    subprocess.Popen(["dockerd"], stdout=log, stderr=log, start_new_session=True)
    for _ in range(60):
        if subprocess.run(["docker", "info"], capture_output=True).returncode == 0:
            return
        time.sleep(1)
    fail(f"dockerd did not start (see {log.name})")


def debian_mirror() -> str:
    """The Debian archive this machine's apt uses."""
    for source in [pathlib.Path("/etc/apt/sources.list"),
                   *pathlib.Path("/etc/apt/sources.list.d").glob("*.sources")]:
        if source.is_file():
            m = re.search(
                r"(?m)^(?:URIs:\s*|deb\s+(?:\[[^]]*\]\s+)?)(\S+/debian)/?\s", source.read_text()
            )
            if m:
                return m.group(1)
    return "http://deb.debian.org/debian"


def base_image() -> None:
    if subprocess.run(["docker", "image", "inspect", BASE], capture_output=True).returncode == 0:
        return
    if not shutil.which("debootstrap"):
        fail("debootstrap is not installed (apt-get install debootstrap)")
    with tempfile.TemporaryDirectory() as tmp:
        target = pathlib.Path(tmp) / "rootfs"
        print(f"debootstrap bookworm from {debian_mirror()} ...", flush=True)
        run(["debootstrap", "--variant=minbase", "bookworm", str(target), debian_mirror()],
            stdout=subprocess.DEVNULL)
        tar = subprocess.Popen(["tar", "-C", str(target), "-c", "."], stdout=subprocess.PIPE)
        run(["docker", "import", "-", BASE], stdin=tar.stdout, stdout=subprocess.DEVNULL)
        tar.wait()


def autograder_image(work: pathlib.Path) -> None:
    from grading.releases.gradescope import bundle
    zip_path = bundle("01", work / "lab01.zip")
    context = work / "context"
    with zipfile.ZipFile(zip_path) as z:
        z.extractall(context / "source")
    shutil.copy(pathlib.Path(__file__).with_name("Dockerfile"), context / "Dockerfile")
    print("docker build (setup.sh) ...", flush=True)
    run(["docker", "build", "-q", "--build-arg", f"BASE={BASE}", "-t", IMAGE, str(context)],
        stdout=subprocess.DEVNULL)


def grade(work: pathlib.Path, name: str, files: dict[str, str | pathlib.Path]) -> dict:
    """run_autograder in a fresh container on a submission; its results.json."""
    sub = work / name / "submission"
    results = work / name / "results"
    sub.mkdir(parents=True)
    results.mkdir()
    for file_name, content in files.items():
        if isinstance(content, pathlib.Path):
            (sub / file_name).symlink_to(content)
        else:
            (sub / file_name).write_text(content)
    p = subprocess.run(
        [
            "docker",
            "run",
            "--rm",
            *LIMITS,
            "-v",
            f"{sub}:/autograder/submission:ro",
            "-v",
            f"{results}:/autograder/results",
            IMAGE,
            "/autograder/run_autograder",
        ],
        capture_output=True,
        text=True,
        timeout=1800,
    )
    try:
        return json.loads((results / "results.json").read_text())
    except (OSError, ValueError):
        fail(f"{name}: no results.json ({p.stdout[-500:]}{p.stderr[-500:]})")


def main() -> int:
    from grading.students_tree import pristine_skeleton
    docker_ready()
    base_image()
    with tempfile.TemporaryDirectory() as tmp:
        work = pathlib.Path(tmp)
        work.chmod(0o755)
        autograder_image(work)
        solution = (ROOT / "labs/01-serial/solution/render.cpp").read_text()
        tracer = (ROOT / "common/core/path_steps.h").read_text()
        cases = [
            (
                "reference",
                {"render.cpp": solution, "path_steps.h": tracer},
                lambda s: s == 100,
                "100",
            ),
            ("skeleton", pristine_skeleton("01-serial"), lambda s: s <= 10, "at most 10"),
            (
                "includes-the-solution",
                {
                    "render.cpp":
                        '#include "/autograder/source/labs/01-serial/solution/render.cpp"\n',
                    "path_steps.h": '#include "/autograder/source/common/core/path_steps.h"\n',
                },
                lambda s: s <= 10,
                "at most 10",
            ),
            (
                "links",
                {
                    "render.cpp": solution,
                    "path_steps.h": pathlib.Path("/autograder/source/common/core/path_steps.h"),
                },
                lambda s: s <= 10,
                "at most 10",
            ),
        ]
        failed = 0
        for name, files, ok, want in cases:
            results = grade(work, name, files)
            good = ok(results.get("score", -1)) and results.get("tests")
            failed += not good
            print(f"{'PASS' if good else 'FAIL'} {name}: {results.get('score')}/"
                  f"{results.get('max_score')} (want {want}); sandbox: {results.get('sandbox')}; "
                  f"{results.get('output', '')[:300]!r}", flush=True)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
