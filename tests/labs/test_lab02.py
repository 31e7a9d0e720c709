"""Lab 02 (SIMD): both references pass every correctness check, the skeletons are visibly
incomplete, a CPU without AVX2 gets one clear line, and Part B is faster than lab 01.

Part A (./lab02a-ref): lab 01's renderer with the SSE Vec3. Its skeleton is correct but
scalar: every TODO falls back to scalar code, and the run's summary says so.
Part B: one path per SIMD lane. ./lab02-ref-avx2 is what students write, finished: 8 paths per
AVX2 packet. ./lab02-ref runs at the width the CPU has (16 AVX-512 lanes, else 8 of AVX2) with
compacted packets (survivors repacked after every bounce); ./lab02-bench runs any width and
method (RT_SIMD_LANES, RT_SIMD_COMPACT). The skeleton tests rectangles, triangles and quads in
lane 0 only, so 7 of every 8 samples miss every wall: a dark, wrong image.
The skeleton tests build the pristine skeleton (as generated from the solution), not the
student's copy, so `make test` stays green while students fill theirs in.

Both parts, every width and method, and the across-primitives example do lab 01's arithmetic
lane by lane (sin and cos too: one polynomial, material.h and lane_math.h), and each pixel adds
its samples in lab 01's order, so their images are lab 01's bit for bit, and the tests assert
exactly that. The statistical checks (grading.checks) apply to them as well, as to any
renderer.
"""
import os
import pathlib
import shutil
import subprocess

import pytest

from grading.checks.golden import check_golden
from grading.checks.renderer import CHECKS as RENDERER_CHECKS
from labkit.harness import (
    ROOT,
    available_cores,
    build,
    cpu_has_avx2,
    interleaved_speedup,
    render_seconds,
    run_lab,
)
from labkit.variants import build_pristine_skeleton, build_sources, pristine_skeleton_sources


def cpu_has_avx512() -> bool:
    """Whether this CPU runs the 16-lane objects (AVX-512 F, DQ, VL, BW), as the binaries check."""
    for line in pathlib.Path("/proc/cpuinfo").read_text().splitlines():
        if line.startswith("flags"):
            return all(f in line.split() for f in ("avx512f", "avx512dq", "avx512vl", "avx512bw"))
    return False


needs_avx2 = pytest.mark.skipif(not cpu_has_avx2(), reason="this CPU has no AVX2/FMA")
needs_avx512 = pytest.mark.skipif(
    not cpu_has_avx512(),
    reason="this CPU has no AVX-512 (F, DQ, VL, BW): the 16-lane packets cannot run here")

# Every width and method of the packet tracer: (lanes, compacted).
PACKETS = [(8, False), (8, True), (16, False), (16, True)]
PACKET_IDS = ["8-lanes", "8-compacted", "16-lanes", "16-compacted"]


def packets_param(lanes, compacted):
    marks = [needs_avx512] if lanes == 16 else [needs_avx2]
    return pytest.param(lanes, compacted, marks=marks,
                        id=f"{lanes}-{'compacted' if compacted else 'lanes'}")


PACKET_PARAMS = [packets_param(*p) for p in PACKETS]


@pytest.fixture(scope="module")
def lab02_ref():
    return build("lab02-ref")[0]


@pytest.fixture(scope="module")
def lab02_ref_avx2():
    return build("lab02-ref-avx2")[0]


@pytest.fixture(scope="module")
def lab02_bench():
    return build("lab02-bench")[0]


@pytest.fixture(scope="module")
def lab02():
    return build("lab02")[0]


@pytest.fixture(scope="module")
def lab02a_ref():
    return build("lab02a-ref")[0]


@pytest.fixture(scope="module")
def lab02a():
    return build("lab02a")[0]


@pytest.fixture(scope="module")
def lab02_prims():
    return build("lab02-prims")[0]


@pytest.fixture(scope="module")
def lab02_pristine_skeleton(tmp_path_factory):
    """Part B's skeleton exactly as generated (skeleton/render*.cpp, packet_hits.h)."""
    if not cpu_has_avx2():
        pytest.skip("this CPU has no AVX2/FMA")
    return build_pristine_skeleton("02-simd", tmp_path_factory.mktemp("lab02-skeleton"))


@pytest.fixture(scope="module")
def lab02a_pristine_skeleton(tmp_path_factory):
    """Part A's skeleton as generated: lab 01's pixel loop built against the pristine
    skeleton/part-a/vec3.h, linked with the driver objects of ./lab02a-ref's build (the same
    16-byte Vec3 layout; only the operators' bodies differ)."""
    build("lab02a-ref")
    sources = {"vec3.h": pristine_skeleton_sources("02-simd")["part-a/vec3.h"],
               "render_vec3_sse.cpp": (ROOT / "labs/02-simd/render_vec3_sse.cpp").read_text()}
    return build_sources("02-simd-a", tmp_path_factory.mktemp("lab02a-skeleton"), sources)


CHECKS = list(RENDERER_CHECKS.values())
CHECK_IDS = list(RENDERER_CHECKS)


def render_shipped(binary, scene: str, **size):
    """A shipped scene at small size (default 64x64, 16 spp), showcase with 8 bounces (its
    glass and mirror paths run long), as PFM bytes."""
    bounces = 8 if scene == "showcase" else None
    settings = dict(width=64, height=64, spp=16) | size
    run = run_lab(binary, ROOT / "common" / "scenes" / f"{scene}.json", bounces=bounces, seed=21,
                  **settings)
    return run.image.tobytes()


@pytest.fixture
def packets(monkeypatch):
    """Sets lab02-bench's width and method (its environment) for the test's runs."""
    def choose(lanes, compacted):
        monkeypatch.setenv("RT_SIMD_LANES", str(lanes))
        monkeypatch.setenv("RT_SIMD_COMPACT", "1" if compacted else "0")
    return choose


# ---- Part B --------------------------------------------------------------------------------

@needs_avx2
@pytest.mark.parametrize("check", CHECKS, ids=CHECK_IDS)
def test_part_b_reference_passes(lab02_ref, check):
    result = check(lab02_ref)
    assert result.passed, str(result)


@needs_avx2
@pytest.mark.parametrize("scene", ["cornell", "showcase"])
def test_part_b_is_lab01_bit_for_bit(lab01_ref, lab02_ref, lab02_ref_avx2, scene):
    """Same samples, same hits, same shading per lane, the same bounce step lane by lane:
    the PFM is lab 01's, byte for byte, for the widest compacted reference and for the 8-lane
    one students write."""
    expected = render_shipped(lab01_ref, scene)
    assert render_shipped(lab02_ref, scene) == expected, "lab02-ref"
    assert render_shipped(lab02_ref_avx2, scene) == expected, "lab02-ref-avx2"


# Odd sizes and sample counts: partly empty last packets, groups of 256 paths that end inside
# a pixel (spp 300) or span many (spp 5), rows not a multiple of anything.
ODD_RENDERS = [dict(width=37, height=23, spp=13), dict(width=9, height=31, spp=5),
               dict(width=7, height=3, spp=300), dict(width=16, height=16, spp=1)]


@pytest.mark.parametrize("lanes, compacted", PACKET_PARAMS)
@pytest.mark.parametrize("scene", ["cornell", "showcase"])
def test_every_width_and_method_is_lab01_bit_for_bit(lab01_ref, lab02_bench, packets, scene,
                                                     lanes, compacted):
    """8 and 16 lanes, traced from camera to end or compacted after every bounce, on both
    scenes at odd sizes and sample counts: lab 01's PFM, byte for byte."""
    packets(lanes, compacted)
    for size in ODD_RENDERS:
        expected = render_shipped(lab01_ref, scene, **size)
        assert render_shipped(lab02_bench, scene, **size) == expected, f"{size}"


@needs_avx2
def test_part_b_spp_not_a_multiple_of_8(lab01_ref, lab02_ref_avx2):
    """The last packet of a pixel is partly empty: its spare lanes must add nothing, to the
    bit."""
    for spp in (1, 5, 13):
        a = run_lab(lab01_ref, width=16, height=16, spp=spp, seed=4).image
        b = run_lab(lab02_ref_avx2, width=16, height=16, spp=spp, seed=4).image
        assert a.tobytes() == b.tobytes(), f"spp {spp}"


@needs_avx2
def test_reference_says_which_width(lab02_ref, lab02_ref_avx2):
    """--json (and the summary line) name the packets: the widest this CPU runs, compacted;
    8 AVX2 lanes for the students' reference."""
    run = run_lab(lab02_ref, width=8, height=6, spp=3, bounces=2)
    assert run.json["lab"] == "02-simd"
    expected = ("AVX-512, 16 paths per packet" if cpu_has_avx512() else "AVX2, 8 paths per packet")
    assert expected + ", compacted" in run.json["device"], run.json["device"]
    assert run.image.shape == (6, 8, 3)
    device = run_lab(lab02_ref_avx2, width=8, height=6, spp=3).json["device"]
    assert "AVX2, 8 paths per packet" in device and "compacted" not in device, device


@needs_avx2
def test_reference_without_avx512_takes_the_8_lane_path(lab01_ref, lab02_ref, monkeypatch):
    """RT_FORCE_NO_AVX512=1 takes the path of a CPU with AVX2 only: 8 compacted lanes, and
    still lab 01's bits."""
    monkeypatch.setenv("RT_FORCE_NO_AVX512", "1")
    run = run_lab(lab02_ref, width=21, height=11, spp=7, seed=8)
    assert "AVX2, 8 paths per packet, compacted" in run.json["device"], run.json["device"]
    assert run.image.tobytes() == run_lab(lab01_ref, width=21, height=11, spp=7,
                                          seed=8).image.tobytes()


@needs_avx2
def test_16_lanes_without_avx512_is_one_clear_line(lab02_bench, tmp_path):
    """Asked for 16 lanes on a CPU without AVX-512 (forced here), the bench build refuses
    with exit status 2 and one line naming AVX-512, and leaves no file behind."""
    out = tmp_path / "never.pfm"
    p = subprocess.run([str(lab02_bench), "--quiet", "--width", "8", "--height", "8", "--spp",
                        "1", "--pfm", str(out)], capture_output=True, text=True,
                       env={"RT_FORCE_NO_AVX512": "1", "RT_SIMD_LANES": "16",
                            "PATH": "/usr/bin:/bin"})
    assert p.returncode == 2, p.stderr
    lines = p.stderr.strip().splitlines()
    assert len(lines) == 1 and "AVX-512" in lines[0] and lines[0].startswith("error:"), p.stderr
    assert list(tmp_path.iterdir()) == []


@pytest.mark.skipif(shutil.which("nm") is None, reason="no nm (binutils) to list the symbols")
def test_avx512_object_defines_only_its_own_code(lab02_ref):
    """The one object built with AVX-512 (packets_avx512.o) defines no function that another
    object could also define: every global or weak symbol in it is an instantiation for
    Float16 or one of its entry points. So the linker never has to choose between an AVX-512
    copy of an inline function and another (the Makefile's link order is the second line of
    defence), and a CPU without AVX-512 never runs one."""
    obj = ROOT / "build" / "common" / "simd" / "packets_avx512.o"
    listing = subprocess.run(["nm", "-C", "--defined-only", str(obj)], capture_output=True,
                             text=True, check=True).stdout
    shared = [line for line in listing.splitlines()
              if line.split()[1:2] and line.split()[1] in ("T", "W", "V", "u", "D", "B", "R")
              and "Float16" not in line and "_avx512" not in line]
    assert not shared, "symbols another object may define too:\n" + "\n".join(shared)


def peak_memory_kib(command) -> int:
    """The peak resident memory of one process (KiB), as the kernel counts it."""
    p = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    _, status, usage = os.wait4(p.pid, 0)
    assert os.waitstatus_to_exitcode(status) == 0, p.stderr.read()
    return usage.ru_maxrss


@needs_avx2
def test_compacted_memory_is_bounded(lab02_ref):
    """A group holds at most 256 paths, whatever the sample count: one pixel at 2^18 samples
    (3 MB of radiance if every sample were kept) peaks within 1 MiB of one at 256."""
    def peak(spp):
        return peak_memory_kib([str(lab02_ref), "--quiet", "--width", "1", "--height", "1",
                                "--spp", str(spp), "--bounces", "2"])
    small, large = peak(256), peak(1 << 18)
    assert large - small < 1024, f"{small} KiB at 256 spp, {large} KiB at 2^18 spp"


def test_part_b_skeleton_is_visibly_incomplete(lab02_pristine_skeleton):
    """Until students write the 8-wide triangle test, only lane 0 of each packet sees the
    triangles: the walls are missing from 7 of every 8 samples."""
    skeleton = lab02_pristine_skeleton
    results = [check_golden(skeleton, "cornell"), check_golden(skeleton, "showcase")]
    assert not any(r.passed for r in results), "\n".join(map(str, results))
    run = run_lab(skeleton, width=32, height=32, spp=8)
    assert run.image is not None and run.image.max() > 0  # an image, not a crash or a blank


@needs_avx2
def test_part_b_students_build_runs(lab02):
    """`make lab02` builds the student's copy and it runs (what it renders is graded); it is
    8 lanes of AVX2, whatever the CPU."""
    run = run_lab(lab02, width=8, height=8, spp=8)
    assert run.image.shape == (8, 8, 3)
    assert "AVX2, 8 paths per packet" in run.json["device"], run.json["device"]


@pytest.mark.parametrize("binary", ["lab02-ref", "lab02-ref-avx2"])
def test_missing_avx2_is_one_clear_line(binary, tmp_path):
    """RT_FORCE_NO_AVX2=1 takes the path a CPU without AVX2 takes: exit status 2, one line
    that says what is missing, and no output file left behind."""
    out = tmp_path / "never.ppm"
    p = subprocess.run([str(build(binary)[0]), "--quiet", "--width", "8", "--height", "8",
                        "--spp", "1", "--out", str(out)], capture_output=True, text=True,
                       env={"RT_FORCE_NO_AVX2": "1", "PATH": "/usr/bin:/bin"})
    assert p.returncode == 2, p.stderr
    lines = p.stderr.strip().splitlines()
    assert len(lines) == 1 and "AVX2" in lines[0] and lines[0].startswith("error:"), p.stderr
    assert not out.exists() and list(tmp_path.iterdir()) == []


@pytest.mark.timed
@needs_avx2
@pytest.mark.parametrize("binary", ["lab02-ref-avx2", "lab02-ref"])
def test_part_b_faster_than_lab01(lab01_ref, binary):
    """The references' speedup over lab 01 on one core, interleaved, best of 3. The bars (2.4x
    for 8 AVX2 lanes, 3.5x for lab02-ref on AVX-512, on the Cornell box) are measured by
    python3 -m tools.bench.simd --packets; the threshold here holds with a wide margin on a busy
    two-core machine."""
    candidate = build(binary)[0]
    kwargs = dict(width=100, height=100, spp=32)
    speedup, base, simd = interleaved_speedup(lambda: render_seconds(lab01_ref, **kwargs),
                                              lambda: render_seconds(candidate, **kwargs), n=3)
    print(f"{binary} {speedup:.2f}x faster than lab01-ref ({base:.3f} s vs {simd:.3f} s, "
          f"{available_cores()} cores available)")
    assert speedup >= 1.5, f"only {speedup:.2f}x faster than lab 01 ({base:.3f} s vs {simd:.3f} s)"


# ---- Part A --------------------------------------------------------------------------------

@pytest.mark.parametrize("check", CHECKS, ids=CHECK_IDS)
def test_part_a_reference_passes(lab02a_ref, check):
    result = check(lab02a_ref)
    assert result.passed, str(result)


def test_part_a_reference_keeps_lab01s_bits(lab01_ref, lab02a_ref):
    """The SSE Vec3 does lab 01's operations in lab 01's order (no FMA, the same sums), so
    the image is lab 01's bit for bit: the instructions changed, the arithmetic did not."""
    args = dict(width=32, height=32, spp=8, seed=9)
    assert run_lab(lab02a_ref, **args).image.tobytes() == run_lab(lab01_ref, **args).image.tobytes()


def test_part_a_skeleton_is_correct_but_scalar(lab02a_pristine_skeleton):
    """Part A's skeleton falls back to scalar code in every TODO: it renders correctly from
    the start (so each operator can be converted and checked on its own), and its summary
    says it is not SSE yet."""
    skeleton = lab02a_pristine_skeleton
    run = run_lab(skeleton, width=8, height=8, spp=1)
    assert run.json["lab"] == "02-simd-a"
    assert "scalar fallback" in run.json["device"], run.json["device"]
    result = check_golden(skeleton, "cornell")
    assert result.passed, str(result)


def test_part_a_students_build_runs(lab02a):
    """`make lab02a` builds the student's copy (skeleton/part-a/vec3.h) and it runs."""
    assert run_lab(lab02a, width=8, height=8, spp=1).json["lab"] == "02-simd-a"


def test_part_a_reference_says_sse(lab02a_ref):
    assert "SSE" in run_lab(lab02a_ref, width=8, height=8, spp=1).json["device"]


# ---- the worked example: SIMD across primitives ---------------------------------------------

@needs_avx2
@pytest.mark.parametrize("scene", ["cornell", "showcase"])
def test_across_primitives_keeps_lab01s_bits(lab01_ref, lab02_prims, scene):
    """One ray against 8 primitives, with lab 01's path loop: the very same image."""
    assert render_shipped(lab02_prims, scene) == render_shipped(lab01_ref, scene)


# ---- Part A is graded: a hand-in with it undone or wrong loses its points --------------------

def part_a_build(tmp_path, vec3: str):
    build("lab02a")  # the driver objects a Part A variant links (labs/02-simd/lab.mk)
    loop = (ROOT / "labs/02-simd/render_vec3_sse.cpp").read_text()
    return build_sources("02-simd-a", tmp_path, {"vec3.h": vec3, "render_vec3_sse.cpp": loop})


def graded_part_a(binary):
    from grading.checks import draws
    from grading.checks.part_a import check_part_a
    with draws.secret("part-a"):
        return check_part_a(binary, "part-a", build("lab01-ref")[0])


def test_part_a_is_in_the_rubric():
    from grading.grade import RUBRICS
    item = next(i for i in RUBRICS["02"] if i.id == "part-a")
    assert item.part == "a" and item.points >= 10


def test_part_a_reference_earns_part_a(lab02a_ref):
    result = graded_part_a(lab02a_ref)
    assert result.passed and result.credit == 1, str(result)


def test_part_a_dot_without_its_z_term_loses_part_a(tmp_path):
    solution = (ROOT / "labs/02-simd/solution/part-a/vec3.h").read_text()
    whole = "return _mm_cvtss_f32(_mm_add_ss(pairs, _mm_movehl_ps(pairs, pairs)));"
    assert whole in solution
    mutant = part_a_build(tmp_path, solution.replace(whole, "return _mm_cvtss_f32(pairs);"))
    result = graded_part_a(mutant)
    assert not result.passed and result.credit <= 0.25, str(result)
    assert "FAIL sphere interior" in result.detail and "FAIL lit plane" in result.detail


def test_part_a_left_as_the_skeleton_earns_nothing(lab02a_pristine_skeleton):
    result = graded_part_a(lab02a_pristine_skeleton)
    assert result.credit == 0 and "scalar fallback" in result.detail, str(result)
