"""A Gradescope autograder bundle for one lab: the repository (the grader, the references'
sources, the golden data) with Gradescope's two entry points at the top of the zip.

    make gradescope LAB=01            -> build/gradescope-lab01.zip

Gradescope unpacks the zip into /autograder/source, runs setup.sh once when it builds the
image (packages, bubblewrap, the reference binaries) and run_autograder for every
submission, which finds the student's files in /autograder/submission and must leave
/autograder/results/results.json. The grader runs the student's binary in its sandbox; the
solutions in the image stay out of the sandbox's view. AUTOGRADER_ROOT (default /autograder)
lets a test run the bundle in a scratch folder laid out the same way.
"""
from __future__ import annotations

import argparse
import pathlib
import subprocess
import sys
import textwrap
import zipfile

from grading.grade import RUBRICS
from labkit import gpu, registry
from labkit.harness import ROOT

# The labs graded on their parallel speedup, which a quota below 1.5 cores cannot measure
# (speed.QUOTA_TOO_SMALL).
PARALLEL_LABS = {lab.number for lab in registry.labs() if lab.rubric in ("openmp", "mpi")}

SETUP = """#!/usr/bin/env bash
# Gradescope runs this once, as root, when it builds the autograder image. The image is built
# on one machine and run on others: the references are compiled for any x86-64-v2 CPU (the
# same bits as a native build: -ffp-contract=off stays). Gradescope's containers refuse
# namespaces (Docker's default seccomp profile), so the grader isolates submissions by user
# there: each run a user of its own, needing no account (grading/README.md).
set -euo pipefail
cd "$(dirname "$0")"
bash tools/install_deps.sh
make -s lab01-ref lab04-ref \\
    OPT="-O3 -march=x86-64-v2 -ffp-contract=off -fno-math-errno -fno-trapping-math"
"""

RUN = """#!/usr/bin/env bash
# Gradescope runs this for every submission. The grader writes results.json whatever happens;
# if even Python cannot start, this still leaves one saying so.
root="${{AUTOGRADER_ROOT:-/autograder}}"
cd "$root/source"
mkdir -p "$root/results"
python3 -m grading.grade {lab} --no-build --sources "$root/submission" \\
    --results "$root/results/results.json" --heatmaps "$root/results/heatmaps"
status=$?
if [ ! -s "$root/results/results.json" ]; then
    printf '{{"score": 0, "output": "the grader failed (status %s) before writing results", "tests": []}}\\n' \\
        "$status" > "$root/results/results.json"
fi
exit 0
"""


def settings(lab: str) -> str:
    """What to choose in the assignment's autograder settings on Gradescope for lab `lab`, and
    what happens at its defaults: printed by `make gradescope` and the bundle's README.md."""
    kind = registry.lab(lab).kind
    if kind == "gpu" or gpu.is_gpu_lab(lab):
        cpus = ("Gradescope's machines have no GPU: every grade of this lab is refused in one "
                "line and marked for regrade. Grade it on the course's GPU machines instead "
                "(make grade-batch or make grade-slurm LAB=%s); the settings above only keep "
                "the refusal fast." % lab)
        cpu_line, memory = "any (0.5 CPU is enough to refuse)", "768 MB (the default)"
    elif lab in PARALLEL_LABS:
        cpus = (f"Lab {lab} is graded on its parallel speedup. At Gradescope's default of 0.5 "
                f"CPU the grader says so in one line (\"not timed: this machine gives 0.5 "
                f"cores' worth...\"), grades correctness and marks the speed, and with it the "
                f"points gated on it, for a hand regrade on a course machine: every grade then "
                f"waits for one. Choose 2.0 CPUs or more.")
        cpu_line, memory = "2.0 or more (4.0 measures more cores' worth)", "3 GB (with 2.0 CPUs)"
    else:
        cpus = (f"Lab {lab} is timed on one core or not at all: Gradescope's default of 0.5 CPU "
                f"grades it, only more slowly.")
        cpu_line, memory = "0.5 (the default) or more", "768 MB (the default) or more"
    return f"""Gradescope settings for lab {lab} (the assignment's "Configure Autograder" page)
  Base image:          Ubuntu 22.04 or any Debian-based image with apt (setup.sh installs
                       every package; `make test-gradescope` builds it on Debian 12)
  Autograder CPUs:     {cpu_line}
  Memory:              {memory}
  Autograder timeout:  40 minutes (Gradescope's default; the grader's own budget is 40
                       minutes and it writes results.json at every step, so a grade cut short
                       keeps what it did)
{textwrap.fill(cpus, 92, initial_indent="  ", subsequent_indent="  ")}
"""


def bundle_readme(lab: str) -> str:
    return f"""# Autograder for lab {lab}

Upload this zip as the assignment's autograder. Gradescope runs `setup.sh` once when it
builds the image (packages, the sandbox user, the reference binaries) and `run_autograder`
for every submission (grading/README.md in this zip: "On Gradescope").

```
{settings(lab)}```

The course's own README is COURSE-README.md.
"""


def repository_files() -> list[str]:
    """Tracked and untracked-but-not-ignored files: what a checkout of the tree holds."""
    out = subprocess.run(["git", "-C", str(ROOT), "ls-files", "-co", "--exclude-standard", "-z"],
                         capture_output=True, check=True).stdout
    return sorted(f for f in out.decode().split("\0") if f and (ROOT / f).is_file())


def bundle(lab: str, out: pathlib.Path) -> pathlib.Path:
    out.parent.mkdir(parents=True, exist_ok=True)
    with zipfile.ZipFile(out, "w", zipfile.ZIP_DEFLATED) as z:
        for f in repository_files():
            z.write(ROOT / f, "COURSE-README.md" if f == "README.md" else f)
        z.writestr("README.md", bundle_readme(lab))
        for name, text in (("setup.sh", SETUP), ("run_autograder", RUN.format(lab=lab))):
            info = zipfile.ZipInfo(name)
            info.external_attr = 0o755 << 16  # executable once unpacked
            z.writestr(info, text)
    return out


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("lab", choices=sorted(RUBRICS))
    p.add_argument("--out", type=pathlib.Path)
    a = p.parse_args(argv)
    out = bundle(a.lab, a.out or ROOT / "build" / f"gradescope-lab{a.lab}.zip")
    print(f"wrote {out} (its README.md says the same)\n")
    print(settings(a.lab), end="")
    return 0


if __name__ == "__main__":
    sys.exit(main())
