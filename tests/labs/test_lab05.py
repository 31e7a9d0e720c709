"""Lab 05 (CUDA megakernel).

Host-side tests run wherever nvcc is (CI has it, and no GPU): the CUDA targets build, a
machine without nvcc gets one line from them, the skeleton matches its solution, the
compiler's report lists the kernels, bad input and a missing GPU give one line and a
non-zero exit. GPU tests (the `gpu` fixture) render: every correctness check of the CPU
labs, agreement with lab 01, finite pixels at the baseline, reproducibility, banded renders,
the skeleton's visible failure. Without a GPU they skip and say why."""
import json
import os
import re
import subprocess

import numpy as np
import pytest
from cuda_env import gpu_name, missing_gpu

from grading.checks import analytic, invariance
from grading.checks.golden import check_golden
from grading.checks.renderer import CHECKS
from labkit import scenes
from labkit.compare import compare
from labkit.harness import ROOT, build, golden, run_lab

LAB = "05-cuda-mega"
# The time bars: loose guards, BAR_MARGIN times what the reference measured on this card (its
# record, reference/gpu/<card>/bench-lab05.json), so that a slower clock of the same GPU
# fails nothing that works. The speed targets themselves (bench/gpu/speed_targets.h) are
# judged by lab05-bench.
BAR_MARGIN = 1.2


def make(*args, **kwargs):
    return subprocess.run(["make", "-s", "-C", str(ROOT), *args], capture_output=True,
                          text=True, timeout=900, **kwargs)


# ---- host side: the build --------------------------------------------------------------

def test_without_nvcc_the_targets_fail_with_one_line():
    """No toolkit: each CUDA target says so in one line and fails; other targets still work."""
    for target in ("lab05", "lab05-ref", "kernel-report"):
        p = make(target, "NVCC=/no/such/nvcc")
        assert p.returncode != 0, target
        lines = p.stderr.strip().splitlines()
        assert lines and "needs the CUDA toolkit" in lines[0], p.stderr
        assert len([ln for ln in lines if not ln.startswith("make")]) == 1, p.stderr
    assert make("-n", "lab01-ref", "NVCC=/no/such/nvcc").returncode == 0


def test_targets_build_with_nvcc(lab05_ref, lab05):
    assert os.access(lab05_ref, os.X_OK) and os.access(lab05, os.X_OK)


def test_architectures(nvcc):
    """Machine code for the GPU present, or for sm_75..sm_90 plus PTX where there is none;
    under CI without a GPU only the range's ends (compute_75 PTX, sm_90 machine code) for the
    labs, and sm_90 alone for the benchmarks and variants."""
    def codes_of(*args):
        command = make("print-cuda-build-command", *args).stdout
        return set(re.findall(r"code=(sm_\d+|compute_\d+)", command)), command
    codes, command = codes_of("CI=")
    if missing_gpu():
        assert codes == {"sm_75", "sm_80", "sm_86", "sm_89", "sm_90", "compute_90"}, command
        codes, command = codes_of("CI=true")
        assert codes == {"compute_75", "sm_90"}, command
        # The benchmarks and lab 05's variants, which nothing runs there: sm_90 alone.
        p = make("-n", "-B", "CI=true", "lab05-bench", "lab06-bench", "lab05-ref-fast-math")
        compiles = [c for c in p.stdout.replace("\\\n", " ").splitlines()
                    if " -c " in c and "nvcc" in c]
        assert len(compiles) == 3, p.stdout + p.stderr
        for c in compiles:
            assert set(re.findall(r"code=(sm_\d+|compute_\d+)", c)) == {"sm_90"}, c
    else:
        caps = subprocess.run(["nvidia-smi", "--query-gpu=compute_cap", "--format=csv,noheader"],
                              capture_output=True, text=True).stdout.split()
        assert codes == {"sm_" + c.replace(".", "") for c in caps}, command


def test_shared_gpu_headers_compile_alone(nvcc):
    """Every header of common/cuda, common/wavefront and bench/gpu compiles on its own (it
    includes what it uses), for sm_90 with warnings as errors."""
    p = make("-j2", "check-gpu-headers")
    assert p.returncode == 0, p.stdout + p.stderr
    headers = [h for folder in ("common/cuda", "common/wavefront", "bench/gpu")
               for h in (ROOT / folder).glob("*.*h")]
    assert f"check-gpu-headers: {len(headers)} headers" in p.stdout, p.stdout


def test_speed_target_verdicts(nvcc):
    """What the benchmarks say of their speed targets (bench/gpu/speed_targets.h): judged
    only for the baseline on the GPU the bars are set on; met, missed, not judged, not run
    (tests/cuda/speed_targets_check.cu holds the cases)."""
    p = make("check-speed-targets")
    assert p.returncode == 0 and "every case holds" in p.stdout, p.stdout + p.stderr


def test_kernel_choice_on_the_host(nvcc, tmp_path):
    """Which of lab05-ref's kernels a scene gets (its memory, material and primitive sets),
    the constant bank's limit, the scene's rectangles as quads or everything as triangles
    (the same surface, to the last bit of the distance) and RT_LAB05_GEOMETRY's values:
    tests/cuda/lab05_kernel_choice_check.cu, host code, no GPU."""
    binary = tmp_path / "check"
    p = subprocess.run(["nvcc", "-std=c++17", "-arch=sm_90", "-Xcompiler", "-Wall,-Werror",
                        "-Werror", "all-warnings", "-Icommon/cuda", "-Icommon/core",
                        "-Icommon/host", "tests/cuda/lab05_kernel_choice_check.cu", "-o",
                        str(binary)], cwd=ROOT, capture_output=True, text=True, timeout=600)
    assert p.returncode == 0, p.stderr
    p = subprocess.run([str(binary)], capture_output=True, text=True, timeout=60)
    assert p.returncode == 0 and "every case holds" in p.stdout, p.stdout + p.stderr


def test_skeleton_in_sync():
    """The committed skeleton is exactly what labkit/skeletons.py makes from the solution."""
    from labkit.variants import pristine_skeleton_sources
    expected = pristine_skeleton_sources(LAB)
    assert set(expected) == {"render_kernel.cuh", "render.cu"}
    for name, text in expected.items():
        assert (ROOT / "labs" / LAB / "skeleton" / name).read_text() == text, name


def test_kernel_report(nvcc):
    """The compiler's report lists the kinds kernel (scene in the constant bank, whole paths,
    at most 56 registers, compiled for the Cornell box's kinds: DiffuseOnly, BoxGeometry)
    within its cap and with a small stack, every kernel lab05-ref chooses from (the kinds
    kernels and a small-scene kernel for every pair of counts it holds, the surface by index,
    within 56 registers), the benchmark's uncapped shapes with no spills and its other caps
    kept."""
    p = make("kernel-report")
    assert p.returncode == 0, p.stderr
    report = (ROOT / "build" / "kernel-report.md").read_text()

    def row(kernel):
        line = next((ln for ln in report.splitlines() if f"`{kernel}`" in ln), None)
        assert line is not None, f"{kernel} is not in the report"
        cells = [c.strip() for c in line.strip("|").split("|")]
        return int(cells[2]), int(cells[3]) + int(cells[4]), int(cells[5])  # regs, spills, stack

    reference = "render_kernel<32, constant, 64, whole, 56, DiffuseOnly, BoxGeometry>"
    registers, _, stack = row(reference)
    assert 16 <= registers <= 56 and stack <= 256, (registers, stack)
    # lab05-ref's menu: both places for the scene, both material sets, three primitive sets.
    for memory in ("constant", "global"):
        for materials in ("DiffuseOnly", "AnyMaterial"):
            for primitives in ("BoxGeometry", "GeneralGeometry", "AnyGeometry"):
                row(f"render_kernel<32, {memory}, 64, whole, 56, {materials}, {primitives}>")
    # The small-scene kernels (small_scene.cuh): one per pair of counts, 0-2 spheres and 0-6
    # rectangles (kSmallSceneMaxSpheres, kSmallSceneMaxRects), the IEEE build's cap.
    for spheres in range(3):
        for rects in range(7):
            registers, _, stack = row(
                f"small_scene_kernel<{spheres}, {rects}, 32, 64, 56, true, false>")
            assert registers <= 56 and stack <= 256, (spheres, rects, registers, stack)
    for kernel in ("render_kernel<32, constant, 64, whole, 255, DiffuseOnly, BoxGeometry>",
                   "small_scene_kernel<1, 5, 32, 64, 255, true, false>"):
        registers, spilled, stack = row(kernel)
        assert registers > 56 and spilled == 0 and stack == 0, (kernel, registers, spilled, stack)
    for cap in (48, 64):
        registers, _, _ = row(reference.replace("whole, 56", f"whole, {cap}"))
        assert registers <= cap, (cap, registers)
    # Every row names its kernel whole: no two rows read alike (the wavefront kernels' nine
    # template arguments included).
    names = [ln.split("|")[1].strip() for ln in report.splitlines() if ln.startswith("| `")]
    assert len(names) == len(set(names)), sorted(n for n in names if names.count(n) > 1)
    assert any("WavefrontConfig<SoaPathPool, global, per block, " in n for n in names), names


def test_kernel_report_keeps_one_architecture(tmp_path):
    """The build's logs hold a kernel once per architecture compiled (a machine without a GPU
    builds several): the report lists those of the architecture asked for only, and where the
    objects hold none of it, says which they hold in one line. Made-up logs, so no nvcc."""
    def entry(name, arch, registers):
        return (f"ptxas info    : Compiling entry function '{name}' for '{arch}'\n"
                f"ptxas info    : Function properties for {name}\n"
                f"    0 bytes stack frame, 0 bytes spill stores, 0 bytes spill loads\n"
                f"ptxas info    : Used {registers} registers, used 1 barriers, 400 bytes cmem[0]\n")
    (tmp_path / "a.ptxas").write_text(entry("_Z1fv", "sm_75", 40) + entry("_Z1fv", "sm_90", 56))
    (tmp_path / "b.ptxas").write_text(entry("_Z1gv", "sm_90", 32))
    script = str(ROOT / "labs" / LAB / "kernel_report.py")
    logs = [str(tmp_path / "a.ptxas"), str(tmp_path / "b.ptxas")]
    p = subprocess.run(["python3", script, *logs, "--arch", "sm_90"], capture_output=True,
                       text=True)
    assert p.returncode == 0, p.stderr
    rows = [ln for ln in p.stdout.splitlines() if ln.startswith("| `")]
    assert [r.split("|")[1].strip() for r in rows] == ["`f()`", "`g()`"], rows
    assert rows[0].split("|")[3].strip() == "56", rows
    p = subprocess.run(["python3", script, *logs, "--arch", "sm_80"], capture_output=True,
                       text=True)
    assert p.returncode == 1 and p.stdout == "", p.stdout
    assert p.stderr.count("\n") == 1 and "sm_75, sm_90" in p.stderr, p.stderr


def test_loop_branches_reads_machine_code():
    """labs/05-cuda-mega/loop_branches.py finds a kernel's innermost loops in cuobjdump's
    listing and tells a branch that can split the warp from one that only guards the CALL of
    a slow path or follows a warp vote; the trap at a kernel's end (a branch to itself) is no
    loop. A made-up listing, so no cuobjdump is needed."""
    code = [
        (0x00, "MOV R1, c[0x0][0x28]"),
        (0x10, "FADD R2, R2, R3"),
        (0x20, "@P0 BRA 0x50"),  # skips arithmetic: lanes may part here
        (0x30, "FMUL R4, R4, R4"),
        (0x40, "FMUL R5, R5, R5"),
        (0x50, "@!P1 BRA 0x80"),  # skips only the call of a slow path
        (0x60, "MOV R0, 0x70"),
        (0x70, "CALL.REL.NOINC 0x200"),
        (0x80, "VOTE.ANY P3, P4"),
        (0x88, "ISETP.GE.AND P2, PT, R6, R7, PT"),
        (0x8c, "@!P3 BRA 0x90"),  # on a vote: the whole warp takes it or none
        (0x90, "@!P2 BRA 0x10"),  # the loop
        (0xa0, "EXIT"),
        (0xb0, "BRA 0xb0"),
    ]
    listing = "\t\tFunction : _Z13render_kernelv\n" + "".join(
        f"        /*{a:04x}*/                   {text} ;  /* 0x0 */\n" for a, text in code)
    script = ROOT / "labs" / LAB / "loop_branches.py"
    p = subprocess.run(["python3", str(script)], input=listing, capture_output=True, text=True,
                       timeout=60)
    assert p.returncode == 0, p.stderr
    loops = [ln.strip() for ln in p.stdout.splitlines() if ln.strip().startswith("loop")]
    assert loops == ["loop 0x0010-0x0090: 11 instructions, 1 divergent branches, "
                     "1 slow-path guards, 1 warp-uniform branches"], p.stdout
    p = subprocess.run(["python3", str(script), "--kernel", "no_such_kernel"], input=listing,
                       capture_output=True, text=True, timeout=60)
    assert p.returncode == 1 and "no function matching" in p.stderr, p.stderr


# ---- host side: errors before and without the GPU --------------------------------------

def test_no_gpu_is_one_line(lab05_ref, tmp_path):
    """With no GPU visible (CUDA_VISIBLE_DEVICES empty; CI has none at all): one line, exit
    status 3 (the machine's fault, not the input's: that is 2), no output file."""
    out = tmp_path / "out.pfm"
    env = {**os.environ, "CUDA_VISIBLE_DEVICES": ""}
    p = subprocess.run([str(lab05_ref), "--quiet", "--width", "8", "--height", "8", "--spp", "1",
                        "--pfm", str(out)], capture_output=True, text=True, env=env, timeout=60)
    assert p.returncode == 3, (p.returncode, p.stderr)
    lines = p.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: GPU: "), p.stderr
    assert "CUDA" in lines[0]
    assert p.stdout == "" and not out.exists()


def test_a_variant_needs_every_file_students_write(nvcc, tmp_path):
    """A CUDA lab built from a folder (a submission, the pristine skeleton) must hold each file
    its students write: without render_kernel.cuh the shared reference of that name
    (common/cuda/render_kernel.cuh) would be compiled in its place. One line, nothing built."""
    from labkit.variants import pristine_skeleton_sources
    (tmp_path / "render.cu").write_text(pristine_skeleton_sources(LAB)["render.cu"])
    p = make("cuda-variant", f"VARIANT_LAB={LAB}", f"VARIANT={tmp_path}")
    assert p.returncode != 0
    assert "has no render_kernel.cuh" in p.stderr, p.stderr
    assert not (tmp_path / "lab").exists()


def test_bad_geometry_setting_is_one_line(lab05_ref, tmp_path):
    """RT_LAB05_GEOMETRY takes 'scene' or 'general'; anything else is bad input, told before
    the GPU is opened (so here too, without one): one line naming the variable, status 2, no
    output file."""
    out = tmp_path / "out.pfm"
    for value in ("generl", "GENERAL", "general "):
        env = {**os.environ, "RT_LAB05_GEOMETRY": value}
        p = subprocess.run([str(lab05_ref), "--quiet", "--width", "8", "--height", "8", "--spp",
                            "1", "--pfm", str(out)], capture_output=True, text=True, env=env,
                           timeout=60)
        assert p.returncode == 2, (value, p.returncode, p.stderr)
        lines = p.stderr.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith("error: RT_LAB05_GEOMETRY: "), p.stderr
        assert f"'{value}'" in lines[0], p.stderr
        assert p.stdout == "" and not out.exists()


@pytest.mark.parametrize("case", ["malformed json", "negative radius", "undefined material"])
def test_bad_scene(lab05_ref, tmp_path, case):
    from test_bad_input import GOOD, SCENE_ERRORS, assert_one_line_error, run, scene_with
    transform, fragments = SCENE_ERRORS[case]
    path = scene_with(tmp_path, transform(json.dumps(GOOD, indent=2)))
    assert_one_line_error(run(lab05_ref, "--scene", str(path)), str(path), *fragments)


@pytest.mark.parametrize("flags, fragment", [
    (["--width", "0"], "--width: expected an integer in 1..16384"),
    (["--spp", "-3"], "--spp: expected an integer"),
])
def test_bad_flags(lab05_ref, flags, fragment):
    from test_bad_input import assert_one_line_error, run
    assert_one_line_error(run(lab05_ref, *flags), fragment)


# ---- on the GPU ------------------------------------------------------------------------

@pytest.mark.parametrize("check", list(CHECKS.values()), ids=list(CHECKS))
def test_reference_passes(gpu, lab05_ref, check):
    result = check(lab05_ref)
    assert result.passed, str(result)


GENERAL_CHECKS = {
    "sphere-interior": analytic.check_sphere_interior,
    "lit-plane": analytic.check_lit_plane,
    "golden-cornell": lambda b: check_golden(b, "cornell"),
    "golden-showcase": lambda b: check_golden(b, "showcase"),
    "scale": invariance.check_scale_invariance,
    "reproducible": invariance.check_reproducible,
}


@pytest.fixture
def general_geometry(monkeypatch):
    """lab05-ref with its rectangles as convex quads and the kernel for general geometry."""
    monkeypatch.setenv("RT_LAB05_GEOMETRY", "general")


@pytest.mark.parametrize("check", list(GENERAL_CHECKS.values()), ids=list(GENERAL_CHECKS))
def test_general_geometry_passes(gpu, lab05_ref, general_geometry, check):
    """RT_LAB05_GEOMETRY=general renders the Cornell box's walls (and every other scene's
    rectangles) as convex quads, with the kernel for spheres, triangles and quads: the same
    estimator, so the same checks pass."""
    result = check(lab05_ref)
    assert result.passed, str(result)


def test_general_geometry_is_the_same_image(gpu, lab05_ref, monkeypatch):
    """The general kernel is what runs (the summary's device says so) and, with the same seed,
    draws the same random numbers on the same surfaces: its pixels agree with the default
    render far inside the noise (only rays that meet an edge may differ)."""
    g = golden("cornell")
    size = dict(width=g.meta["width"], height=g.meta["height"], bounces=g.meta["bounces"])
    default = run_lab(lab05_ref, g.scene, spp=64, seed=5, **size)
    monkeypatch.setenv("RT_LAB05_GEOMETRY", "general")
    general = run_lab(lab05_ref, g.scene, spp=64, seed=5, **size)
    assert "general geometry" in general.json["device"], general.json["device"]
    assert "general geometry" not in default.json["device"], default.json["device"]
    rel = np.abs(general.image - default.image) / (np.abs(default.image) + 1e-3)
    assert float(np.median(rel)) < 1e-4 and float((rel > 1e-2).mean()) < 0.02, \
        (float(np.median(rel)), float((rel > 1e-2).mean()))


def test_agrees_with_lab01(gpu, lab05_ref):
    """Lab 01's image is the same estimator: with other seeds the two pass the noise-aware
    comparison against each other (lab 01's render standing in for the golden image, with the
    golden per-path variance); with the same seed they draw the same random numbers, so the
    pixels agree far inside the noise (only fused multiply-adds and the order of the per-pixel
    sum differ)."""
    lab01_ref = build("lab01-ref")[0]
    g = golden("cornell")
    size = dict(width=g.meta["width"], height=g.meta["height"], bounces=g.meta["bounces"])
    cpu = run_lab(lab01_ref, g.scene, spp=256, seed=21, **size).image
    gpu_image = run_lab(lab05_ref, g.scene, spp=64, seed=22, **size).image
    report = compare(gpu_image, 64, cpu, g.variance, 256)
    assert report.passed, report.summary()

    same_cpu = run_lab(lab01_ref, g.scene, spp=64, seed=22, **size).image
    rel = np.abs(gpu_image - same_cpu) / (np.abs(same_cpu) + 1e-3)
    assert float(np.median(rel)) < 1e-4 and float((rel > 1e-2).mean()) < 0.02, \
        (float(np.median(rel)), float((rel > 1e-2).mean()))


@pytest.mark.parametrize("check", [
    analytic.check_sphere_interior,
    lambda b: check_golden(b, "cornell"),
    lambda b: check_golden(b, "showcase"),
], ids=["sphere-interior", "golden-cornell", "golden-showcase"])
def test_double_build_passes(gpu, check):
    """The megakernel in double (common/core/real.h, make lab05-ref-double) renders the
    same estimator: tests/labs/test_precision.py checks lab 01's double build on the CPU."""
    binary = build("lab05-ref-double")[0]
    assert run_lab(binary, width=4, height=4, spp=1).json["precision"] == "double"
    result = check(binary)
    assert result.passed, str(result)


def test_the_reference_renders_a_mixed_scale_scene_in_double(gpu, lab05_ref, lab01_ref, tmp_path):
    """A sphere of radius 1e-4 on a floor of half-size 1e4 (test_precision.py's scene): the
    GPU reference hands it to its double build by itself, says so, and draws what lab 01's
    reference draws (which hands it to double too): the same mean, every shadow pixel dark."""
    settings = dict(width=64, height=64, spp=64, bounces=1, seed=5)
    far = scenes.write_scene(tmp_path / "mixed.json", scenes.mixed_scale(1e4))
    gpu_run = run_lab(lab05_ref, far, **settings)
    cpu = run_lab(lab01_ref, far, **settings).image
    assert gpu_run.json["precision"] == "double", gpu_run.json
    assert "/spheres/0/radius" in gpu_run.json["precision_reason"]
    assert abs(gpu_run.image.mean() / cpu.mean() - 1) < 1e-3
    want = cpu.mean(axis=2)
    shadow = want < 0.02 * want.mean()
    assert shadow.sum() > 100 and (gpu_run.image.mean(axis=2)[shadow] < 0.1 * want.mean()).all()


def test_baseline_is_finite_and_summarised(gpu, lab05_ref):
    """The report's baseline (600x600, 512 spp, 4 bounces): no NaN or Inf anywhere, and the
    summary names the GPU and times the kernel only (well under the process's wall time)."""
    import time
    start = time.perf_counter()
    run = run_lab(lab05_ref)
    wall = time.perf_counter() - start
    assert run.image.shape == (600, 600, 3)
    assert np.isfinite(run.image).all(), f"{(~np.isfinite(run.image)).sum()} non-finite values"
    assert run.image.mean() > 0
    assert gpu_name() in run.json["device"], run.json
    assert 0 < run.json["seconds"] < wall
    assert "kernel only" in run.json["timing"], run.json  # the JSON says what seconds covers


def test_bands_match_one_launch(gpu, lab05_ref):
    """An image larger than the memory allowed for it renders in bands, bit for bit the same
    (RT_LAB05_BAND_BYTES forces bands here: 7 rows of 40 pixels per band, the last shorter)."""
    settings = dict(width=40, height=45, spp=8, seed=4)
    whole = run_lab(lab05_ref, **settings).image
    os.environ["RT_LAB05_BAND_BYTES"] = str(7 * 40 * 12)
    try:
        banded = run_lab(lab05_ref, **settings).image
    finally:
        del os.environ["RT_LAB05_BAND_BYTES"]
    assert banded.tobytes() == whole.tobytes()


def test_band_too_small_is_one_line(gpu, lab05_ref):
    env = {**os.environ, "RT_LAB05_BAND_BYTES": "100"}  # less than one row
    p = subprocess.run([str(lab05_ref), "--quiet", "--width", "64", "--height", "8", "--spp",
                        "1"], capture_output=True, text=True, env=env, timeout=60)
    assert p.returncode == 3  # the device's limit, not bad input
    lines = p.stderr.strip().splitlines()
    assert len(lines) == 1 and "not enough free device memory" in lines[0], p.stderr


@pytest.fixture(scope="module")
def lab05_pristine_skeleton(nvcc, tmp_path_factory):
    """The skeleton as generated from the solution, built as `make lab05` builds it."""
    from labkit.variants import pristine_skeleton_sources
    folder = tmp_path_factory.mktemp("lab05-skeleton")
    for name, text in pristine_skeleton_sources(LAB).items():
        (folder / name).write_text(text)
    p = make("cuda-variant", f"VARIANT_LAB={LAB}", f"VARIANT={folder}")
    assert p.returncode == 0, p.stdout + p.stderr
    return folder / "lab"


def test_skeleton_is_visibly_incomplete(gpu, lab05_pristine_skeleton):
    """Until students fill it in, the skeleton builds and renders, but not the right image:
    the spheres only, one path per pixel."""
    skeleton = lab05_pristine_skeleton
    assert not check_golden(skeleton, "cornell").passed
    image = run_lab(skeleton, width=32, height=32, spp=4).image
    assert image is not None and image.max() > 0


def test_students_build_runs(gpu, lab05):
    assert run_lab(lab05, width=8, height=8, spp=1).image.shape == (8, 8, 3)


def test_time_bar(lab05_ref):
    """The baseline's kernel stays under BAR_MARGIN times the reference's time in this card's
    record (best of 3): a loose guard against a slow reference, which a slower clock of the
    card still passes. The lab's real bar is a speed target, printed by lab05-bench
    (bench/gpu/speed_targets.h)."""
    from test_lab06 import best_seconds, recorded_ms
    bar_ms = BAR_MARGIN * recorded_ms("lab05", "reference")
    seconds = best_seconds(lab05_ref)
    assert seconds * 1e3 <= bar_ms, f"{seconds * 1e3:.1f} ms against {bar_ms:.1f}"


def test_general_time_bar(lab05_ref, monkeypatch):
    """The same guard for the baseline forced to general geometry (the walls as convex quads,
    the kernel for spheres, triangles and quads), against the record's `general` shape."""
    from test_lab06 import best_seconds, recorded_ms
    bar_ms = BAR_MARGIN * recorded_ms("lab05", "general")
    monkeypatch.setenv("RT_LAB05_GEOMETRY", "general")
    seconds = best_seconds(lab05_ref)
    assert seconds * 1e3 <= bar_ms, f"{seconds * 1e3:.1f} ms against {bar_ms:.1f}"
