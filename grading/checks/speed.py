"""Timed renders: the scene drawn for them, the speedup over a reference and its partial
credit, and whether a program ran in parallel (CPU time over wall time, thread by thread)."""
from __future__ import annotations

import os
import pathlib
import time

import numpy as np

from grading.checks import draws, hidden
from grading.checks.check_result import LAB01_REFERENCE, CheckResult, image_checked
from grading.checks.graded_scenes import TIMED_SCENE, timed_scene
from labkit.compare import compare
from labkit.harness import golden, run_lab


def timed_settings(spp: int, scene: pathlib.Path, scale: int = 1) -> dict:
    """The timed render of `scene` (timed_scene()) at `scale` times the golden image's width
    and height, at a seed drawn from the secret."""
    g = golden(TIMED_SCENE)
    return dict(scene=scene, width=g.meta["width"] * scale, height=g.meta["height"] * scale,
                bounces=g.meta["bounces"], seed=draws.seed("timed"), spp=spp)


def timed_golden(scene: pathlib.Path, reference=LAB01_REFERENCE) -> tuple:
    """(mean, variance, golden_spp) of the drawn timed scene, rendered now by the trusted
    reference at the golden size (grading/checks/hidden.py's make_golden)."""
    g = golden(TIMED_SCENE)
    made = hidden.make_golden(reference, scene, size=g.meta["width"], bounces=g.meta["bounces"])
    return made.mean, made.variance, made.golden_spp


def box_filtered(image: np.ndarray, scale: int) -> np.ndarray:
    """Each scale x scale block of pixels averaged into one pixel. A pixel's paths jitter
    uniformly over its area, so the average of a block rendered at n spp is an estimate of the
    large pixel's value from scale^2 n paths, stratified over its area: its variance is at most
    that of scale^2 n unstratified paths, and the golden comparison at that spp stays valid
    (conservative)."""
    h, w, c = image.shape
    blocks = image.reshape(h // scale, scale, w // scale, scale, c).astype(np.float64)
    return blocks.mean(axis=(1, 3)).astype(np.float32)


def wrong_timed_image(image, spp: int, scale: int = 1, reference: tuple | None = None
                      ) -> str | None:
    """Why a timed render is not a correct image of its scene, or None: speed is graded only
    for correct work, on the very runs that were timed. `reference` is the scene's (mean,
    variance, golden_spp) (timed_golden); by default the stored golden Cornell box's."""
    if reference is None:
        g = golden(TIMED_SCENE)
        reference = (g.mean, g.variance, g.meta["golden_spp"])
    report = compare(box_filtered(image, scale) if scale > 1 else image, spp * scale * scale,
                     *reference, per_pixel=scale == 1)
    return None if report.passed else f"the timed render is wrong ({report.summary()})"


# Speed earns partial credit: full points at or above the bar, falling linearly to none at
# ZERO_CREDIT_AT times the bar (grading/README.md). For a parallel lab on two cores (bar
# 1.46x) that is 1.10x, where a serial program is; the CPU-time evidence below stops a serial
# program from earning anything by noise.
ZERO_CREDIT_AT = 0.75


def speed_credit(measured: float, bar: float) -> float:
    """The fraction of a speed check's points for `measured` against `bar` (NaN earns 0)."""
    floor = ZERO_CREDIT_AT * bar
    if not (measured > floor):
        return 0.0
    return min(1.0, (measured - floor) / (bar - floor))


def credit_note(credit: float, bar: float) -> str:
    if credit >= 1.0:
        return ""
    return (f"; {credit:.0%} of the points (full at {bar:.2f}x, none at or below "
            f"{ZERO_CREDIT_AT * bar:.2f}x)")


def cores_used(run) -> float:
    """CPU time over wall time of a run's whole process tree, both measured by the grader."""
    if run.cpu_seconds is None or not run.wall_seconds > 0:
        return float("nan")
    return run.cpu_seconds / run.wall_seconds


def one_cpu() -> int:
    """The CPU lab 02's timed runs are confined to (its lesson is SIMD, not threads). The
    sandbox refuses widening the affinity again (sandbox.Limits.cpu), so threads share that
    CPU and earn nothing; their CPU time is not judged (a serial hand-in whose wrapper script
    does some of the work would look threaded by it)."""
    return min(os.sched_getaffinity(0))


# A program whose tree never used more CPU time than this many times its wall time did not
# run in parallel (a serial renderer measures 0.95-1.0 cores on a quiet machine; a correct
# parallel one on two cores ~1.9, ~1.3 beside a process burning one of them). On a machine
# others load, every thread gets a share of a core: there the parallel check compares the
# cores a program used with those the serial reference used in the same round.
SERIAL_CORES = 1.1


# The reference runs twice a round, before and after the program, and the speedup is over
# the best of all its runs: a load that slowed only some of them does not make the program
# look faster. How far its two series' bests lie apart (at least 1) says how much a ratio
# measured then may be off; where the credit differs between the speedup divided and
# multiplied by that, the rounds are measured again, up to `attempts` times, and failing
# that the lower credit counts and the rest is left to a regrade (grading/README.md has the
# measurement that called for it).


@image_checked("speedup")
def check_speedup(binary, baseline, min_speedup: float, *, threads=None, launcher=(),
                  repeat: int = 3, spp: int = 256, scale: int = 1, attempts: int = 3,
                  overhead_reference=None, one_core: bool = False) -> CheckResult:
    """Wall-clock time against a baseline binary (the lab-01 reference; a GPU lab's own
    reference), measured by the grader around each whole process (never the `seconds` a
    program reports about itself), interleaved, best of `repeat` rounds, the reference before
    and after the program in each: a ratio, so a busy machine slows both sides alike, and a
    ratio the reference's own two series disagree about is measured again or left to a
    regrade (see above). Every timed image must match the golden image, or there is no
    speed to grade. `scale` renders the golden view that many times larger (checked box-
    filtered down to the golden size); `overhead_reference` (a trusted binary) measures a
    start-up cost, rendering one pixel, that is subtracted from both sides (launch_overhead).
    `one_core` (lab 02): both sides run confined to one CPU, which they cannot widen (threads
    are not the lesson: they share that CPU and gain nothing). Both sides render the timed
    scene drawn for this grade (timed_scene), whose golden data the trusted lab-01 reference
    renders first. Points: speed_credit of the speedup."""
    name = f"speedup >= {min_speedup:g}x"
    pinned = one_cpu() if one_core else None
    overhead = launch_overhead(overhead_reference, launcher) if overhead_reference else 0.0
    note = (f", less {overhead:.3f} s of start-up measured on the reference rendering one pixel"
            if overhead else "")
    where = ", both on one CPU" if one_core else ""
    with timed_scene() as scene:
        settings = timed_settings(spp, scene, scale)
        reference = timed_golden(scene)

        def reference_run() -> float:
            run = run_lab(baseline, cpu=pinned, **settings)
            return max(run.wall_seconds - overhead, 1e-3)

        for attempt in range(1, attempts + 1):
            before, after, fast = [], [], []
            for _ in range(repeat):
                before.append(reference_run())
                run = run_lab(binary, threads=threads, launcher=launcher, cpu=pinned,
                              **settings)
                wrong = wrong_timed_image(run.image, spp, scale, reference)
                if wrong:
                    return CheckResult(name, False,
                                       f"{wrong}: speed is graded only for a correct image",
                                       credit=0.0)
                fast.append(max(run.wall_seconds - overhead, 1e-3))
                after.append(reference_run())
            base = min(before + after)
            speedup = base / min(fast)
            unsteady = max(min(before), min(after)) / base
            low = speed_credit(speedup / unsteady, min_speedup)
            high = speed_credit(speedup * unsteady, min_speedup)
            if low == high:
                break
            if attempt < attempts:
                time.sleep(2.0 * attempt)  # let the other load pass
    detail = (f"{speedup:.2f}x ({base:.3f} s -> {min(fast):.3f} s wall clock measured by the "
              f"grader{note}{where}, best of {repeat} rounds, the reference twice a round)")
    if low != high:
        return CheckResult(name, low > 0,
                           f"{detail}: the reference's best before and after the program lay "
                           f"{unsteady - 1:.1%} apart, too unsteady to tell {low:.0%} of the "
                           f"points from {high:.0%} in {attempts} attempts; {low:.0%} now, the "
                           f"rest marked for regrade", regrade=True, credit=low,
                           provisional=1.0 - low)
    return CheckResult(name, low > 0, detail + credit_note(low, min_speedup), credit=low)


def launch_overhead(reference, launcher, rounds: int = 3) -> float:
    """Seconds a launcher (mpirun) and MPI start-up add to a run, measured on a trusted
    reference binary rendering one pixel: subtracted from the candidate's wall-clock time so
    that a fixed start-up of ~0.5 s does not hide a parallel speedup."""
    return min(run_lab(reference, width=1, height=1, spp=1, launcher=launcher).wall_seconds
               for _ in range(rounds))


# On a machine giving fewer than BUSY cores' worth of throughput (a quiet two-core machine
# gives 1.9-2.0) a missed bar may be the machine's fault: under bursts of other load the
# reference measured 0.95x with 1.79x capacity measured in the same rounds, and ~1x under a
# steady load of 9 on two cores. Such a result is measured again and, failing that, marked
# for regrade, with only the points measured in the score. Whether the program runs in
# parallel at all is told apart from the load two ways. Thread by thread, at any load: a
# program one of whose threads did ONE_THREAD of its timed runs' CPU time is serial (a
# serial renderer's one thread does all of it; a parallel one's busiest thread about 1/T of
# it, however few cores it got). By CPU time over wall time: where the machine gave at least
# SERIAL_TELLABLE cores' worth, a parallel program uses more than SERIAL_CORES of them (CFS
# shares the CPUs by thread), a serial one cannot.
BUSY = 1.9
SERIAL_TELLABLE = 1.25
QUOTA_TOO_SMALL = 1.5  # cores' worth of CPU (count or cgroup quota) below which nothing is timed
ONE_THREAD = 0.9
# A speedup this many times the capacity measured in the same rounds is impossible: a
# program cannot get more from the cores than n copies of the serial reference do, beyond
# noise and a faster serial path. One that does read something it had kept (its own first
# render, another run's image) or slowed the reference: refused, never scored.
IMPOSSIBLE = 1.5
# Threads that take turns (an `ordered` loop body, one `critical` around the work, a lock held
# while tracing): the work is shared among the threads, so no thread did ONE_THREAD of it, and
# while they wait they may spin, so the CPU time says "parallel"; only the speed tells. Where
# the same rounds measured at least TURNS_CAPACITY cores' worth for n copies of the serial
# reference (room for a parallel program) and the program's best speedup stays at most
# TURNS_SPEEDUP, the verdict is final: a machine that busy still gives the reference ~1.4x.
TURNS_CAPACITY = 1.5
TURNS_SPEEDUP = 1.15


def busiest_thread_share(run) -> float:
    """The fraction of a run's CPU time that its busiest thread did (both measured by the
    grader from /proc, sandbox.TreeClock); NaN where nothing was measured."""
    return run.thread_share


def one_thread_did_it(shares: list[float]) -> bool:
    """Every timed run did at least ONE_THREAD of its work on one thread (none unmeasured)."""
    return bool(shares) and all(share >= ONE_THREAD for share in shares)


def serial_by_thread(shares: list[float], where: str, timed: str = "") -> CheckResult:
    """The verdict on a program whose one thread did the work; `timed`: what the timed runs
    measured, where they ran (the class page shows those numbers beside the verdict)."""
    return CheckResult("parallel speedup", False,
                       f"serial: in every timed run one thread did at least {ONE_THREAD:.0%} "
                       f"of the CPU time ({min(shares):.0%} at the least; measured by the "
                       f"grader, thread by thread, {where}); a parallel program shares its work "
                       f"among its threads" + (f" (timed: {timed})" if timed else ""),
                       credit=0.0)


@image_checked("parallel speedup")
def check_parallel_speedup(binary, baseline, *, threads=None, launcher=(),
                           fraction: float = 0.75, spp: int = 512, attempts: int = 3,
                           overhead_reference=None) -> CheckResult:
    """Speedup of a parallel lab over the serial baseline, in wall-clock time measured by the
    grader, against the machine's capacity measured alongside (labkit.harness.
    measure_parallel), on the timed scene drawn for this grade (timed_scene). Every timed
    image must be the baseline's, bit for bit (what labs 03 and 04 promise). It fails closed:
    - a program one of whose threads did ONE_THREAD of every timed run's CPU time is serial,
      at any load and capacity (even where nothing is timed): no points, not a regrade;
    - so is a program whose timed runs never used more than SERIAL_CORES cores' worth of CPU
      time (the grader's own measurement of the sandboxed tree) nor more than SERIAL_CORES
      times the serial reference's share in the same rounds, on a machine giving at least
      SERIAL_TELLABLE;
    - points follow speed_credit of the speedup against the bar; where the machine stays too
      busy to reach a verdict, the test is marked for regrade and only the points measured
      count: the rest is shown apart, never in the score."""
    with timed_scene() as scene:
        return _parallel_speedup(binary, baseline, timed_settings(spp, scene), threads=threads,
                                 launcher=launcher, fraction=fraction, attempts=attempts,
                                 overhead_reference=overhead_reference)


def _parallel_speedup(binary, baseline, settings: dict, *, threads, launcher, fraction: float,
                      attempts: int, overhead_reference) -> CheckResult:
    import threading

    from labkit.harness import cpu_capacity, measure_parallel
    capacity_here = cpu_capacity()
    if capacity_here < QUOTA_TOO_SMALL:
        # Nothing to time: no program can show a speedup here. One run shows whether the work
        # is one thread's (serial: final here too); else correctness is graded (the checks
        # gated on this one open) and the speed left to a regrade on a course machine.
        try:
            run = run_lab(binary, threads=threads, launcher=launcher, check=False, **settings)
        except OSError:  # the binary cannot even be staged: nothing to tell
            run = None
        # Only a run that rendered tells whose work a render is (a crash is one thread's too).
        shares = [busiest_thread_share(run)] if run and run.image is not None else []
        if one_thread_did_it(shares):
            return serial_by_thread(shares, f"on a machine giving {capacity_here:g} cores' worth")
        return CheckResult("parallel speedup", True,
                           f"not timed: this machine gives {capacity_here:g} cores' worth of CPU "
                           f"time (CPU count, cgroup cpu.max), too few to show a parallel "
                           f"speedup; correctness graded, speed marked for regrade on a machine "
                           f"with 2 or more", regrade=True, credit=0.0, provisional=1.0)
    want: list[bytes] = []
    wrong: list[str] = []
    used: list[float] = []       # cores' worth of CPU time of each of your timed runs
    shares: list[float] = []     # the share of each of your timed runs' busiest thread
    base_used: list[float] = []  # the same of the serial reference run alone, same rounds
    overhead = launch_overhead(overhead_reference, launcher) if overhead_reference else 0.0

    def base() -> float:
        run = run_lab(baseline, **settings)
        if not want:
            want.append(run.image.tobytes())
        if threading.current_thread() is threading.main_thread():  # alone, not the capacity's
            base_used.append(cores_used(run))
        return run.wall_seconds

    def yours() -> float:
        run = run_lab(binary, threads=threads, launcher=launcher, **settings)
        if want and run.image.tobytes() != want[0] and not wrong:
            wrong.append("the timed render differs from the serial reference's image (the bit "
                         "check says why)")
        used.append(cores_used(run))
        shares.append(busiest_thread_share(run))
        return max(run.wall_seconds - overhead, 1e-3)

    def copies(n: int) -> float:
        """n copies of the baseline at once as one process tree (one session, as a parallel
        program is: measure_parallel says why)."""
        run = run_lab(baseline, launcher=together_launcher(n), check=False, **settings)
        return run.wall_seconds

    def share() -> float:
        """Cores your runs used over the cores the serial reference used in the same rounds
        (the median over rounds): ~1 for a serial program whatever the load, NaN unknown."""
        ratios = sorted(y / b for y, b in zip(used, base_used) if b > 0)
        return ratios[len(ratios) // 2] if ratios else float("nan")

    def parallel() -> bool:
        """Shown to run on more than one core: a run used more than SERIAL_CORES cores' worth
        of CPU time (one thread cannot use more than one core, whatever the load), or the runs
        got more than SERIAL_CORES times the serial reference's share of a busy machine."""
        return max(used, default=0.0) > SERIAL_CORES or share() > SERIAL_CORES

    def threaded() -> bool:
        """Evidence enough to grade correctness while the speed waits for a regrade: shown
        parallel, or the work shared among threads (which a busy machine may have run on one
        core's worth; a regrade on a quiet machine tells)."""
        return parallel() or (bool(shares) and max(shares) < ONE_THREAD)

    note = f" (launch overhead {overhead:.3f} s subtracted)" if overhead else ""
    best = None  # (credit, timing) of the attempt closest to the bar
    capacity = 0.0
    for attempt in range(1, attempts + 1):
        timing = measure_parallel(base, {"yours": yours}, together=copies)
        capacity = max(capacity, timing.capacity)
        if wrong:
            return CheckResult("parallel speedup", False,
                               f"{wrong[0]}: speed is graded only for a correct image", credit=0.0)
        if timing.speedup("yours") > IMPOSSIBLE * timing.capacity:
            return CheckResult("parallel speedup", False,
                               f"impossible: {timing.describe('yours')}; more than "
                               f"{IMPOSSIBLE:g} times the capacity no program can get from the "
                               f"machine, so not a speedup: refused, no points", credit=0.0)
        if one_thread_did_it(shares):
            return serial_by_thread(shares, f"{max(used):.2f} cores' worth at most, on a "
                                            f"machine giving {capacity:.2f}",
                                    f"{timing.describe('yours')}{note}")
        if not parallel() and capacity >= SERIAL_TELLABLE:
            return CheckResult("parallel speedup", False,
                               f"serial: the timed runs used at most {max(used):.2f} cores' "
                               f"worth of CPU time, {share():.2f}x the serial reference's share "
                               f"(measured by the grader), on a machine giving {capacity:.2f} "
                               f"cores' worth; a parallel program uses more than "
                               f"{SERIAL_CORES:g} ({timing.describe('yours')}{note})", credit=0.0)
        if timing.capacity >= 1.5:
            credit = speed_credit(timing.speedup("yours"), timing.required(fraction))
            if best is None or credit > best[0]:
                best = (credit, timing)
            if credit >= 1 or timing.capacity >= BUSY:
                break  # reached the bar, or measured on a machine quiet enough to judge
        if attempt < attempts:
            time.sleep(2.0 * attempt)  # let the other load pass
    if best is None:
        return CheckResult("parallel speedup", threaded(),
                           f"not measurable: the machine gave only {capacity:.2f} cores' worth "
                           f"of throughput in {attempts} attempts (the timed runs used "
                           f"{share():.2f}x the serial reference's CPU share, their busiest "
                           f"thread {max(shares, default=float('nan')):.0%} of their CPU time); "
                           f"no points now, marked for regrade",
                           regrade=True, credit=0.0, provisional=1.0)
    credit, timing = best
    bar = timing.required(fraction)
    detail = timing.describe("yours") + note + credit_note(credit, bar)
    if took_turns(timing.speedup("yours"), timing.capacity, shares):
        return CheckResult("parallel speedup", False,
                           f"the threads ran one at a time: the work was shared among them "
                           f"(the busiest thread did {max(shares):.0%} of the CPU time) but "
                           f"the best speedup was {timing.speedup('yours'):.2f}x where the "
                           f"machine gave {timing.capacity:.2f} cores' worth in the same rounds; "
                           f"an ordered loop body, a critical section or a lock around the work "
                           f"makes them wait for each other ({detail})", credit=0.0)
    if credit < 1 and timing.capacity < BUSY:
        return CheckResult("parallel speedup", credit > 0 or threaded(),
                           f"short of the bar on a machine too busy to judge ({detail}); "
                           f"marked for regrade", regrade=True, credit=credit,
                           provisional=1.0 - credit)
    return CheckResult("parallel speedup", credit > 0, detail, credit=credit)


def took_turns(speedup: float, capacity: float, shares: list[float]) -> bool:
    """Threads that shared the work but ran one at a time (see TURNS_CAPACITY): a final
    verdict, not the machine's fault."""
    return (capacity >= TURNS_CAPACITY and speedup <= TURNS_SPEEDUP and bool(shares)
            and max(shares) < ONE_THREAD)


def together_launcher(n: int) -> list[str]:
    """A launcher running its command n times at once and waiting for all of them."""
    return ["/bin/sh", "-c", f'i=0; while [ $i -lt {n} ]; do "$@" & i=$((i + 1)); done; wait',
            "copies"]
