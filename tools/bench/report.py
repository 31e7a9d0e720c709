"""The course report's Tables 4-7 for this machine (`make bench`).

    make bench                 every implementation this host runs, on the baseline (600x600,
                               512 spp, 4 bounces) and the three sweeps (size 150/300/600, spp
                               256/512/1024, bounces 2/4/8), best of 3: about 40 minutes a
                               round for the CPU labs on a busy two-core VM. SCALE=K divides
                               every image side by K (K*K less work) and the report says so.
    make bench QUICK=1         the CI size: sides / 5, spp / 4, one round (under a minute)
    python3 -m tools.bench.report --gpu-only --json-out gpu.json [--scale K | --quick]
                               on a GPU machine: only the CUDA labs, rows as JSON; needs
                               python3 with numpy and `make` (or built binaries, --bin-dir)
    python3 -m tools.bench.report --merge gpu.json --out DIR
                               adds those rows to the report already in DIR and redraws it

Time is the render time each binary reports (CUDA-event kernel time on the GPU labs). Runs
are interleaved: in each round, every setting in turn with every implementation at that
setting, so a busy spell hits all implementations alike; a row's time is its best round and
its spread (max - min) / min says how noisy the machine was. Speedup is over lab01-ref at the
same setting in the same run (merged GPU rows: over this report's lab01-ref, another machine's
CPU). Writes bench.json, bench.csv, bench.md and bench-*.png to --out. Exit 2: bad input or
a render that failed, with one line saying which.
"""
from __future__ import annotations

import argparse
import dataclasses
import json
import pathlib
import shutil
import subprocess
import sys

from labkit import registry
from labkit.harness import (
    ImageError,
    RunError,
    available_cores,
    cpu_has_avx2,
    measure_parallel,
    run_lab,
)
from labkit.mpi import mpirun
from tools.bench import report_data as report
from tools.tradeoff import report as tradeoff_report  # (Machine: CPU model, cores, date, load)
from tools.tradeoff import (
    series as tradeoff_series,  # (make, gpu_missing, gpu_info; also sets Open MPI's root switches)
)

ROOT = pathlib.Path(__file__).resolve().parents[2]

FORMAT = "bench-report rows v1"  # the JSON's "format": --merge refuses anything else


class BadInput(Exception):
    """One line for the user, exit status 2."""


class Parser(argparse.ArgumentParser):
    def error(self, message):  # one line, not argparse's usage block
        raise BadInput(message)


@dataclasses.dataclass(frozen=True)
class Impl:
    binary: str
    label: str
    avx2: bool = False        # needs AVX2 + FMA at run time (lab 02 Part B's packets)
    threads: bool = False     # takes --threads (one per core)

    @property
    def gpu(self) -> bool:
        """Renders on a GPU: its lab's kind in labs/labs.toml."""
        return registry.owner(self.binary).kind == "gpu"

    @property
    def mpi(self) -> bool:
        """Runs under mpirun, one rank per core: its lab's kind in labs/labs.toml."""
        return registry.owner(self.binary).kind == "mpi"


IMPLS = [
    Impl("lab01-ref", "serial"),
    Impl("lab02a-ref", "SIMD A: SSE Vec3, 1 thread"),
    Impl("lab02-ref", "SIMD B: AVX2 8 paths per packet, 1 thread", avx2=True),
    Impl("lab03-ref", "OpenMP, every core", threads=True),
    Impl("lab03-simd-ref", "OpenMP + AVX2 packets, every core", avx2=True, threads=True),
    Impl("lab04-ref", "MPI, one rank per core"),
    Impl("lab04-simd-ref", "MPI + AVX2 packets, one rank per core", avx2=True),
    Impl("lab05-ref", "CUDA megakernel"),
    Impl("lab06-ref", "CUDA split kernels (wavefront)"),
    Impl("lab07-ref", "CUDA split kernels, SoA"),
]
BY_NAME = {i.binary: i for i in IMPLS}
SERIAL = "lab01-ref"


@dataclasses.dataclass(frozen=True)
class Plan:
    """The report's settings, with image sides divided by size_div and spp by spp_div."""
    name: str
    size_div: int
    spp_div: int
    repeat: int

    def setting(self, size: int, spp: int, bounces: int) -> tuple[int, int, int]:
        return (max(1, round(size / self.size_div)), max(1, spp // self.spp_div), bounces)

    def experiments(self) -> dict[str, list[tuple[object, tuple[int, int, int]]]]:
        """experiment -> [(the report's setting value, (side, spp, bounces) run here)]"""
        b = report.BASELINE
        out = {"baseline": [(None, self.setting(b["size"], b["spp"], b["bounces"]))]}
        for exp, values in report.SWEEPS.items():
            out[exp] = [(v, self.setting(**{**b, exp: v})) for v in values]
        return out

    def settings(self) -> list[tuple[int, int, int]]:
        """Every distinct setting once (the baseline is also a point of each sweep)."""
        seen = []
        for points in self.experiments().values():
            seen += [s for _, s in points if s not in seen]
        return seen

    def describe(self) -> str:
        parts = []
        if self.size_div != 1:
            parts.append(f"image sides / {self.size_div}")
        if self.spp_div != 1:
            parts.append(f"spp / {self.spp_div}")
        scaled = "the report's settings" + (f" with {', '.join(parts)}" if parts else "")
        return f"{self.name}: {scaled}, best of {self.repeat}"


def plan_from(quick: bool, scale: int | None, repeat: int | None) -> Plan:
    if quick:
        # CI: 30/60/120-pixel images at 64/128/256 spp, one round: about 30 s of rendering
        # (all CPU labs) on a busy two-core VM, where the full plan is about 40 minutes a round.
        p = Plan("quick (CI size)", 5, 4, 1)
    else:
        p = Plan("full", 1, 1, 3)
    if scale is not None:
        if scale < 1 or 150 / scale < 4:
            raise BadInput(f"--scale {scale}: must be 1..37 (the 150-pixel image must keep "
                           "at least 4 pixels a side)")
        p = dataclasses.replace(p, name=p.name + f", scale {scale}", size_div=scale)
    if repeat is not None:
        if repeat < 1:
            raise BadInput(f"--repeat {repeat}: must be at least 1")
        p = dataclasses.replace(p, repeat=repeat)
    return p


# ---- which implementations run here ----------------------------------------------------------

def why_not(impl: Impl, bin_dir: pathlib.Path | None) -> str | None:
    """Why `impl` cannot run here, or None (then its binary is ready)."""
    if impl.gpu and tradeoff_series.gpu_missing():
        return tradeoff_series.gpu_missing()
    if impl.avx2 and not cpu_has_avx2():
        return "this CPU lacks AVX2/FMA"
    if impl.mpi and shutil.which("mpirun") is None:
        return "no mpirun on this machine"
    if bin_dir is not None:  # binaries built elsewhere: use what is there, build nothing
        return None if (bin_dir / impl.binary).is_file() else f"no binary {bin_dir / impl.binary}"
    return tradeoff_series.make(impl.binary)


def choose(names: list[str] | None, gpu_only: bool, bin_dir, log) -> tuple[list, dict]:
    """(implementations to run, {binary: why not} for the rest). A lab named with --labs
    that cannot run is bad input; lab01-ref must run unless only the GPU labs are wanted."""
    wanted = [BY_NAME[n] for n in names] if names else [i for i in IMPLS
                                                       if i.gpu or not gpu_only]
    if gpu_only:
        wanted = [i for i in wanted if i.gpu]
        if not wanted:
            raise BadInput("--gpu-only: --labs names no GPU lab (lab05-ref, lab06-ref, lab07-ref)")
    elif SERIAL not in [i.binary for i in wanted]:
        wanted.insert(0, BY_NAME[SERIAL])  # every speedup is over it
    run, skipped = [], {}
    for impl in wanted:
        log(f"  {impl.binary}: checking{' (make)' if bin_dir is None else ''}")
        why = why_not(impl, bin_dir)
        if why and (names and impl.binary in names or impl.binary == SERIAL):
            raise BadInput(f"{impl.binary}: {why}")
        if why:
            skipped[impl.binary] = why
        else:
            run.append(impl)
    return run, skipped


# ---- measuring --------------------------------------------------------------------------------

def render(impl: Impl, path: pathlib.Path, setting) -> dict:
    side, spp, bounces = setting
    cores = available_cores()
    try:
        r = run_lab(path, width=side, height=side, spp=spp, bounces=bounces, seed=1,
                    threads=cores if impl.threads else (1 if impl.mpi else None),
                    launcher=mpirun(cores) if impl.mpi else ())
    except (RunError, ImageError) as e:
        raise RuntimeError(f"{impl.binary} at {side}x{side}, {spp} spp, {bounces} bounces: "
                           f"{str(e).strip().splitlines()[0]}") from None
    if not r.json or not isinstance(r.json.get("seconds"), (int, float)):
        raise RuntimeError(f"{impl.binary}: printed no --json line with 'seconds'")
    return r.json


def capacity(serial: Impl, bin_dir: pathlib.Path, setting) -> float:
    """Cores' worth of throughput this run gets now: one lab01-ref render against one per
    core at once (labkit.harness.measure_parallel, as the grader measures it). On a shared
    machine it is what bounds every parallel lab's speedup in the same round."""
    one = lambda: render(serial, bin_dir / serial.binary, setting)["seconds"]  # noqa: E731
    return measure_parallel(one, {}, rounds=1).capacity


def measure(plan: Plan, impls: list[Impl], bin_dir: pathlib.Path, log) -> tuple[list, list]:
    """(rows {binary, label, side, spp, bounces, seconds (best), runs, device}, capacity per
    round): rounds outermost, then settings, then implementations (interleaved, see the
    module's doc)."""
    settings = plan.settings()
    runs: dict[tuple, list[float]] = {}
    device: dict[tuple, str] = {}
    caps = []
    serial = next((i for i in impls if i.binary == SERIAL), None)
    smallest = min(settings, key=lambda s: s[0] * s[0] * s[1] * s[2])
    for rnd in range(plan.repeat):
        if serial is not None and available_cores() > 1:
            caps.append(capacity(serial, bin_dir, smallest))
            log(f"  round {rnd + 1}/{plan.repeat}: capacity {caps[-1]:.2f} of "
                f"{available_cores()} cores")
        for setting in settings:
            line = []
            for impl in impls:
                j = render(impl, bin_dir / impl.binary, setting)
                runs.setdefault((impl.binary, setting), []).append(float(j["seconds"]))
                device[(impl.binary, setting)] = str(j.get("device", ""))
                line.append(f"{impl.binary} {j['seconds']:.3f}")
            side, spp, b = setting
            log(f"  round {rnd + 1}/{plan.repeat}, {side}x{side} {spp} spp {b} bounces: "
                + ", ".join(line))
    rows = []
    for impl in impls:
        for setting in settings:
            t = runs[(impl.binary, setting)]
            rows.append({"binary": impl.binary, "label": impl.label, "gpu": impl.gpu,
                         "side": setting[0], "spp": setting[1], "bounces": setting[2],
                         "seconds": min(t), "runs": t, "device": device[(impl.binary, setting)]})
    return rows, caps


def machine_dict() -> dict:
    m = tradeoff_report.Machine.here()
    return {"cpu": m.cpu, "cores": m.cores, "date": m.date, "load_before": m.load_before,
            "gpu": tradeoff_series.gpu_info()}


# ---- the JSON a report is made from (and --gpu-only writes) -----------------------------------

def load_rows_json(path: pathlib.Path, what: str) -> dict:
    try:
        data = json.loads(path.read_text())
    except OSError as e:
        raise BadInput(f"{what} {path}: cannot read it ({e.strerror or e})") from None
    except ValueError as e:
        raise BadInput(f"{what} {path}: not JSON ({e})") from None
    if not isinstance(data, dict) or data.get("format") != FORMAT:
        raise BadInput(f"{what} {path}: not rows written by tools/bench/report.py "
                       f"(no \"format\": \"{FORMAT}\")")
    for r in data.get("rows", []):
        ok = (isinstance(r, dict) and isinstance(r.get("binary"), str)
              and all(isinstance(r.get(k), int) for k in ("side", "spp", "bounces"))
              and isinstance(r.get("seconds"), (int, float)) and r["seconds"] > 0)
        if not ok:
            raise BadInput(f"{what} {path}: a row lacks binary/side/spp/bounces or a positive "
                           f"seconds: {json.dumps(r)[:120]}")
    return data


def merge(out: pathlib.Path, gpu_json: pathlib.Path) -> dict:
    """The report in `out` with the rows of `gpu_json` added (replacing rows of the same
    binary). The GPU rows must be at this report's settings: speedups divide by its lab01-ref."""
    extra = load_rows_json(gpu_json, "--merge")
    base = load_rows_json(out / "bench.json", "--out (the report to add to)")
    if [extra["plan"][k] for k in ("size_div", "spp_div")] != \
            [base["plan"][k] for k in ("size_div", "spp_div")]:
        raise BadInput(f"--merge {gpu_json}: measured with plan {extra['plan']['name']!r} "
                       f"(sides / {extra['plan']['size_div']}, spp / {extra['plan']['spp_div']})"
                       f", the report with {base['plan']['name']!r}; run --gpu-only with the "
                       "same --quick/--scale")
    names = {r["binary"] for r in extra["rows"]}
    base["rows"] = [r for r in base["rows"] if r["binary"] not in names] + extra["rows"]
    base["skipped"] = {k: v for k, v in base.get("skipped", {}).items() if k not in names}
    # An earlier merge's note keeps only the binaries whose rows are still its own.
    earlier = [{**m, "binaries": [b for b in m["binaries"] if b not in names]}
               for m in base.get("merged", [])]
    base["merged"] = [m for m in earlier if m["binaries"]] + [
        {"machine": extra["machine"], "binaries": sorted(names)}]
    return base


def main(argv=None) -> int:
    p = Parser(description=__doc__.splitlines()[0])
    p.add_argument("--quick", action="store_true", help="the CI size (QUICK=1)")
    p.add_argument("--scale", type=int, help="divide every image side by K")
    p.add_argument("--repeat", type=int, help="rounds; the best counts (default 3, quick 1)")
    p.add_argument("--out", default=str(ROOT / "build" / "reports" / "bench"),
                   help="folder for bench.json/.csv/.md/*.png (default build/reports/bench)")
    p.add_argument("--labs", help="comma-separated binaries to run (default: all that run here)")
    p.add_argument("--bin-dir", help="use the binaries in this folder; build nothing")
    p.add_argument("--gpu-only", action="store_true",
                   help="run only the GPU labs and write their rows as JSON (--json-out)")
    p.add_argument("--json-out", help="where --gpu-only writes its rows")
    p.add_argument("--merge", metavar="JSON", help="add --gpu-only rows to the report in --out")
    p.add_argument("--redraw", action="store_true",
                   help="rewrite the CSV, Markdown and plots in --out from its bench.json "
                   "(with --note: replacing its note)")
    p.add_argument("--note", default="", help="a line for the report (e.g. how busy the "
                   "machine was)")
    log = lambda *args: print(*args, flush=True)  # noqa: E731
    try:
        a = p.parse_args(argv)
        names = [n.strip() for n in a.labs.split(",") if n.strip()] if a.labs else None
        unknown = [n for n in names or [] if n not in BY_NAME]
        if unknown:
            raise BadInput(f"--labs: unknown {', '.join(unknown)} (known: "
                           f"{', '.join(BY_NAME)})")
        bin_dir = pathlib.Path(a.bin_dir).resolve() if a.bin_dir else None
        if bin_dir is not None and not bin_dir.is_dir():
            raise BadInput(f"--bin-dir {a.bin_dir}: no such folder")
        if a.gpu_only and not a.json_out:
            raise BadInput("--gpu-only needs --json-out FILE (where its rows go)")
        if a.merge and (a.gpu_only or a.labs):
            raise BadInput("--merge only redraws a report: give it --out, not --gpu-only/--labs")
        out = pathlib.Path(a.out)
        if a.redraw:
            from tools.bench import report_output  # matplotlib: only where the report is drawn
            data = load_rows_json(out / "bench.json", "--out")
            if a.note:
                data["note"] = a.note
            report_output.write_all(out, data)
            log(f"bench: redrew {out / 'bench.md'}")
            return 0
        if a.merge:
            data = merge(out, pathlib.Path(a.merge))
            from tools.bench import report_output  # matplotlib: only where the report is drawn
            report_output.write_all(out, data)
            log(f"bench: merged {a.merge} into {out / 'bench.md'}")
            return 0
        plan = plan_from(a.quick, a.scale, a.repeat)
        if not a.gpu_only:
            try:
                from tools.bench import report_output  # noqa: F401  (checked before minutes of rendering)
            except ImportError:
                raise BadInput(
                    "matplotlib is not installed for this python: run `make deps`") from None
            if problem := tradeoff_report.cannot_write(out):
                raise BadInput(problem)
        machine = machine_dict()
        log(f"bench ({plan.describe()}) on {machine['cpu']}, {machine['cores']} cores"
            + (f", {machine['gpu']}" if machine["gpu"] else "") + f", {machine['date']}")
        impls, skipped = choose(names, a.gpu_only, bin_dir, log)
        for b, why in skipped.items():
            log(f"  not measured: {b}: {why}")
        if a.gpu_only and not impls:
            raise BadInput("--gpu-only: no GPU lab runs here: " + "; ".join(
                f"{b}: {w}" for b, w in skipped.items()))
        rows, caps = measure(plan, impls, bin_dir or ROOT, log)
        machine["load_after"] = tradeoff_report.load()
        machine["capacity"] = caps
        data = {"format": FORMAT, "plan": dataclasses.asdict(plan), "machine": machine,
                "note": a.note, "rows": rows, "skipped": skipped}
        if a.gpu_only:
            path = pathlib.Path(a.json_out)
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_text(json.dumps(data, indent=1) + "\n")
            log(f"bench: {len(rows)} GPU rows in {path}; merge them with "
                f"python3 -m tools.bench.report --merge {path.name} --out REPORT_DIR")
            return 0
        from tools.bench import report_output
        report_output.write_all(out, data)
        log(f"bench: report in {out / 'bench.md'}")
        return 0
    except BadInput as e:
        print(f"bench: error: {e}", file=sys.stderr)
        return 2
    except (RuntimeError, ValueError, OSError, subprocess.SubprocessError) as e:
        print(f"bench: error: {str(e).strip().splitlines()[0]}", file=sys.stderr)
        return 2



if __name__ == "__main__":
    sys.exit(main())
