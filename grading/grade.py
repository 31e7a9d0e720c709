"""The autograder: build a lab, run its checks on the binary in a sandbox, print a score table
and write a Gradescope-style results.json, whatever happens.

    make grade LAB=01                  grade your own lab-01 code (./lab01), trusted
    python3 -m grading.grade 01 --binary ./lab01-ref --results out.json

Without --trusted every process of the submission runs in the sandbox of labkit/sandbox.py;
where the sandbox cannot be had the grader says why and grades nothing. The score formula of
each lab is in grading/README.md.
"""
from __future__ import annotations

import argparse
import dataclasses
import os
import pathlib
import re
import signal
import sys
import time
from typing import Callable

from grading import references, report_html
from grading.checks import (
    analytic,
    check_result,
    draws,
    golden_sums,
    hidden,
    identity,
    invariance,
    mpi,
    part_a,
    races,
    speed,
    symptoms,
)
from grading.checks.golden import check_golden
from grading.checks.layout import check_structure_of_arrays
from grading.results import Results, Test
from labkit import gpu, registry, sandbox
from labkit.harness import ROOT, RunPolicy, available_cores, make_in_root, policy, rerun_as
from labkit.mpi import mpirun

LAB01_REFERENCE = ROOT / "lab01-ref"
LAB04_REFERENCE = ROOT / "lab04-ref"
# The binaries a rubric's parts run on, besides the lab's own (Item.part).
PART_NAMES = {"a": "Part A binary (./lab02a)", "race": "ThreadSanitizer build (make lab03-race)"}


@dataclasses.dataclass(frozen=True)
class Item:
    """One line of a rubric. The grader and its tests know a check by `id`; `label` is only
    what the table and Gradescope print."""
    id: str
    label: str
    points: int
    run: Callable  # run(binary, **kwargs) -> check_result.CheckResult
    heatmaps: bool = False  # run() takes heatmap_dir=: an image comparison
    requires: tuple[str, ...] = ()  # counted only once the items with these ids have passed
    # Runs even while a requirement fails (its points still wait for it): lab 03/04's bit
    # check, whose diagnosis (a race, or the work split) is what a failing speedup needs.
    always_runs: bool = False
    visibility: str = "visible"     # Gradescope's, for its results.json test
    part: str = ""  # runs on this part's binary (lab 02's "a": ./lab02a), not the lab's

    def __post_init__(self):
        if isinstance(self.requires, str):
            object.__setattr__(self, "requires", (self.requires,))


def golden(scene: str, points: int, **options) -> Item:
    return Item(f"golden-{scene}", f"golden image '{scene}'", points,
                lambda b, **k: check_golden(b, scene, **options, **k), heatmaps=True)


def bitwise(points: int, **options) -> Item:
    return Item("bitwise", "bit-identical to lab 01", points,
                lambda b: identity.check_bitwise_equal(b, LAB01_REFERENCE, **options),
                always_runs=True)


def hidden_scene(**options) -> Item:
    """A scene made from a secret at grading time (grading/checks/hidden.py): worth no points
    itself, but the golden images count only when it passes, so printing the stored golden images
    earns nothing."""
    return Item("hidden", "hidden scene", 0,
                lambda b, secret, **k: hidden.check_hidden(b, LAB01_REFERENCE, secret,
                                                           **options, **k), heatmaps=True,
                visibility="after_published")


def parallel_speedup(points: int, **options) -> Item:
    return Item("parallel-speedup", "parallel speedup", points,
                lambda b: speed.check_parallel_speedup(b, LAB01_REFERENCE, **options))


def worth(item: Item, points: int) -> Item:
    return dataclasses.replace(item, points=points)


def needs(item: Item, *ids: str) -> Item:
    return dataclasses.replace(item, requires=item.requires + ids)


SPHERE_INTERIOR = Item("sphere-interior", "analytic sphere interior", 0,
                       analytic.check_sphere_interior)
LIT_PLANE = Item("lit-plane", "analytic lit plane", 0, analytic.check_lit_plane)
GLASS_PANE = Item("glass-pane", "analytic glass pane (Fresnel)", 0, analytic.check_glass_slab)
# Robustness counts only for a renderer that renders light: a flat-colour skeleton is
# trivially scale-invariant.
SCALE = Item("scale", "scale invariance 1e-4..1e5", 0, invariance.check_scale_invariance,
             requires="golden-cornell")
REPRODUCIBLE = Item("reproducible", "reproducible", 0, invariance.check_reproducible)
STRUCTURE_OF_ARRAYS = Item("structure-of-arrays", "path pool laid out as a structure of arrays", 10,
                           check_structure_of_arrays)
GOLDENS = ("golden-cornell", "golden-showcase")


def checked_golden(scene: str, points: int, **options) -> Item:
    return needs(golden(scene, points, **options), "hidden")




# ---- the GPU labs (05-07) ------------------------------------------------------------------
# Their correctness checks are lab 01's, run on the student's GPU binary. Their speed is
# compared with the lab's own reference (labNN-ref, built from labs/NN-*/solution) on the same
# GPU in the same run, interleaved, best of 3, in wall-clock time the grader measures around
# each process (speed.check_speedup). A GPU process spends about 0.3 s creating its CUDA
# context and loading its kernels before any pixel is rendered, ten times the kernel time of
# the baseline (handouts/05-cuda-mega.md, section 8), which would squash every ratio towards 1.
# So the timed render is the golden Cornell view at GPU_TIMED_SCALE times its size (640x640,
# the baseline's shape, a grid that fills the GPU) with spp chosen for GPU_TIMED_SECONDS of the
# reference's kernel time on the record's H200, and the start-up, measured by rendering one
# pixel with the trusted reference, is subtracted from both sides: the ratio compares
# rendering, copies included, not context creation. Each timed image is box-filtered to the
# golden size and must pass the golden comparison.
GPU_SPEED_BAR = 0.75  # at least 3/4 of the reference's speed: at most 1.33x its time
GPU_TIMED_SCALE = 10
# Each GPU lab's spp is its timed_spp in labs/labs.toml: the spp at which the lab's reference,
# at the throughput its newest GPU record (reference/gpu/<card>/) measured on the baseline,
# renders the timed view in GPU_TIMED_SECONDS of kernel time (`python3 -m tools.gpu.figures
# --timed-spp` computes it; tests/tools/test_gpu_figures.py fails when labs.toml and the record
# disagree).
GPU_TIMED_SECONDS = 0.35
GPU_TIMED_SPP = {lab.number: lab.timed_spp for lab in registry.labs() if lab.gpu}


def gpu_reference(lab: str) -> pathlib.Path:
    return ROOT / f"lab{lab}-ref"


def gpu_speed(lab: str, points: int) -> Item:
    """Speed against the lab's reference; counts only once both golden images pass. A lab whose
    reference goes past what its task asks (labs/labs.toml's speed_bar) sets its own bar."""
    reference = gpu_reference(lab)
    bar = registry.lab(lab).speed_bar or GPU_SPEED_BAR
    return Item("speed", f"speed >= {bar:g}x the lab {lab} reference", points,
                lambda b: speed.check_speedup(b, reference, bar,
                                              spp=GPU_TIMED_SPP[lab], scale=GPU_TIMED_SCALE,
                                              overhead_reference=reference),
                requires=GOLDENS)


def gpu_rubric(lab: str, layout_lesson: bool = False) -> list[Item]:
    """Labs 05-07 alike. The sphere interior is worth little: lab 05's skeleton (spheres only,
    one path per pixel) passes it, the zero-variance scene needing no second path. A
    reproducible skeleton proves nothing either, so reproducibility, like scale, counts only
    for a renderer that renders the golden image. Lab 07's lesson is the pool's layout
    (`layout_lesson`, rubric "gpu-soa"), which its speed cannot show (lab 06's layout is within
    10% of it): 10 of its speed's points go to the layout itself."""
    layout = [needs(STRUCTURE_OF_ARRAYS, "golden-cornell")] if layout_lesson else []
    return [
        worth(SPHERE_INTERIOR, 5), worth(LIT_PLANE, 10), worth(GLASS_PANE, 10), hidden_scene(),
        checked_golden("cornell", 20), checked_golden("showcase", 15), worth(SCALE, 5),
        needs(worth(REPRODUCIBLE, 5), "golden-cornell"), gpu_speed(lab, 30 - 10 * len(layout)),
        *layout,
    ]


# Points per check, per kind of rubric (grading/README.md gives the formulas); each lab names
# its rubric in labs/labs.toml. The checks are described in grading/checks/. In labs 03 and
# 04 the point is parallelism: a correct serial renderer (lab 03's skeleton is one) earns
# nothing there until its parallel speedup is shown, and the speedup counts only when the
# timed images are lab 01's bits.
RUBRIC_KINDS: dict[str, Callable[[str], list[Item]]] = {
    "serial": lambda lab: [
        worth(SPHERE_INTERIOR, 15), worth(LIT_PLANE, 15), worth(GLASS_PANE, 10), hidden_scene(),
        checked_golden("cornell", 20), checked_golden("showcase", 20), worth(SCALE, 10),
        worth(REPRODUCIBLE, 10),
    ],
    # Both parts of the handout: Part B (./lab02, the packets) and Part A (./lab02a, lab 01's
    # renderer on the student's SSE Vec3: lab 01's closed forms and hidden scene on it).
    "simd": lambda lab: [
        worth(SPHERE_INTERIOR, 5), worth(LIT_PLANE, 5), worth(GLASS_PANE, 5), hidden_scene(),
        checked_golden("cornell", 15), checked_golden("showcase", 10), worth(SCALE, 10),
        # The handout's bar is 2.5x on the full baseline; graded here is what holds on a busy
        # two-core machine in a short run, both sides on one CPU (the lesson is SIMD, not
        # threads). Speed counts only for a correct renderer.
        Item("speedup", "speedup >= 1.5x on one core", 30,
             lambda b: speed.check_speedup(b, LAB01_REFERENCE, 1.5, one_core=True),
             requires=GOLDENS),
        Item("part-a", "Part A (./lab02a)", 20,
             lambda b, secret: part_a.check_part_a(b, secret, LAB01_REFERENCE), part="a"),
    ],
    "openmp": lambda lab: [
        needs(bitwise(30), "parallel-speedup"),
        hidden_scene(),
        needs(checked_golden("cornell", 20), "parallel-speedup"),
        needs(checked_golden("showcase", 10), "parallel-speedup"),
        # 75% of the cores' worth of throughput the machine gives during the run; the
        # handout's bar, 0.9 x cores, is measured by tools/bench/openmp.py on a quiet machine.
        parallel_speedup(30),
        # The races no image shows: the hand-in built for ThreadSanitizer (its own binary).
        Item("races", "no data race", 10, races.check_races, requires="parallel-speedup",
             part="race"),
    ],
    # Every task of the handout: the gather (the bits at 2, 3, 5 ranks), the interleaved and
    # dynamic distributions (their bits, and the rows each rank rendered, which no image
    # shows: blocks render the same bits) and the hybrid run (2 ranks x 2 threads, its bits,
    # and a rank's threads sharing its work, which no image shows either).
    "mpi": lambda lab: [
        needs(bitwise(20, runs={
            **{f"{n} ranks": {"launcher": mpirun(n), "threads": 1} for n in (1, 2, 3, 5)},
            **{f"3 ranks {d}": {"launcher": mpirun(3, d), "threads": 1}
               for d in mpi.DISTRIBUTIONS if d != "dynamic"},
            "2 ranks x 2 threads": {"launcher": mpirun(2), "threads": 2}}),
            "parallel-speedup"),
        Item("distributions", "rows per distribution", 20, mpi.check_distributions,
             requires=("bitwise",)),
        Item("hybrid", "hybrid threads", 10, mpi.check_hybrid_threads, requires=("bitwise",)),
        hidden_scene(launcher=mpirun(2), threads=1),
        needs(checked_golden("cornell", 15, launcher=mpirun(2)), "parallel-speedup"),
        needs(checked_golden("showcase", 10, launcher=mpirun(2)), "parallel-speedup"),
        # 2048 spp: mpirun's start-up, whose CPU time counts in the cores a run used, must be
        # small beside the render, or a parallel reference reads as serial.
        parallel_speedup(25, threads=1, launcher=mpirun(available_cores()),
                         overhead_reference=LAB04_REFERENCE, spp=2048),
    ],
    "gpu": gpu_rubric,
    "gpu-soa": lambda lab: gpu_rubric(lab, layout_lesson=True),
}
RUBRICS = {lab.number: RUBRIC_KINDS[lab.rubric](lab.number) for lab in registry.labs()}

# What a grade takes, said when it starts (measured on a two-core VM: grading/README.md's
# "Always a result"): the speed checks time the lab against its reference in rounds.
HOW_LONG = {"serial": "seconds", "simd": "about a minute", "openmp": "one to a few minutes: "
            "the speedup is timed in rounds", "mpi": "one to a few minutes: the speedup is "
            "timed in rounds", "gpu": "about a minute", "gpu-soa": "about a minute"}

# One run may take this long (seconds); every test render of a reference takes under 2 s on
# a busy two-core machine. After a run has timed out, later runs get SHORT_RUN_SECONDS: a
# program that hangs once is not given the full limit again and again.
RUN_SECONDS = 20.0
SHORT_RUN_SECONDS = 5.0
# Gradescope's default limit for a whole submission.
BUDGET_SECONDS = 40 * 60


def grading_order(rubric: list[Item]) -> list[Item]:
    """The rubric with every item after those it requires (the table keeps rubric order)."""
    done: list[Item] = []
    pending = list(rubric)
    while pending:
        ready = [i for i in pending if all(r in {d.id for d in done} for r in i.requires)]
        if not ready:
            raise ValueError(f"circular requirements among {[i.id for i in pending]}")
        done.append(ready[0])
        pending.remove(ready[0])
    return done


def grade(lab: str, binary: pathlib.Path, heatmap_dir: pathlib.Path, *, trusted: bool = False,
          budget_seconds: float = BUDGET_SECONDS, run_seconds: float = RUN_SECONDS,
          results: Results | None = None, secret: str | None = None,
          progress: Callable | None = None,
          parts: dict[str, pathlib.Path | str] | None = None) -> dict:
    """Grade `binary` on lab `lab`'s rubric; returns results.json's content. `results` (if
    given) is updated after each item, so a caller can write it as it goes. `secret` makes
    the hidden scene (default: $GRADING_SECRET, else a new one for this grade). Trusted (at
    home), every check runs and says what it saw; a requirement decides only whether its
    points count. `progress(item, test)` is called as each check starts (test None) and
    finishes. `parts` holds a part's binary (lab 02's "a": ./lab02a) or why there is none.
    """
    secret = secret or hidden.secret_from_environment()
    rubric = RUBRICS[lab]
    results = results or Results()
    for item in rubric:
        results.add(Test(item.id, item.label, item.points, visibility=item.visibility))
    if not trusted:
        reason = sandbox_problem(results)
        if reason:
            results.refuse(reason, regrade=True)
            return results.as_dict()
    reason = golden_sums.problem()
    if reason:  # every image check would compare with the wrong data: the grader's fault
        results.refuse(f"refusing to grade against golden data that is not as recorded: "
                       f"{reason}", regrade=True)
        return results.as_dict()
    reason = references.problem(lab)
    if reason:  # no baseline, no golden data for the hidden scene: the machine's fault
        results.refuse(reason, regrade=True)
        return results.as_dict()
    on_gpu = gpu.is_gpu_lab(lab)
    # CUDA reserves virtual address space for all of the GPU's memory and the host's (unified
    # addressing), so an address-space limit (RLIMIT_AS) stops every CUDA program at start-up.
    limits = sandbox.Limits(wall_seconds=run_seconds,
                            memory_bytes=None if trusted or on_gpu else sandbox.Limits.memory_bytes)
    run_policy = RunPolicy(trusted=trusted, limits=limits, gpu=on_gpu)
    if on_gpu:
        reason = gpu_problem(lab, run_policy)
        if reason:
            results.refuse(reason, regrade=True)
            return results.as_dict()
    start = time.perf_counter()
    foreign_seen, sweeps_seen = len(sandbox.FOREIGN_CODE), len(sandbox.SWEEP_PROBLEMS)

    def foreign_code() -> str | None:
        return (sandbox.FOREIGN_CODE[foreign_seen:] or [None])[0]
    with draws.secret(secret), symptoms.grading(lab), rerun_as(f"./lab{lab}"):
        grade_items(rubric, binary, heatmap_dir, secret, results, run_policy, limits,
                    budget_seconds, start, progress, lambda: references.problem(lab), parts,
                    stop=foreign_code)
    if what := foreign_code():
        results.ran_foreign_code(what)
    for problem in sandbox.SWEEP_PROBLEMS[sweeps_seen:]:
        results.for_staff.append(f"the sandbox could not remove everything a run left "
                                 f"({problem}); the grade stands")
        results.notes.append(results.for_staff[-1])
    results.complete(time.perf_counter() - start)
    return results.as_dict()


def grade_items(rubric, binary, heatmap_dir, secret, results, run_policy, limits,
                budget_seconds, start, progress=None, reference_problem=None,
                parts=None, stop=None) -> None:
    """Each item of the rubric in grading order, results updated after each, until `stop()`
    says why the grade ends (a foreign program ran: nothing after it counts). A check whose
    requirements failed is not run (untrusted: the grade's time goes to what counts), unless
    the grade is trusted or the check always runs: then it runs and shows what it saw, its
    points "not counted until" the requirements pass. A check that failed while a reference
    could not run (`reference_problem()` says why) is marked for regrade, never scored."""
    for item in grading_order(rubric):
        test = results.test(item.id)
        labels = [i.label for i in rubric if i.id in item.requires
                  and not results.test(i.id).passed]
        waiting = (f"the {' and the '.join(labels)} "
                   f"{'passes' if len(labels) == 1 else 'pass'}") if labels else ""
        unconfirmed = [i.label for i in rubric if i.id in item.requires
                       and gate_unconfirmed(results.test(i.id))]
        # A part's binary, or why it has none (a string); the lab's own binary otherwise.
        target = (parts or {}).get(item.part, f"no {PART_NAMES[item.part]} was given") \
            if item.part else binary
        if item.part and isinstance(target, str):
            test.finish(0, f"not graded: {target}")
        elif time.perf_counter() - start > budget_seconds:
            test.finish(0, "not graded: the grading budget of "
                           f"{budget_seconds:g} s was spent on the checks before it")
        elif waiting and not (run_policy.trusted or item.always_runs):
            test.finish(0, f"not graded until {waiting}")
        else:
            if progress:
                progress(item, None)
            t0 = time.perf_counter()
            with policy(dataclasses.replace(run_policy, limits=limits)):
                result = run_check(item, target, heatmap_dir, secret)
            if not result.passed and reference_problem and (why := reference_problem()):
                result = check_result.CheckResult(item.label, False, why, regrade=True)
            credit = result.credit if result.credit is not None else float(result.passed)
            if waiting:  # it ran, and says what it saw; its points wait for the gate
                mark = "" if result.detail.startswith(("PASS", "FAIL")) else \
                    ("PASS " if result.passed else "FAIL ")
                test.finish(0, f"not counted until {waiting}; it saw: {mark}{result.detail}",
                            seconds=time.perf_counter() - t0)
            elif unconfirmed:  # its points wait, shown apart, for the regrade of the gate
                test.finish(0, f"{result.detail}; counted when the regrade confirms the "
                               f"{' and the '.join(unconfirmed)}",
                            seconds=time.perf_counter() - t0, regrade=True, ok=result.passed,
                            provisional=round(item.points * credit))
            else:
                test.finish(round(item.points * credit), result.detail,
                            seconds=time.perf_counter() - t0, regrade=result.regrade,
                            ok=result.passed,
                            provisional=round(item.points * result.provisional)
                            if result.regrade else 0)
            if "timed out after" in result.detail:
                limits = dataclasses.replace(
                    limits, wall_seconds=min(limits.wall_seconds, SHORT_RUN_SECONDS))
            if progress:
                progress(item, test)
        results.changed()
        if stop and stop():
            return


def gate_unconfirmed(test: Test) -> bool:
    """A requirement that passed with nothing measured, left to a regrade (a parallel speedup
    the machine could not time: a thread that only spins looks like parallel work there):
    what it gates is graded, but its points stay provisional with it."""
    return test.passed and test.regrade and test.score == 0


def sandbox_problem(results: Results | None = None) -> str | None:
    """Why untrusted code cannot be graded here, in one line, or None; records which sandbox
    was picked in `results`. The machine's fault, never the submission's: a refusal is marked
    for regrade. In the user sandbox the repository is closed to the sandbox user; either
    sandbox's user must reach the temporary folder where inputs and builds are staged."""
    import tempfile
    if os.geteuid() == 0:  # either sandbox runs as a user other than root: it must get in
        closed = sandbox.unreachable(pathlib.Path(tempfile.gettempdir()), sandbox.NOBODY,
                                     sandbox.NOBODY)
        if closed:
            return (f"refusing to grade: the sandbox user cannot enter {closed} (mode "
                    f"{closed.stat().st_mode & 0o777:o}), where the grader stages every input "
                    f"and build; set TMPDIR to a folder it can enter; marked for regrade")
    reason = sandbox.probe()
    if reason:
        return (f"refusing to grade untrusted code without a sandbox: {reason} (pass "
                f"--trusted to grade your own code without one); marked for regrade")
    if os.geteuid() == 0:
        sandbox.hide_from_sandbox(ROOT)
    if results is not None:
        results.sandbox = sandbox.description()
    return None


def no_gpu_line(lab: str, reason: str, environment=None) -> str:
    """One line for a grade with no working GPU. Inside a Slurm job (make grade-gpu, the
    course's batch), the node was given as a GPU node: its name is what staff need, and
    running make grade-gpu again could land on it again."""
    environment = os.environ if environment is None else environment
    start = f"lab {lab} renders on an NVIDIA GPU and {reason}: not graded, marked for regrade"
    if environment.get("SLURM_JOB_ID"):
        node = environment.get("SLURMD_NODENAME") or environment.get("SLURM_NODELIST") or "?"
        return (f"{start}; this Slurm job's node {node} (job {environment['SLURM_JOB_ID']}) "
                f"was given as a GPU node: tell course staff, naming the node")
    return f"{start} on a machine with one (yours: make grade-gpu, through the course's Slurm)"


def next_step(results: dict) -> str | None:
    """At home, what to do about checks marked for regrade: the machine could not measure
    them, and the score table alone does not say what helps."""
    marked = [t["name"] for t in results["tests"] if t["extra_data"].get("regrade")]
    if not marked:
        return None
    return (f"marked for regrade: {', '.join(marked)}. At home that means this machine could "
            f"not measure it (too busy, too few cores, no GPU): close what else runs and run "
            f"make grade again, on a machine with more cores for labs 03/04 (2 or more, "
            f"idle) or with a GPU for labs 05-07 (make grade-gpu); the course "
            f"regrades your hand-in on its own machines, so nothing is lost meanwhile.")


def gpu_problem(lab: str, run_policy: RunPolicy) -> str | None:
    """Why lab `lab` cannot be graded on this machine's GPU, in one line, or None: no GPU, or
    the lab's trusted reference cannot render a pixel, outside the sandbox or where the
    submission will run (a sandbox without the device nodes or the driver's library). Each
    is the machine's fault, never the submission's. The run outside comes first also because
    the driver creates /dev/nvidia-uvm (nvidia-modprobe) at a machine's first CUDA program,
    which a sandboxed one cannot do; the sandbox shows the nodes that exist when it starts."""
    reason = gpu.missing_gpu()
    if reason:
        return no_gpu_line(lab, reason)
    from labkit.harness import run_lab
    policies = [dataclasses.replace(run_policy, trusted=True)]
    if not run_policy.trusted:
        policies.append(run_policy)
    for p in policies:
        with policy(p):
            run = run_lab(gpu_reference(lab), width=1, height=1, spp=1, check=False)
        if run.returncode != 0 or run.image is None:
            said = run.stderr.strip().splitlines()[-1:] or [sandbox.describe_exit(run.returncode)]
            where = "trusted" if p.trusted else "in the sandbox"
            return (f"lab {lab}'s reference cannot render on this machine's GPU ({where}): "
                    f"{said[0][:300]}; not graded, marked for regrade")
    return None


def run_check(item: Item, binary, heatmap_dir, secret: str = "") -> check_result.CheckResult:
    kwargs = {"heatmap_dir": heatmap_dir} if item.heatmaps else {}
    if item.id in ("hidden", "part-a"):
        kwargs["secret"] = secret
    try:
        result = item.run(binary, **kwargs)
    except Exception as e:  # a crash, a timeout, a missing image: no points, say why
        return check_result.CheckResult(item.label, False, f"could not run: {e}")
    if heatmap_dir:  # the images the page shows beside the check (grading/report_html.py)
        for scene, (yours, want) in result.images.items():
            report_html.write_images(heatmap_dir, scene, yours, want)
    return result


def check_id(test: dict) -> str:
    """The rubric item id of one entry of results["tests"]."""
    return test["extra_data"]["check"]


def passed_by_check(results: dict) -> dict[str, bool]:
    """Check id -> whether it passed (and so earned all its points)."""
    return {check_id(t): t["status"] == "passed" for t in results["tests"]}


def describe(results: dict) -> str:
    """One line per check: its id and what it saw."""
    return "\n".join(f"{check_id(t)}: {t['output']}" for t in results["tests"])


def unmeasurable(results: dict, check: str = "parallel-speedup") -> str | None:
    """What the speedup check said when the machine was too busy to measure it, else None."""
    output = next(t["output"] for t in results["tests"] if check_id(t) == check)
    test = next(t for t in results["tests"] if check_id(t) == check)
    return output if test["extra_data"].get("regrade") else None


def print_table(lab: str, binary: pathlib.Path, results: dict) -> None:
    print(f"Lab {lab} — {binary}")
    print(f"{'check':<32} {'points':>7}  what it saw")
    for t in results["tests"]:
        mark = {"passed": "PASS", "failed": "FAIL"}[t["status"]]
        if t["extra_data"].get("regrade"):
            mark = "REGRADE"
        print(f"{t['name']:<32} {t['score']:>3}/{t['max_score']:<3}  {mark} {t['output']}")
    print(f"{'total':<32} {results['score']:>3}/{sum(t['max_score'] for t in results['tests'])}")
    if results.get("output"):
        print(results["output"])


# A line that says why a build stopped: the compilers' errors and fatal errors ("nvcc fatal",
# "ptxas fatal"), a crash or a limit the shell reports, the sandbox's own verdict.
STOP_WORDS = re.compile(r"error|fatal|segmentation fault|killed|aborted|terminate called|"
                        r"limit exceeded|timed out", re.IGNORECASE)
MAKE_STOPPED = re.compile(r"^make(\[\d+\])?: \*\*\* ")


def first_errors(text: str, lines: int = 20) -> str:
    """The compiler's first error lines (what a student needs to see first). Where nothing but
    make's own "*** ... Error N" says why (nvcc running its compilers in parallel threads
    prints nothing when one of them crashes), the build's last lines stand in, said as such."""
    all_lines = text.splitlines()
    errors = [line for line in all_lines if STOP_WORDS.search(line)]
    if errors and all(MAKE_STOPPED.match(line) for line in errors):
        kept = [line for line in all_lines if line.strip()][-lines:]
        return "\n".join(["the compiler stopped without an error message; the build's last "
                           "lines:", *kept])[:4000]
    return "\n".join((errors or all_lines)[:lines])[:4000]


def build_warnings(text: str, lines: int = 20) -> str:
    """The compiler's warnings of a build that succeeded, with where they point: what a
    student should read before the points (an uninitialised variable, a sign mix-up)."""
    kept = [line for line in text.splitlines() if line.strip()]
    if not any("warning" in line.lower() for line in kept):
        return ""
    return "the build's warnings:\n" + "\n".join(kept[:lines])[:4000]


def clear_report(folder: pathlib.Path) -> None:
    """Removes what an earlier grade wrote in the report folder (its images, heatmaps and
    page), and nothing else: the page must show the images of this run only."""
    if not folder.is_dir():
        return
    for pattern in ("*-yours.png", "*-golden.png", "*-diff.png", "report.html"):
        for path in folder.glob(pattern):
            if path.is_file() and not path.is_symlink():
                path.unlink()


def print_progress(item: Item, test) -> None:
    """One line per check as it finishes (lab 03's speedup takes 15-50 s): the table at the
    end repeats them with what each saw."""
    if test is None:
        print(f"  {item.label} ...", end="", flush=True)
        return
    mark = "PASS" if test.passed else "not counted" if test.output.startswith(
        "not counted") else "FAIL"
    print(f" {mark} {test.score}/{test.max_score} ({test.seconds:.1f} s)", flush=True)


def build_lab(lab: str, sources: pathlib.Path | None = None, trusted: bool = True,
              notes: list[str] | None = None) -> tuple[pathlib.Path | None, str]:
    """Build ./labNN, or a submission's folder of sources as a student of lab NN would build
    it, in the students' tree (grading/students_tree.py; in the sandbox unless trusted,
    grading/compile.py says why); (binary, "") or (None, why: a one-line refusal or the
    compiler's first errors). `notes` receives what the grade should say about the hand-in
    (the expected files it lacked)."""
    if sources is not None:
        from grading.compile import build_in_sandbox
        target = "cuda-variant" if gpu.is_gpu_lab(lab) else "variant"
        binary, errors, note = build_in_sandbox(registry.lab(lab).folder, sources, target,
                                                trusted=trusted)
        if note and notes is not None:
            notes.append(note)
        if binary is None and errors.startswith("refused: "):
            return None, errors
        return binary, first_errors(errors) if errors else ""
    p = make_in_root(f"lab{lab}", capture_output=True, text=True, errors="replace")
    if p.returncode == 0:
        warnings = build_warnings(p.stdout + p.stderr)
        if warnings and notes is not None:
            notes.append(warnings)
        return ROOT / f"lab{lab}", ""
    return None, first_errors(p.stdout + p.stderr)


def part_a_binary(a, results: Results) -> pathlib.Path | str:
    """Lab 02's Part A binary for this grade (grading/checks/part_a.py), or why there is none."""
    if a.binary:
        if a.part_a and pathlib.Path(a.part_a).is_file():
            return pathlib.Path(a.part_a).resolve()
        return "no Part A binary was given (--part-a BINARY)"
    notes: list[str] = []
    binary, errors = part_a.build(pathlib.Path(a.sources) if a.sources else None, a.trusted,
                                  notes)
    results.notes.extend(notes)
    if binary is None:
        why = errors.removeprefix("refused: ") if errors.startswith("refused: ") else \
            f"Part A (part-a/vec3.h) does not compile: {first_errors(errors, 5)}"
        return why
    return binary.resolve()


def race_binary(a, results: Results) -> pathlib.Path | str:
    """Lab 03's ThreadSanitizer build for this grade (grading/checks/races.py), or why there is
    none."""
    if a.binary:
        if a.race_binary and pathlib.Path(a.race_binary).is_file():
            return pathlib.Path(a.race_binary).resolve()
        return "no ThreadSanitizer build was given (--race-binary BINARY)"
    binary, errors = races.build(registry.lab(a.lab).folder,
                                 pathlib.Path(a.sources) if a.sources else None, a.trusted)
    if binary is None:
        return errors.removeprefix("refused: ") if errors.startswith("refused: ") else \
            f"the ThreadSanitizer build (clang++) does not compile: {first_errors(errors, 5)}"
    return binary.resolve()


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("lab", choices=sorted(RUBRICS))
    p.add_argument("--binary", help="lab binary to grade (default: build ./labNN)")
    p.add_argument("--sources", help="a folder of submitted sources (render.cpp...) to build "
                                     "as lab NN, instead of ./labNN")
    p.add_argument("--results", default="results.json", help="where to write results.json")
    p.add_argument("--heatmaps", default="grading-heatmaps",
                   help="folder for diff heatmaps of failing image comparisons")
    p.add_argument("--trusted", action="store_true",
                   help="run the binary without the sandbox (your own code, at home)")
    p.add_argument("--run-seconds", type=float, default=RUN_SECONDS,
                   help=f"wall-clock limit of one run (default {RUN_SECONDS:g})")
    p.add_argument("--budget-seconds", type=float, default=BUDGET_SECONDS,
                   help=f"wall-clock budget of the whole grade (default {BUDGET_SECONDS})")
    p.add_argument("--part-a", help="with --binary: lab 02's Part A binary (./lab02a)")
    p.add_argument("--race-binary", help="with --binary: lab 03's ThreadSanitizer build "
                                         "(make lab03-race)")
    p.add_argument("--no-build", action="store_true",
                   help="run make for nothing: the references are built already (a batch "
                        "builds them once before its graders start side by side)")
    a = p.parse_args(argv)
    out = pathlib.Path(a.results)
    results = Results(path=out)
    results.add_all(Test(i.id, i.label, i.points, visibility=i.visibility)
                    for i in RUBRICS[a.lab])

    def interrupted(signum, _frame):
        raise KeyboardInterrupt(signal.Signals(signum).name)
    signal.signal(signal.SIGTERM, interrupted)
    if os.geteuid() == 0:  # OpenMPI refuses root unless told (trusted runs as root; the
        os.environ.setdefault("OMPI_ALLOW_RUN_AS_ROOT", "1")  # sandbox runs as nobody)
        os.environ.setdefault("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
    try:
        line = None if a.trusted else sandbox_problem(results)
        if line:  # one line, and a results.json that says the same
            print(f"error: {line}", file=sys.stderr)
            results.refuse(line, regrade=True)
            return 2
        if gpu.is_gpu_lab(a.lab) and (reason := gpu.missing_gpu()):
            line = no_gpu_line(a.lab, reason)  # one line, and a results.json that says it
            print(f"error: {line}", file=sys.stderr)
            results.refuse(line, regrade=True)
            return 2
        line = None if a.no_build else references.build(a.lab)
        if line:  # the machine's fault: one line, and a results.json marked for regrade
            print(f"error: {line}", file=sys.stderr)
            results.refuse(line, regrade=True)
            return 2
        if a.binary:
            binary = pathlib.Path(a.binary)
            if not binary.is_file():
                print(f"error: {binary}: no such binary", file=sys.stderr)
                results.refuse(f"no binary to grade: {binary} does not exist")
                return 2
        else:
            notes: list[str] = []
            binary, errors = build_lab(a.lab, pathlib.Path(a.sources) if a.sources else None,
                                       trusted=a.trusted, notes=notes)
            results.notes.extend(notes)
            for note in notes:
                if note.startswith("the build's warnings"):
                    print(note)
            if binary is None and errors.startswith("refused: "):
                results.refuse(f"the hand-in was {errors}")
                print(f"error: the hand-in was {errors}", file=sys.stderr)
                print_table(a.lab, pathlib.Path(f"lab{a.lab}"), results.as_dict())
                return 1
            if binary is None:
                results.refuse("the code does not compile", detail=errors)
                print_table(a.lab, pathlib.Path(f"lab{a.lab}"), results.as_dict())
                return 1
        parts = {}
        if part_a.has_part_a(a.lab):
            parts["a"] = part_a_binary(a, results)
        if registry.lab(a.lab).rubric in races.RUBRICS:
            parts["race"] = race_binary(a, results)
        heatmaps = pathlib.Path(a.heatmaps)
        clear_report(heatmaps)
        heatmaps.mkdir(parents=True, exist_ok=True)
        how_long = HOW_LONG.get(registry.lab(a.lab).rubric, "minutes")
        print(f"grading lab {a.lab}: {binary} ({how_long})", flush=True)
        grade(a.lab, binary.resolve(), heatmaps, trusted=a.trusted, results=results,
              budget_seconds=a.budget_seconds, run_seconds=a.run_seconds,
              progress=print_progress, parts=parts)
        print_table(a.lab, binary, results.as_dict())
        if a.trusted and (step := next_step(results.as_dict())):
            print(step)
        if not any(heatmaps.iterdir()):
            heatmaps.rmdir()
            print(f"wrote {out}")
        else:
            page = report_html.write_report(heatmaps, a.lab, str(a.binary or a.sources or binary),
                                            results.as_dict())
            print(f"wrote {out}; the images, diff heatmaps and {page}")
        return 2 if results.refused else 0
    except KeyboardInterrupt as e:
        results.interrupt(f"the grader was interrupted ({e or 'SIGINT'}) before it finished")
        print(f"interrupted; partial results in {out}", file=sys.stderr)
        return 130
    except Exception as e:  # a grader bug must still leave a results.json saying so
        results.interrupt(f"the grader failed: {type(e).__name__}: {e}")
        raise
    finally:
        results.write()


if __name__ == "__main__":
    sys.exit(main())
