"""Where the lab-01 reference's work goes, counted rather than timed.

    python3 -m tools.bench.count_work [--width 60 --height 60 --spp 16]

Builds a copy of the lab-01 reference in which closest_hit and occluded are not inlined, runs
it under valgrind's callgrind (instructions, and branches through callgrind's simple
predictor model), and prints the instructions of a camera path split into closest-hit
queries, shadow queries and the rest (camera, shading, sampling, RNG, the sum).

Why count: on a shared VM the render time of one build drifts by +-20% over minutes, so a 5%
change to the path loop is lost in the timing noise. Instruction counts are exact and repeat
bit for bit. They are not time (IPC varies, and a mispredicted branch costs ~15-20 cycles),
so confirm a change that counts well with interleaved timings (tools/bench/cpu.py).

The copy is built for x86-64-v3 (AVX2) because valgrind 3.19 cannot decode AVX-512; the
reference itself is built with -march=native. Prints a table; asserts nothing. Needs
valgrind (apt-get install valgrind).
"""
import argparse
import pathlib
import re
import shutil
import subprocess
import sys
import tempfile

from labkit.variants import build_sources

ROOT = pathlib.Path(__file__).resolve().parents[2]

# The two queries, kept out of line so that callgrind can count them.
QUERIES = {
    "closest_hit": "RT_HD inline Hit closest_hit(const SceneView& scene, const Ray& ray) {",
    "occluded": "RT_HD inline bool occluded(const SceneView& scene, const Ray& ray, real t_max) {",
}


def fail(message: str) -> None:
    print(f"count_work: {message}", file=sys.stderr)
    sys.exit(2)


def build(work: pathlib.Path) -> pathlib.Path:
    tracer = (ROOT / "common" / "core" / "path_steps.h").read_text()
    for name, signature in QUERIES.items():
        if signature not in tracer:
            fail(f"common/core/path_steps.h no longer declares {name} as '{signature}'; "
                 "update QUERIES")
        tracer = tracer.replace(signature, "__attribute__((noinline)) " +
                                signature.replace("RT_HD inline ", ""))
    sources = {"render.cpp": (ROOT / "labs/01-serial/solution/render.cpp").read_text(),
               "path_steps.h": tracer}
    # The Makefile's build, for a target valgrind can run (no AVX-512), with -g for
    # callgrind's line numbers, into a build folder of its own.
    opt = "-O3 -march=x86-64-v3 -g -ffp-contract=off -fno-math-errno -fno-trapping-math"
    try:
        return build_sources("01-serial", work, sources,
                             make_args=[f"OPT={opt}", f"BUILD={work / 'build'}", "CI="])
    except RuntimeError as e:
        fail(str(e).splitlines()[0])


def inclusive(annotated: str, function: str) -> list:
    """The inclusive event counts of the first line that names `function(`."""
    for line in annotated.splitlines():
        if re.search(rf"[:\s]{re.escape(function)}\(", line) and "[" in line:
            return [int(n.replace(",", "")) for n in re.findall(r"([\d,]+) \(\s*[\d.]+%\)", line)]
    fail(f"callgrind found no function {function}")


def calls(tree: str, function: str) -> int:
    match = re.search(rf">\s+\S*{re.escape(function)}\([^\n]*\(([\d,]+)x\)", tree)
    if not match:
        fail(f"callgrind found no calls of {function}")
    return int(match.group(1).replace(",", ""))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--width", type=int, default=60)
    parser.add_argument("--height", type=int, default=60)
    parser.add_argument("--spp", type=int, default=16)
    parser.add_argument("--bounces", type=int, default=4)
    args = parser.parse_args()
    for name in ("width", "height", "spp", "bounces"):
        if getattr(args, name) < 1:
            parser.error(f"--{name} must be at least 1")
    for tool in ("valgrind", "callgrind_annotate"):
        if not shutil.which(tool):
            fail(f"{tool} is not installed (apt-get install valgrind)")

    with tempfile.TemporaryDirectory() as tmp:
        work = pathlib.Path(tmp)
        binary = build(work)
        out = work / "callgrind.out"
        subprocess.run(["valgrind", "--tool=callgrind", "--branch-sim=yes",
                        f"--callgrind-out-file={out}", str(binary),
                        "--scene", str(ROOT / "common/scenes/cornell.json"),
                        "--width", str(args.width), "--height", str(args.height),
                        "--spp", str(args.spp), "--bounces", str(args.bounces), "--quiet"],
                       check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        annotate = ["callgrind_annotate", "--threshold=100", str(out)]
        flat = subprocess.run(annotate + ["--inclusive=yes"], capture_output=True, text=True,
                              check=True).stdout
        tree = subprocess.run(annotate + ["--tree=calling"], capture_output=True, text=True,
                              check=True).stdout

    paths = args.width * args.height * args.spp
    # Events: Ir, Bc (conditional branches), Bcm (their mispredictions), Bi, Bim.
    render = inclusive(flat, "render")
    closest, shadow = inclusive(flat, "closest_hit"), inclusive(flat, "occluded")
    n_closest, n_shadow = calls(tree, "closest_hit"), calls(tree, "occluded")
    rest = [r - c - s for r, c, s in zip(render, closest, shadow)]

    print(f"Lab 01 reference, Cornell {args.width}x{args.height}, {args.spp} spp, "
          f"{args.bounces} bounces: {paths} paths (callgrind, x86-64-v3 build)")
    print(f"{'part':<22} {'calls/path':>10} {'instr/call':>10} {'instr/path':>10} "
          f"{'share':>6} {'mispredicts/path':>16}")
    for name, events, n in (("closest hit", closest, n_closest),
                            ("shadow ray (occluded)", shadow, n_shadow),
                            ("rest of the path", rest, paths)):
        print(f"{name:<22} {n / paths:>10.2f} {events[0] / n:>10.0f} {events[0] / paths:>10.0f} "
              f"{events[0] / render[0]:>6.1%} {events[2] / paths:>16.1f}")
    print(f"{'all':<22} {'':>10} {'':>10} {render[0] / paths:>10.0f} {1:>6.1%} "
          f"{render[2] / paths:>16.1f}")
    print("Mispredictions are callgrind's simple predictor model, an upper bound on real "
          "hardware's.")


if __name__ == "__main__":
    try:
        main()
    except subprocess.CalledProcessError as error:
        fail(
            f"'{' '.join(map(str, error.cmd[:2]))} ...' failed with exit status {error.returncode}"
        )
