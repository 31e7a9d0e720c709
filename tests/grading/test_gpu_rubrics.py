"""The rubrics of the GPU labs (05-07).

Host side, wherever the tests run (CI has no GPU): each rubric sums to 100 and grades speed
only after both golden images, against the lab's own reference; the mutants still apply to
the solution and build (where nvcc is); submitted GPU sources build in the sandbox, without
the solution in view; a machine without a GPU gets one line and a complete results.json
marked for regrade; the sandbox's GPU binds are made from the device nodes and driver folders
that exist and reach a sandboxed process; the symptoms the GPU mutants show are named
(checked on lab 01's reference made to show them); and the whole rubric runs on a CPU
stand-in.

On a GPU (tools/gpu/check.sh runs these; elsewhere they skip and say why): each lab's
reference scores 100 in the sandbox, each pristine skeleton at most 10%, and each classic GPU
bug (tests/grading/gpu_mutants.py) loses the points it should, with a message naming the
symptom, and lab 06's reference handed in for lab 07 loses the layout's points. Renders are
small but for the timed ones (~0.4 s of kernel time each on an H200), so that this part stays
within a few minutes there.
"""
import concurrent.futures
import json
import os
import pathlib
import shutil
import subprocess
import sys

import pytest

from grading.checks import analytic, check_result, speed
from grading.checks.layout import check_structure_of_arrays
from grading.grade import (
    GOLDENS,
    GPU_TIMED_SCALE,
    RUBRICS,
    describe,
    grade,
    grading_order,
    passed_by_check,
)
from labkit import gpu, registry, sandbox
from labkit.harness import ROOT, build
from tests.grading import submissions
from tests.grading.gpu_mutants import (
    LAB,
    MUTANTS,
    build_cuda_folder,
    mutant_sources,
    reference_hand_in,
)
from tests.labs.cuda_env import missing_gpu, missing_nvcc

# The GPU labs: number -> folder, as labs/labs.toml declares them.
GPU_LABS = {lab: registry.lab(lab).folder for lab in registry.gpu_labs()}


# ---- host side: the rubrics ---------------------------------------------------------------

def test_the_gpu_labs_have_rubrics():
    """The labs 05-07 are the registry's GPU labs, the grader runs them on the GPU, and each
    has a GPU rubric: one timed against its own reference."""
    assert {"05", "06", "07"} <= set(GPU_LABS) == gpu.GPU_LABS <= set(RUBRICS)
    assert all(gpu.is_gpu_lab(lab) == (lab in GPU_LABS) for lab in RUBRICS)
    assert all(any(i.id == "speed" for i in RUBRICS[lab]) for lab in GPU_LABS)


def test_each_gpu_lab_is_timed_against_its_own_bar():
    """Lab 05's reference runs the small-scene kernel, past the kinds kernel its task asks for,
    so its bar is labs.toml's speed_bar; labs 06 and 07 ask the grader's three quarters."""
    names = {lab: next(i.label for i in RUBRICS[lab] if i.id == "speed") for lab in GPU_LABS}
    assert names["05"] == "speed >= 0.56x the lab 05 reference", names
    assert names["06"] == "speed >= 0.75x the lab 06 reference", names
    assert names["07"] == "speed >= 0.75x the lab 07 reference", names


@pytest.mark.parametrize("lab", sorted(GPU_LABS))
def test_each_gpu_rubric_sums_to_100(lab):
    items = RUBRICS[lab]
    assert sum(i.points for i in items) == 100, [(i.id, i.points) for i in items]
    assert len({i.id for i in items}) == len(items)
    grading_order(items)  # no circular or unknown requirement


@pytest.mark.parametrize("lab", sorted(GPU_LABS))
def test_speed_counts_only_for_correct_images(lab):
    """Speed needs both golden images (which need the hidden scene), and nothing that a
    skeleton passes by doing little (scale, reproducibility) counts without the golden image."""
    items = {i.id: i for i in RUBRICS[lab]}
    assert set(GOLDENS) <= set(items["speed"].requires)
    assert all("hidden" in items[g].requires for g in GOLDENS)
    assert "golden-cornell" in items["scale"].requires
    assert "golden-cornell" in items["reproducible"].requires
    order = [i.id for i in grading_order(RUBRICS[lab])]
    assert order.index("speed") > max(order.index(g) for g in GOLDENS)


@pytest.mark.parametrize("lab", sorted(GPU_LABS))
def test_speed_is_measured_against_the_labs_own_reference(lab, monkeypatch):
    """The speed item times the student's binary against labNN-ref, large enough that kernel
    time is not lost in the CUDA start-up, which the reference measures and both sides lose."""
    seen = {}

    def fake_speedup(binary, baseline, min_speedup, **options):
        seen.update(binary=binary, baseline=baseline, bar=min_speedup, **options)
        return check_result.CheckResult("speedup", True, "")

    monkeypatch.setattr(speed, "check_speedup", fake_speedup)
    item = next(i for i in RUBRICS[lab] if i.id == "speed")
    item.run("student-binary")
    assert seen["binary"] == "student-binary"
    assert seen["baseline"] == seen["overhead_reference"] == ROOT / f"lab{lab}-ref"
    assert seen["scale"] == GPU_TIMED_SCALE >= 8 and 0 < seen["bar"] < 1
    # At least 8e8 paths: far above the ~0.3 s start-up on any GPU the kit targets (each
    # lab's spp gives GPU_TIMED_SECONDS at the record's throughput: test_gpu_figures.py).
    assert seen["spp"] * (64 * seen["scale"]) ** 2 >= 8e8


# ---- host side: the mutants still are what they say -------------------------------------------

@pytest.mark.parametrize("name", sorted(MUTANTS))
def test_each_mutant_applies_to_the_solution_and_builds(name, tmp_path):
    """Each edit finds its text in today's solution (mutant_sources raises otherwise) and the
    result compiles: a mutant the solution has drifted away from would test nothing."""
    files = mutant_sources(name)
    file = MUTANTS[name].file
    assert files[file] != reference_hand_in(LAB)[file]
    if reason := missing_nvcc():
        pytest.skip(reason)
    assert build_cuda_folder(LAB, tmp_path / name, files).is_file()


# ---- host side: submitted GPU sources are built in the sandbox --------------------------------

@pytest.fixture
def nvcc_and_sandbox():
    if reason := missing_nvcc() or sandbox.probe():
        pytest.skip(reason)
    build("lab01-ref")  # the driver objects the sandboxed build links (it cannot write build/)


def test_lab07_sources_build_in_the_sandbox(nvcc_and_sandbox, tmp_path):
    """Lab 07's build reads lab 06's reference queue and stage loop (common/wavefront/);
    without them in view its skeleton does not compile in the sandbox."""
    from grading.grade import build_lab
    from labkit.variants import pristine_skeleton_sources
    for name, text in pristine_skeleton_sources(GPU_LABS["07"]).items():
        (tmp_path / name).write_text(text)
    binary, errors = build_lab("07", tmp_path, trusted=False)
    assert binary is not None and binary.is_file(), errors


def test_a_gpu_submission_including_the_solution_is_refused(nvcc_and_sandbox, tmp_path):
    """As for the CPU labs: a lab 05 render.cu that #includes the solution by its path is
    refused in one line naming the file, before nvcc runs; the pristine hand-in builds."""
    from grading.grade import build_lab
    from labkit.variants import pristine_skeleton_sources
    solution = ROOT / "labs" / GPU_LABS["05"] / "solution"
    (tmp_path / "render.cu").write_text(f'#include "{solution}/render.cu"\n')
    # The other file lab 05's students write: a hand-in without it does not build at all.
    (tmp_path / "render_kernel.cuh").write_text(
        pristine_skeleton_sources(GPU_LABS["05"])["render_kernel.cuh"]
    )
    binary, errors = build_lab("05", tmp_path, trusted=False)
    assert binary is None and errors.startswith("refused: render.cu: #include"), errors
    assert "\n" not in errors, errors
    (tmp_path / "render.cu").write_text(pristine_skeleton_sources(GPU_LABS["05"])["render.cu"])
    binary, errors = build_lab("05", tmp_path, trusted=False)
    assert binary is not None, errors


# ---- host side: a machine without a GPU ------------------------------------------------------

def test_no_gpu_refuses_in_process_and_marks_for_regrade(tmp_path, monkeypatch):
    monkeypatch.setattr(gpu, "missing_gpu", lambda: "this machine has no NVIDIA GPU (test)")
    results = grade("05", tmp_path / "no-binary-needed", tmp_path, trusted=True)
    assert results["score"] == 0, describe(results)
    assert all(t["status"] == "failed" and t["extra_data"]["regrade"] for t in results["tests"])
    assert all("renders on an NVIDIA GPU" in t["output"] for t in results["tests"])
    assert "\n" not in results["output"] and "marked for regrade" in results["output"]


def test_a_reference_that_cannot_reach_the_gpu_refuses_the_grade(tmp_path, monkeypatch):
    """nvidia-smi sees a GPU but CUDA programs cannot use it (here: a stand-in reference that
    fails as lab 05's does without a GPU): the machine's fault, said in one line, regrade."""
    from grading import grade as grading
    failing = tmp_path / "lab05-ref"
    failing.write_text("#!/bin/sh\necho 'error: GPU: no CUDA GPU found (stand-in)' >&2\nexit 3\n")
    failing.chmod(0o755)
    monkeypatch.setattr(gpu, "missing_gpu", lambda: None)
    monkeypatch.setattr(grading, "gpu_reference", lambda lab: failing)
    results = grade("05", failing, tmp_path, trusted=True)
    assert results["score"] == 0 and "\n" not in results["output"], results["output"]
    assert results["output"] == ("lab 05's reference cannot render on this machine's GPU "
                                 "(trusted): error: GPU: no CUDA GPU found (stand-in); "
                                 "not graded, marked for regrade"), results["output"]
    assert all(t["extra_data"]["regrade"] for t in results["tests"])


def path_without_nvidia_smi(tmp_path) -> str:
    """A PATH with what the grader may call, nvidia-smi left out."""
    bin_dir = tmp_path / "bin"
    bin_dir.mkdir()
    for tool in ("make", "prlimit", "bwrap", "git", "g++", "nvcc"):
        found = shutil.which(tool)
        if found:
            (bin_dir / tool).symlink_to(found)
    return str(bin_dir)


@pytest.mark.parametrize("lab", sorted(GPU_LABS))
def test_no_gpu_is_one_line_and_a_results_file(lab, tmp_path):
    """From the command line: one error line, exit status 2, a results.json with every test
    failed and marked for regrade, before anything is built."""
    out = tmp_path / "results.json"
    p = subprocess.run([sys.executable, "-m", "grading.grade", lab, "--trusted", "--binary",
                        str(tmp_path / "lab"), "--results", str(out)], cwd=ROOT,
                       capture_output=True, text=True, timeout=120,
                       env={**os.environ, "PATH": path_without_nvidia_smi(tmp_path)})
    assert p.returncode == 2, p.stderr
    assert p.stderr.count("\n") == 1 and p.stderr.startswith("error: "), p.stderr
    assert f"lab {lab} renders on an NVIDIA GPU" in p.stderr and "nvidia-smi" in p.stderr
    results = json.loads(out.read_text())
    assert results["score"] == 0 and len(results["tests"]) == len(RUBRICS[lab])
    assert all(t["status"] == "failed" and t["extra_data"]["regrade"] for t in results["tests"])


# ---- host side: the sandbox's view of the GPU ------------------------------------------------

def test_gpu_binds_are_built_from_what_exists(tmp_path):
    dev = tmp_path / "dev"
    dev.mkdir()
    for name in ("nvidiactl", "nvidia-uvm", "nvidia0", "nvidia1", "null", "video0"):
        (dev / name).touch()
    (dev / "nvidia-caps").mkdir()
    with_driver, without_driver, from_env = (tmp_path / d for d in ("lib", "other", "env"))
    for folder in (with_driver, without_driver, from_env):
        folder.mkdir()
    (with_driver / "libcuda.so.1").touch()
    (from_env / "libcuda.so").touch()
    (without_driver / "libm.so.6").touch()
    libs = gpu.lib_dirs([str(with_driver), str(without_driver), str(tmp_path / "absent")],
                        environment=f"{from_env}:{with_driver}")
    assert libs == [str(from_env), str(with_driver)]
    args = gpu.sandbox_args(dev=str(dev), libs=libs, sysfs=("/sys/bus/pci",), only=None)
    assert args == [
        "--dev-bind", f"{dev}/nvidia-caps", "/dev/nvidia-caps",
        "--dev-bind", f"{dev}/nvidia-uvm", "/dev/nvidia-uvm",
        "--dev-bind", f"{dev}/nvidia0", "/dev/nvidia0",
        "--dev-bind", f"{dev}/nvidia1", "/dev/nvidia1",
        "--dev-bind", f"{dev}/nvidiactl", "/dev/nvidiactl",
        "--ro-bind-try", "/sys/bus/pci", "/sys/bus/pci",
        "--ro-bind", str(from_env), str(from_env),
        "--ro-bind", str(with_driver), str(with_driver),
        "--setenv", "LD_LIBRARY_PATH", f"{from_env}:{with_driver}"]
    # A grader given one GPU (grading/classes/batch.py) shows that GPU's node only, found by its
    # minor number, with the nodes all GPUs share; an index nvidia-smi does not list shows all.
    one = gpu.sandbox_args(dev=str(dev), libs=[], sysfs=(),
                           only=gpu.assigned_node({"CUDA_VISIBLE_DEVICES": "1"}, {"1": "0"}))
    assert [a for a in one if a.startswith("/dev/")] == [
        "/dev/nvidia-caps", "/dev/nvidia-uvm", "/dev/nvidia0", "/dev/nvidiactl"]
    assert gpu.assigned_node({"CUDA_VISIBLE_DEVICES": "0,1"}, {"0": "0", "1": "1"}) is None
    assert gpu.assigned_node({"CUDA_VISIBLE_DEVICES": "3"}, {"0": "0"}) is None
    assert gpu.assigned_node({}, {"0": "0"}) is None
    every = gpu.sandbox_args(dev=str(dev), libs=[], sysfs=(), only=None)
    assert "/dev/nvidia1" in every and "/dev/nvidia0" in every
    empty = tmp_path / "empty"  # no device node: no GPU, nothing to show
    empty.mkdir()
    assert gpu.sandbox_args(dev=str(empty), libs=libs) == []


def test_a_gpus_node_is_found_through_its_pci_address(tmp_path, monkeypatch):
    """nvidia-smi's index -> the device node's minor number, through the GPU's PCI address
    and the driver's folder for it: the two numberings differ here, as they may on a host."""
    bin_dir, proc = tmp_path / "bin", tmp_path / "gpus"
    bin_dir.mkdir()
    smi = bin_dir / "nvidia-smi"
    smi.write_text("#!/bin/sh\nprintf '0, 00000000:00:06.0\\n1, 00000000:00:07.0\\n'\n")
    smi.chmod(0o755)
    for bus, minor in (("0000:00:06.0", 1), ("0000:00:07.0", 0)):
        (proc / bus).mkdir(parents=True)
        (proc / bus / "information").write_text(f"Model: \t\t X\nDevice Minor: \t {minor}\n")
    monkeypatch.setenv("PATH", f"{bin_dir}:{os.environ['PATH']}")
    assert gpu.gpu_minor_numbers(str(proc)) == {"0": "1", "1": "0"}
    assert gpu.gpu_minor_numbers(str(tmp_path / "absent")) == {}


def test_sandboxed_cuda_builds_target_the_gpu_here(monkeypatch, tmp_path):
    """A submission's CUDA build in the sandbox (where nvidia-smi cannot reach the driver)
    gets the architecture of the GPU the grader sees, not cuda.mk's six-target fallback; with
    no GPU, one architecture: the build only shows whether the sources compile."""
    from grading import compile as grading_compile
    seen = []

    class Recorder:
        def __init__(self, **_):
            pass

        def __enter__(self):
            return self

        def __exit__(self, *_):
            return False

        def bind(self, *_args, **_kwargs):
            pass

        def close_to_others(self, *_args):
            pass

        def run(self, command, _limits):
            seen.append(command)
            return sandbox.Outcome(returncode=2, stdout="", stderr="stand-in", wall_seconds=0,
                                   cpu_seconds=None)

    monkeypatch.setattr(grading_compile, "Runner", Recorder)
    (tmp_path / "render.cu").write_text("// a hand-in\n")
    (tmp_path / "render.cpp").write_text("// a hand-in\n")
    monkeypatch.setattr(gpu, "cuda_arch_flags", lambda: "-gencode arch=compute_80,code=sm_80")
    grading_compile.build_in_sandbox("05-cuda-mega", tmp_path, target="cuda-variant")
    assert "CUDA_ARCH=-gencode arch=compute_80,code=sm_80" in seen[-1], seen[-1]
    monkeypatch.setattr(gpu, "cuda_arch_flags", lambda: "")
    grading_compile.build_in_sandbox("05-cuda-mega", tmp_path, target="cuda-variant")
    assert f"CUDA_ARCH={grading_compile.COMPILE_CHECK_ARCH}" in seen[-1], seen[-1]
    assert grading_compile.COMPILE_CHECK_ARCH.count("-gencode") == 1
    grading_compile.build_in_sandbox("01-serial", tmp_path)  # a CPU lab: never
    assert not any(a.startswith("CUDA_ARCH=") for a in seen[-1]), seen[-1]


def test_only_gpu_runs_see_the_gpu(monkeypatch):
    """A CPU lab's sandbox gets no GPU binds; a GPU lab's gets them after `--dev /dev` (which
    would hide them) and `--clearenv` (which would drop LD_LIBRARY_PATH)."""
    marker = ["--dev-bind", "/dev/nvidia0", "/dev/nvidia0"]
    monkeypatch.setattr(gpu, "sandbox_args", lambda: marker)
    limits = sandbox.Limits()
    with sandbox.Runner(trusted=False) as r:
        cpu_cmd = r.command(["true"], limits, {})
    with sandbox.Runner(trusted=False, gpu=True) as r:
        gpu_cmd = r.command(["true"], limits, {})
    assert "--dev-bind" not in cpu_cmd
    at = gpu_cmd.index("--dev-bind")
    assert gpu_cmd[at:at + 3] == marker
    assert gpu_cmd.index("--dev") < at and gpu_cmd.index("--clearenv") < at


@pytest.fixture
def open_folder():
    """A folder the sandbox's unprivileged user can read (pytest's tmp_path may be closed
    to it), as it can /dev and /usr."""
    import tempfile
    with tempfile.TemporaryDirectory(prefix="gpu-binds-") as folder:
        os.chmod(folder, 0o755)
        yield pathlib.Path(folder)


def test_a_sandboxed_run_sees_the_gpu_binds(open_folder, monkeypatch):
    """bubblewrap takes the binds as built, in that order: a stand-in device node appears
    under /dev, LD_LIBRARY_PATH survives --clearenv, the driver's folder is readable."""
    if reason := sandbox.probe():
        pytest.skip(f"the grader's sandbox is not available here: {reason} (make deps)")
    dev, lib = open_folder / "dev", open_folder / "lib"
    for folder in (dev, lib):
        folder.mkdir(mode=0o755)
    for path in (dev / "nvidia0", lib / "libcuda.so.1"):
        path.write_text("stand-in")
        path.chmod(0o644)
    real = gpu.sandbox_args
    monkeypatch.setattr(gpu, "sandbox_args", lambda: real(dev=str(dev), libs=[str(lib)]))
    script = 'cat /dev/nvidia0; echo " $LD_LIBRARY_PATH"; cat "$LD_LIBRARY_PATH/libcuda.so.1"'
    with sandbox.Runner(trusted=False, gpu=True) as r:
        out = r.run(["/bin/sh", "-c", script], sandbox.Limits(wall_seconds=20))
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["stand-in", str(lib), "stand-in"], out
    with sandbox.Runner(trusted=False) as r:  # a CPU lab's run: none of it
        out = r.run(["/bin/sh", "-c", "ls /dev/nvidia0"], sandbox.Limits(wall_seconds=20))
    assert out.returncode != 0, out


# ---- host side: the symptoms are named --------------------------------------------------------
# The GPU mutants' symptoms, shown by lab 01's reference with its image altered after the
# fact: all black (read back before written), or transposed (x and y swapped).

def altered_reference(folder: pathlib.Path, change: str) -> pathlib.Path:
    return submissions.altered_reference(folder, change, build("lab01-ref")[0])


def test_black_pixels_are_named(tmp_path):
    result = analytic.check_sphere_interior(altered_reference(tmp_path, "image * 0"))
    assert not result.passed
    assert "256 of 256 pixels are exactly black" in result.detail, result.detail
    assert "copied back before the kernel had written them" in result.detail


def test_swapped_x_and_y_are_named(tmp_path):
    result = analytic.check_lit_plane(altered_reference(tmp_path, "image.transpose(1, 0, 2)"))
    assert not result.passed
    assert "right with x and y swapped" in result.detail, result.detail
    right = analytic.check_lit_plane(build("lab01-ref")[0])
    assert right.passed and "swapped" not in right.detail, right.detail


def reporting_layout(folder: pathlib.Path, layout) -> pathlib.Path:
    """Lab 01's reference with `layout` added to its --json (left out when None): what a
    wavefront lab reports about its path pool (common/wavefront/layout_probe.cuh)."""
    script = folder / f"layout-{abs(hash(json.dumps(layout)))}"
    script.write_text(f"""#!{sys.executable}
import json, subprocess, sys
p = subprocess.run([{str(build("lab01-ref")[0])!r}, *sys.argv[1:]], capture_output=True, text=True)
sys.stderr.write(p.stderr)
out, layout = p.stdout, json.loads({json.dumps(json.dumps(layout))})
if layout is not None and out.startswith("{{"):
    out = json.dumps({{**json.loads(out), "layout": layout}}) + "\\n"
sys.stdout.write(out)
sys.exit(p.returncode)
""")
    script.chmod(0o755)
    return script


@pytest.mark.parametrize("layout, passes, says", [
    ({"name": "SoA", "bytes_between_neighbours": 4}, True, "4 bytes apart (a structure of arrays)"),
    ({"name": "AoS", "bytes_between_neighbours": 48}, False, "48 bytes apart"),
    ({"name": "SoA", "bytes_between_neighbours": -1}, False, "does not store what it is given"),
    ({"name": "SoA", "bytes_between_neighbours": "4"}, False, "does not report"),
    (None, False, "does not report its pool's layout"),
])
def test_the_layout_check_reads_the_probe(tmp_path, layout, passes, says):
    """Lab 07's layout check on stand-ins reporting each kind of probe result: only a
    structure of arrays passes, and a pool that stores nothing, or a program that does not
    say, fails with a reason."""
    result = check_structure_of_arrays(reporting_layout(tmp_path, layout))
    assert result.passed == passes and says in result.detail, result.detail


def test_a_timed_render_is_checked_at_the_golden_size():
    """The timed render is the golden view `scale` times larger; box-filtered, a correct one
    is the golden image (here: the golden image itself, upsampled), a transposed one is not."""
    import numpy as np

    from labkit.harness import golden
    g = golden("cornell")
    big = np.kron(g.mean, np.ones((GPU_TIMED_SCALE, GPU_TIMED_SCALE, 1), np.float32))
    assert speed.box_filtered(big, GPU_TIMED_SCALE).shape == g.mean.shape
    assert speed.wrong_timed_image(big, 64, GPU_TIMED_SCALE) is None
    wrong = speed.wrong_timed_image(big.transpose(1, 0, 2), 64, GPU_TIMED_SCALE)
    assert wrong and wrong.startswith("the timed render is wrong"), wrong


def test_a_gpu_rubric_end_to_end_on_a_cpu_stand_in(tmp_path, monkeypatch):
    """Lab 05's rubric, its GPU run policy and its speed check (a 640x640 timed render,
    box-filtered, start-up subtracted) with lab 01's reference standing in for the GPU and
    for lab 05's reference, at 4 spp: full marks in the sandbox, and the transposed image
    keeps only the points of the checks that cannot see positions."""
    from grading import grade as grading
    reference = build("lab01-ref")[0]
    monkeypatch.setattr(gpu, "missing_gpu", lambda: None)
    monkeypatch.setattr(grading, "gpu_reference", lambda lab: reference)
    monkeypatch.setattr(grading, "GPU_TIMED_SPP", {"05": 4})
    monkeypatch.setitem(RUBRICS, "05", grading.gpu_rubric("05"))
    if reason := sandbox.probe():
        pytest.skip(f"the grader's sandbox is not available here: {reason} (make deps)")
    results = grade("05", reference, tmp_path)
    assert results["score"] == 100, describe(results)
    speed = next(t["output"] for t in results["tests"] if t["extra_data"]["check"] == "speed")
    assert "less" in speed and "of start-up measured on the reference" in speed, speed
    transposed = altered_reference(tmp_path, "image.transpose(1, 0, 2)")
    results = grade("05", transposed, tmp_path, trusted=True)
    assert results["score"] == 15, describe(results)


# ---- on the GPU -------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def on_gpu():
    if reason := missing_nvcc() or missing_gpu():
        pytest.skip(reason)
    build("lab01-ref", *(f"lab{lab}-ref" for lab in GPU_LABS))


@pytest.fixture(scope="module")
def gpu_builds(on_gpu, tmp_path_factory):
    """Every pristine skeleton and every mutant, built at once (one nvcc each, in parallel):
    name -> binary."""
    from labkit.variants import pristine_skeleton_sources
    root = tmp_path_factory.mktemp("gpu-builds")
    folders = {f"skeleton-{lab}": (GPU_LABS[lab], pristine_skeleton_sources(GPU_LABS[lab]))
               for lab in GPU_LABS}
    folders.update({name: (LAB, mutant_sources(name)) for name in MUTANTS})
    with concurrent.futures.ThreadPoolExecutor(len(folders)) as pool:
        futures = {name: pool.submit(build_cuda_folder, lab, root / name, files)
                   for name, (lab, files) in folders.items()}
        return {name: f.result() for name, f in futures.items()}


@pytest.mark.parametrize("lab", sorted(GPU_LABS))
def test_reference_scores_100_in_the_sandbox(on_gpu, lab, tmp_path):
    """Graded as a submission is, in the sandbox: this is what shows that a CUDA program
    reaches the GPU there (device nodes, driver library) and that the reference meets its
    own speed bar."""
    if reason := sandbox.probe():
        pytest.skip(f"the grader's sandbox is not available here: {reason} (make deps)")
    results = grade(lab, ROOT / f"lab{lab}-ref", tmp_path)
    assert results["score"] == 100, describe(results)


@pytest.mark.parametrize("lab", sorted(GPU_LABS))
def test_skeleton_scores_at_most_ten_percent(gpu_builds, lab, tmp_path):
    results = grade(lab, gpu_builds[f"skeleton-{lab}"], tmp_path, trusted=True)
    assert results["score"] <= 10, describe(results)


def test_missing_synchronisation_loses_every_point(gpu_builds, tmp_path):
    """Pixels read back before the kernel wrote them: black images, named as such."""
    results = grade("05", gpu_builds["missing-sync"], tmp_path, trusted=True)
    assert results["score"] == 0, f"{MUTANTS['missing-sync'].what}:\n{describe(results)}"
    interior = next(t for t in results["tests"] if t["extra_data"]["check"] == "sphere-interior")
    assert "exactly black" in interior["output"], describe(results)
    assert "before the kernel had written them" in interior["output"], describe(results)


def test_swapped_index_loses_what_shows_position(gpu_builds, tmp_path):
    """x and y swapped: uniform images (the sphere interior, the glass pane's mean) cannot
    tell, the lit plane names it, and the hidden scene fails, so neither golden image, nor
    anything gated on them, counts."""
    results = grade("05", gpu_builds["swapped-index"], tmp_path, trusted=True)
    assert results["score"] == 15, f"{MUTANTS['swapped-index'].what}:\n{describe(results)}"
    passed = passed_by_check(results)
    assert passed["sphere-interior"] and passed["glass-pane"], describe(results)
    assert not passed["lit-plane"] and not passed["hidden"], describe(results)
    plane = next(t for t in results["tests"] if t["extra_data"]["check"] == "lit-plane")
    assert "x and y swapped" in plane["output"], describe(results)


def test_lab06_handed_in_for_lab07_loses_the_layout_points(on_gpu, tmp_path):
    """Lab 07's lesson is the pool's layout: lab 06's reference (the AoS pool, the same
    image) is correct, and on the H200 within 10% of the SoA pool's speed (74 against 68 ms
    on the baseline), above the 0.75 bar. What it lacks is the layout, which the probe
    finds: the same field of neighbouring paths a 48-byte record apart."""
    results = grade("07", ROOT / "lab06-ref", tmp_path, trusted=True)
    passed = passed_by_check(results)
    assert not passed.pop("structure-of-arrays"), describe(results)
    assert all(passed.values()), describe(results)
    assert results["score"] == 90, describe(results)
    layout = next(t["output"] for t in results["tests"]
                  if t["extra_data"]["check"] == "structure-of-arrays")
    assert "48 bytes apart" in layout, layout


def test_no_gpu_inside_a_slurm_job_names_the_node_for_staff():
    """make grade-gpu landed on a node whose GPU does not work: running it again is no advice;
    the node's name for course staff is."""
    from grading.grade import no_gpu_line
    inside = no_gpu_line("05", "no NVIDIA GPU was found", {"SLURM_JOB_ID": "4242",
                                                          "SLURMD_NODENAME": "gpu-node-7"})
    assert "gpu-node-7" in inside and "4242" in inside and "course staff" in inside
    assert "make grade-gpu" not in inside and "\n" not in inside
    assert "make grade-gpu" in no_gpu_line("05", "no NVIDIA GPU was found", {})
