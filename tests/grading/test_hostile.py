"""The grader against a catalogue of broken and hostile submissions (tests/grading/
submissions.py): each loses the points it should, with a message naming the symptom, and
leaves the grader, the repository and the machine as they were."""
import contextlib
import hashlib
import json
import os
import pathlib
import shutil
import signal
import subprocess
import sys
import time

import pytest

from grading.grade import describe, grade, passed_by_check
from labkit import sandbox
from labkit.harness import GOLDEN, ROOT
from tests.grading import submissions as sub


@pytest.fixture(autouse=True)
def needs_sandbox():
    reason = sandbox.probe()
    if reason:  # `make deps` installs bubblewrap; without it the grader grades nothing
        pytest.fail(f"the grader's sandbox is not available here: {reason}")


def outputs(results) -> list[str]:
    return [t["output"] for t in results["tests"]]


def survivors(marker: str) -> list[str]:
    """Processes whose command line holds `marker` (a sleep length no one else uses)."""
    found = []
    for entry in pathlib.Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                cmdline = (entry / "cmdline").read_bytes().replace(b"\0", b" ").decode()
            except OSError:
                continue
            if marker in cmdline:
                found.append(f"{entry.name}: {cmdline}")
    return found


def tree_digest(folder: pathlib.Path) -> str:
    h = hashlib.sha256()
    for f in sorted(folder.rglob("*")):
        if f.is_file():
            h.update(str(f).encode() + f.read_bytes())
    return h.hexdigest()


def test_exec_the_reference_wrapper_scores_nothing(tmp_path):
    results = grade("01", sub.exec_reference(tmp_path), tmp_path)
    assert results["score"] == 0, describe(results)
    assert all("exited with status 127" in o or "not graded" in o for o in outputs(results)), \
        describe(results)
    # Trusted (make grade at home), where the repository is in view, the same wrapper works:
    # the sandbox is what stops it.
    assert grade("01", sub.exec_reference(tmp_path), tmp_path, trusted=True)["score"] == 100


def test_lying_about_seconds_earns_no_speed(tmp_path):
    """Serial, correct, and reporting a render time of 1 ms: the grader's own clock decides."""
    results = grade("02", sub.lying_about_seconds(tmp_path), tmp_path)
    passed = passed_by_check(results)
    assert passed["golden-cornell"] and passed["golden-showcase"], describe(results)
    assert not passed["speedup"], describe(results)
    speedup = next(t["output"] for t in results["tests"] if t["extra_data"]["check"] == "speedup")
    assert "wall clock measured by the grader" in speedup, speedup


def test_one_nan_pixel_fails_every_image_check(tmp_path):
    results = grade("01", sub.nan_pixel(tmp_path), tmp_path)
    assert results["score"] == 0, describe(results)
    for t in results["tests"]:
        assert "1 NaN" in t["output"] or t["output"].startswith("not graded until"), describe(
            results
        )


def test_nan_only_in_the_scaled_scenes_fails_the_scale_check(tmp_path):
    results = grade("01", sub.nan_pixel(tmp_path, only_in_scaled_scenes=True), tmp_path)
    passed = passed_by_check(results)
    assert not passed.pop("scale"), describe(results)
    assert all(passed.values()), describe(results)
    assert results["score"] == 90


def test_copying_the_golden_images_earns_nothing(tmp_path):
    """The golden images are in the repository; the hidden scene, made from a secret at
    grading time, is not, and the golden images count only when it passes."""
    results = grade("01", sub.golden_copier(tmp_path), tmp_path)
    assert results["score"] == 0, describe(results)
    golden = next(t for t in results["tests"] if t["extra_data"]["check"] == "golden-cornell")
    assert golden["output"] == "not graded until the hidden scene passes", describe(results)


def test_the_hidden_scene_depends_on_the_secret():
    from grading.checks.hidden import hidden_scene
    assert hidden_scene("a") == hidden_scene("a") != hidden_scene("b")


def test_a_hang_with_a_grandchild_is_killed_tree_and_all(tmp_path):
    marker = "987651"
    start = time.perf_counter()
    results = grade("01", sub.hang_with_grandchild(tmp_path, marker), tmp_path, run_seconds=1)
    took = time.perf_counter() - start
    assert results["score"] == 0, describe(results)
    assert all("timed out after 1 s" in o or "not graded" in o for o in outputs(results)), \
        describe(results)
    assert took < 30, f"grading a hanging program took {took:.0f} s"
    assert not survivors(marker), survivors(marker)


def test_a_crash_is_named(tmp_path):
    results = grade("01", sub.crash(tmp_path), tmp_path)
    assert results["score"] == 0
    assert "segmentation fault" in results["tests"][0]["output"], describe(results)


def test_non_utf8_stderr_does_not_cost_points(tmp_path):
    results = grade("01", sub.non_utf8_stderr(tmp_path), tmp_path)
    assert results["score"] == 100, describe(results)


def test_the_sandbox_hides_solutions_golden_data_and_the_repository(tmp_path):
    """A spy that tries to read solutions and golden data, to overwrite the golden data and to
    write into the repository and /tmp: nothing of it works, and it still renders correctly."""
    targets = {
        "read solution": ROOT / "labs" / "01-serial" / "solution" / "render.cpp",
        "read golden": GOLDEN / "cornell" / "golden.pfm",
        "read grader": ROOT / "grading" / "grade.py",
        "write golden": GOLDEN / "cornell" / "meta.json",
        "write repository": ROOT / "spy-was-here",
        "write tmp outside": tmp_path / "spy-was-here",
    }
    before = tree_digest(GOLDEN)
    meta = targets["write golden"].read_bytes()
    binary = sub.spy(tmp_path, targets)
    from labkit.harness import RunPolicy, policy, run_lab
    try:
        with policy(RunPolicy(trusted=False)):
            run = run_lab(binary, width=8, height=8, spp=1)
        assert "SPY" not in run.stderr, run.stderr
        results = grade("01", binary, tmp_path)
        assert results["score"] == 100, describe(results)
        assert tree_digest(GOLDEN) == before
        assert not (ROOT / "spy-was-here").exists() and not (tmp_path / "spy-was-here").exists()
    finally:  # had the sandbox leaked, the golden data must still be whole for other tests
        if targets["write golden"].read_bytes() != meta:
            targets["write golden"].write_bytes(meta)
        (ROOT / "spy-was-here").unlink(missing_ok=True)
    # The same spy, trusted, reads the solution: the test would see a leak.
    with policy(RunPolicy(trusted=True)):
        trusted = run_lab(binary, width=8, height=8, spp=1)
    assert "SPY read solution" in trusted.stderr, trusted.stderr
    targets["write golden"].write_bytes(meta)  # the trusted spy did overwrite it
    (ROOT / "spy-was-here").unlink(missing_ok=True)


@pytest.mark.parametrize("stream", ["stdout", "stderr"])
def test_an_output_flood_is_cut(tmp_path, stream):
    """1 GiB on stdout or 10 MiB on stderr: the grader keeps 1 MiB, stops the program, says
    so, stays small itself and writes a small results.json."""
    size = (1 << 30) if stream == "stdout" else 10 << 20
    binary = sub.flood(tmp_path, stream, size)
    out = tmp_path / "results.json"
    p = subprocess.Popen([sys.executable, "-m", "grading.grade", "01", "--binary", str(binary),
                          "--results", str(out), "--heatmaps", str(tmp_path / "maps")],
                         cwd=ROOT, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    _, status, usage = os.wait4(p.pid, 0)
    p.returncode = os.waitstatus_to_exitcode(status)
    assert p.returncode == 0, p.stderr.read()
    results = json.loads(out.read_text())
    assert results["score"] == 0
    assert f"wrote more than 1024 KiB on {stream}" in results["tests"][0]["output"], describe(
        results
    )
    assert out.stat().st_size < 100_000, out.stat().st_size
    assert usage.ru_maxrss < 400_000, f"the grader grew to {usage.ru_maxrss // 1024} MiB"


def test_no_network(tmp_path):
    client = sub.socket_client(tmp_path)
    with sub.loopback_server() as port:
        with sandbox.Runner(trusted=False) as r:
            inside = r.run([r.input(client), port])
        with sandbox.Runner(trusted=True) as r:
            outside = r.run([r.input(client), port])
    assert inside.returncode == 3 and "connect" in inside.stderr, (inside.returncode, inside.stderr)
    assert outside.returncode == 0, outside.stderr  # the client does work: the test can fail


def test_a_compile_error_still_writes_results(tmp_path):
    src = tmp_path / "src"
    src.mkdir()
    (src / "render.cpp").write_text("int broken( { return 0 }\n")
    out = tmp_path / "results.json"
    p = subprocess.run([sys.executable, "-m", "grading.grade", "01", "--sources", str(src),
                        "--results", str(out)], cwd=ROOT, capture_output=True, text=True,
                       timeout=300)
    assert p.returncode == 1, p.stderr
    results = json.loads(out.read_text())
    assert results["score"] == 0
    assert "does not compile" in results["output"] and "error:" in results["output"], results
    assert all("does not compile" in o for o in outputs(results))
    # the file by its own name, not by the grader's temporary folder
    assert "render.cpp:1:" in results["output"] and "students-tree-" not in results["output"]


def test_including_the_solution_is_refused_in_one_line(tmp_path):
    """A render.cpp that #includes the solution by its path (compiled into every build) is
    refused before anything is built, in one line naming the file (grading/source_rules.py);
    the sandboxed compiler, which sees no solution, is the wall behind it
    (test_the_reference_objects_are_out_of_the_compilers_reach)."""
    from grading.grade import build_lab
    solution = ROOT / "labs" / "01-serial" / "solution" / "render.cpp"
    (tmp_path / "render.cpp").write_text(f'#include "{solution}"\n')
    binary, errors = build_lab("01", tmp_path, trusted=False)
    assert binary is None and errors.startswith("refused: render.cpp: #include"), errors
    assert "\n" not in errors, errors


def test_an_interrupted_grader_leaves_complete_results_and_no_processes(tmp_path):
    marker = "987652"
    binary = sub.hang_with_grandchild(tmp_path, marker)
    out = tmp_path / "results.json"
    p = subprocess.Popen([sys.executable, "-m", "grading.grade", "01", "--binary", str(binary),
                          "--results", str(out), "--run-seconds", "60"], cwd=ROOT,
                         stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    deadline = time.time() + 60
    while not survivors(marker) and time.time() < deadline:  # the submission runs
        time.sleep(0.1)
    assert survivors(marker), "the hanging submission never started"
    p.send_signal(signal.SIGTERM)
    assert p.wait(timeout=30) == 130, p.stderr.read()
    results = json.loads(out.read_text())
    assert results["score"] == 0 and "interrupted" in results["output"], results
    assert all(t["status"] == "failed" for t in results["tests"])
    time.sleep(0.5)
    assert not survivors(marker), survivors(marker)


def test_no_sandbox_no_grading(tmp_path, monkeypatch):
    """Where bubblewrap is missing the grader refuses untrusted code, in one line, and still
    writes results; --trusted (make grade, your own code) grades without it."""
    monkeypatch.setattr(sandbox, "probe", lambda: "bubblewrap (bwrap) is not installed")
    results = grade("01", sub.REFERENCE, tmp_path)
    assert results["score"] == 0 and results["output"].startswith("refusing"), results["output"]
    assert "\n" not in results["output"]
    trusted = grade("01", sub.REFERENCE, tmp_path, trusted=True)
    assert trusted["score"] == 100, describe(trusted)


def test_a_missing_binary_still_writes_results(tmp_path):
    out = tmp_path / "results.json"
    p = subprocess.run([sys.executable, "-m", "grading.grade", "01", "--binary",
                        str(tmp_path / "nothing"), "--results", str(out)], cwd=ROOT,
                       capture_output=True, text=True, timeout=120)
    assert p.returncode == 2 and "no such binary" in p.stderr
    assert json.loads(out.read_text())["score"] == 0


def test_no_sandbox_is_one_line_from_the_command_line(tmp_path):
    """bubblewrap hidden from PATH: one error line, exit 2, and a results.json saying so."""
    bin_dir = tmp_path / "bin"
    bin_dir.mkdir()
    for tool in ("make", "prlimit", "git", "g++"):  # what the grader may call, bwrap aside
        found = shutil.which(tool)
        if found:
            (bin_dir / tool).symlink_to(found)
    out = tmp_path / "results.json"
    p = subprocess.run([sys.executable, "-m", "grading.grade", "01", "--binary",
                        str(sub.REFERENCE), "--results", str(out)], cwd=ROOT, capture_output=True,
                       text=True, timeout=120, env={**os.environ, "PATH": str(bin_dir)})
    assert p.returncode == 2, p.stderr
    assert p.stderr.count("\n") == 1 and "bubblewrap (bwrap) is not installed" in p.stderr, p.stderr
    assert json.loads(out.read_text())["output"].startswith("refusing")


# ---- hand-ins built in the students' tree (grading/students_tree.py) ----------------------

def handin(folder: pathlib.Path, files: dict[str, str]) -> pathlib.Path:
    for name, text in files.items():
        (folder / name).parent.mkdir(parents=True, exist_ok=True)
        (folder / name).write_text(text)
    return folder


def solution_text(lab_folder: str, name: str) -> str:
    path = ROOT / "labs" / lab_folder / "solution" / name
    return (path if path.exists() else ROOT / "common" / "core" / name).read_text()


def grade_sources(lab: str, folder: pathlib.Path, tmp_path: pathlib.Path) -> dict:
    from grading.grade import build_lab
    binary, errors = build_lab(lab, folder, trusted=False)
    assert binary is not None, errors
    return grade(lab, binary, tmp_path)


def test_a_missing_shared_file_is_the_skeletons_not_the_solution(tmp_path):
    """Lab 01's render.cpp done, its path_steps.h left out: in the course repository the
    shared path_steps.h is the solution; a student's tree has the skeleton's, and so does the
    grader's build. At most what the skeleton earns."""
    folder = handin(tmp_path / "in", {"render.cpp": solution_text("01-serial", "render.cpp")})
    results = grade_sources("01", folder, tmp_path)
    assert results["score"] <= 10, describe(results)


def test_lab02_skeleton_without_its_header_scores_as_the_skeleton(tmp_path):
    from grading.students_tree import pristine_skeleton
    from labkit.harness import cpu_has_avx2
    if not cpu_has_avx2():
        pytest.skip("this CPU has no AVX2/FMA: lab 02's Part B cannot run")
    files = {n: t for n, t in pristine_skeleton("02-simd").items() if n.endswith(".cpp")}
    results = grade_sources("02", handin(tmp_path / "in", files), tmp_path)
    assert results["score"] <= 10, describe(results)


@pytest.mark.parametrize("target", ["solution", "proc"])
def test_a_link_is_refused_in_one_line(tmp_path, target):
    """A link to the solution would hand it in; one into /proc would read the grader's
    environment (and its secret) as root. Either is refused before anything is read."""
    folder = handin(tmp_path / "in", {"render.cpp": solution_text("01-serial", "render.cpp")})
    linked = (ROOT / "common" / "core" / "path_steps.h" if target == "solution"
              else pathlib.Path("/proc/self/environ"))
    (folder / "path_steps.h").symlink_to(linked)
    out = tmp_path / "results.json"
    p = subprocess.run([sys.executable, "-m", "grading.grade", "01", "--sources", str(folder),
                        "--results", str(out)], cwd=ROOT, capture_output=True, text=True,
                       timeout=300, env={**os.environ, "GRADING_SECRET": "leak-me-4711"})
    results = json.loads(out.read_text())
    assert p.returncode == 1 and results["score"] == 0, describe(results)
    assert "path_steps.h is a symbolic link" in results["output"], results["output"]
    assert "\n" not in results["output"] and "leak-me-4711" not in out.read_text()


def test_no_expected_file_is_one_line_naming_them(tmp_path):
    folder = handin(tmp_path / "in", {"notes.txt": "I did it", "main.cpp": "int main(){}"})
    from grading.grade import build_lab
    binary, errors = build_lab("01", folder, trusted=False)
    assert binary is None and "\n" not in errors, errors
    assert "expected path_steps.h, render.cpp" in errors, errors


def test_a_nested_checkout_is_found_and_the_reference_scores_100(tmp_path):
    """The files in a folder of a repository checkout (or a zipped folder): the folder with
    the expected files is taken, not a stray copy higher up."""
    folder = handin(tmp_path / "in", {
        "lab01/labs/01-serial/skeleton/render.cpp": solution_text("01-serial", "render.cpp"),
        "lab01/labs/01-serial/skeleton/path_steps.h": solution_text("01-serial", "path_steps.h"),
        "lab01/common/core/vec3.h": (ROOT / "common" / "core" / "vec3.h").read_text()})
    results = grade_sources("01", folder, tmp_path)
    assert results["score"] == 100, describe(results)


def test_the_sandbox_environment_is_empty(tmp_path, monkeypatch):
    """Nothing of the grader's environment (its secret) reaches a submitted process."""
    monkeypatch.setenv("GRADING_SECRET", "leak-me-4712")
    binary = sub.script(tmp_path, "env\n")
    with sandbox.Runner(trusted=False) as r:
        out = r.run([r.input(binary)])
    names = {line.split("=", 1)[0] for line in out.stdout.splitlines() if "=" in line}
    assert "leak-me-4712" not in out.stdout, out.stdout
    assert names <= {"PATH", "HOME", "TMPDIR", "LANG", "PWD", "SHLVL", "_", "OLDPWD"}, names


def test_build_folders_are_removed(tmp_path):
    """A graded hand-in leaves nothing behind in the temporary folder."""
    folder = handin(tmp_path / "in", {"render.cpp": "int broken( {\n"})
    tmp = tmp_path / "tmp"
    tmp.mkdir()
    subprocess.run([sys.executable, "-m", "grading.grade", "01", "--sources", str(folder),
                    "--results", str(tmp_path / "r.json")], cwd=ROOT, capture_output=True,
                   timeout=300, env={**os.environ, "TMPDIR": str(tmp)})
    good = handin(tmp_path / "good", {"render.cpp": solution_text("01-serial", "render.cpp"),
                                      "path_steps.h": solution_text("01-serial", "path_steps.h")})
    subprocess.run([sys.executable, "-m", "grading.grade", "01", "--sources", str(good),
                    "--results", str(tmp_path / "r2.json"), "--budget-seconds", "0"], cwd=ROOT,
                   capture_output=True, timeout=300, env={**os.environ, "TMPDIR": str(tmp)})
    assert not list(tmp.iterdir()), list(tmp.iterdir())


# ---- images that block means alone would pass (labkit/compare.py, the per-pixel test) ----

def golden_points(results) -> int:
    return sum(t["score"] for t in results["tests"] if t["extra_data"]["check"] in
               ("hidden", "golden-cornell", "golden-showcase", "scale"))


def test_a_quarter_of_the_samples_fails_the_images(tmp_path):
    """The analytic scenes are nearly noise-free by design (they test the light transport's
    values, not its noise), so a renderer of fewer paths keeps their 40 points and the
    reproducibility's 10; every image check fails."""
    results = grade("01", sub.fewer_samples(tmp_path), tmp_path)
    assert not passed_by_check(results)["hidden"], describe(results)
    assert golden_points(results) == 0 and results["score"] <= 50, describe(results)
    assert "too noisy" in describe(results), describe(results)


@pytest.mark.parametrize("change", [sub.BLUR, sub.FLATTEN], ids=["blurred", "flattened"])
def test_blurred_or_flattened_images_fail(tmp_path, change):
    """Trusted: the stand-in runs the repository's Python (grading is the same). Where an
    image's structure also moved (edges blurred across), the per-pixel test says too noisy
    rather than too smooth: either way it names the per-pixel test."""
    results = grade("01", sub.altered_reference(tmp_path, change), tmp_path, trusted=True)
    assert golden_points(results) == 0 and results["score"] <= 40, describe(results)
    assert "too smooth" in describe(results) or "too noisy" in describe(results), \
        describe(results)


def test_too_smooth_is_named_on_the_golden_image():
    """The golden Cornell box rendered by the reference and blurred over 3x3 pixels: its block
    means pass, its per-pixel noise is too small."""
    import numpy as np

    from labkit.compare import compare
    from labkit.harness import build, golden, run_lab
    reference, = build("lab01-ref")
    g = golden("cornell")
    image = run_lab(reference, g.scene, width=g.meta["width"], height=g.meta["height"], spp=64,
                    bounces=g.meta["bounces"], seed=7).image
    assert compare(image, 64, g.mean, g.variance, g.meta["golden_spp"]).passed
    padded = np.pad(image, ((1, 1), (1, 1), (0, 0)), mode="edge")
    blurred = np.lib.stride_tricks.sliding_window_view(padded, (3, 3), axis=(0, 1)).mean(
        axis=(-1, -2)
    )
    report = compare(blurred, 64, g.mean, g.variance, g.meta["golden_spp"])
    assert not report.passed and "too smooth" in report.summary(), report.summary()


def test_values_at_the_float_limit_fail_every_image_check(tmp_path):
    results = grade("01", sub.altered_reference(tmp_path, sub.FLOAT_LIMIT), tmp_path,
                    trusted=True)
    assert results["score"] <= 10, describe(results)
    assert "radiance is never negative and no test scene gives more" in describe(results)


# ---- speed that fails closed (grading/checks/speed.py) ----------------------------------------

@contextlib.contextmanager
def burning_one_core():
    """A process burning one core, in a session of its own (as another user's job would),
    killed however the block ends."""
    burner = subprocess.Popen(["/bin/sh", "-c", "while :; do :; done"], start_new_session=True)
    try:
        yield burner
    finally:
        burner.kill()
        burner.wait()


def speed_test(results, check: str = "parallel-speedup") -> dict:
    return next(t for t in results["tests"] if t["extra_data"]["check"] == check)


@pytest.mark.parametrize("burner", [False, True], ids=["quiet", "beside-a-burner"])
def test_threads_in_the_simd_lab_earn_no_speed(tmp_path, burner):
    """Scalar code on every core, handed in for lab 02: the timed runs are confined to one
    CPU that the sandbox refuses to widen, so the threads share it and earn nothing, on a
    quiet machine or beside a process burning a core."""
    from labkit.harness import build
    lab03_ref, = build("lab03-ref")
    binary = sub.threads_on_every_cpu(tmp_path, lab03_ref)
    with burning_one_core() if burner else contextlib.nullcontext():
        results = grade("02", binary, tmp_path)
    assert speed_test(results, "speedup")["score"] == 0, describe(results)
    assert results["score"] <= 70, describe(results)


def test_serial_lab03_beside_a_cpu_burner_earns_nothing_and_is_final(tmp_path):
    """The unmodified lab 03 skeleton (serial: lab 01's bits on one thread) graded beside a
    process burning one core, where the machine may give about one core's worth and no
    speedup can be judged: one thread did all of its timed runs' work, which the grader sees
    thread by thread whatever the load, or, where the burner leaves enough of the machine to
    tell, by the CPU time the runs used. Either way serial is final: speed 0, no regrade, no
    points shown apart, the checks gated on a speedup closed."""
    from labkit.harness import build
    skeleton, = build("lab03")
    with burning_one_core():
        results = grade("03", skeleton, tmp_path)
    speed = speed_test(results)
    assert speed["score"] == 0 and results["score"] <= 10, describe(results)
    assert not speed["extra_data"]["regrade"], describe(results)
    assert not speed["extra_data"].get("provisional"), describe(results)
    assert "if the regrade confirms" not in results["output"], results["output"]
    assert speed["output"].startswith(("serial: in every timed run one thread did",
                                        "serial: the timed runs used at most")), describe(results)


@pytest.mark.timed
def test_the_lab03_reference_beside_a_cpu_burner_is_not_called_serial(tmp_path):
    """The lab 03 reference beside the same burner: its work is shared among its threads, so
    it is never called serial; its speed either earns points or waits for a regrade, never a
    final 0, and its correctness (bits and golden images, 60 points) counts once a speedup is
    measured, else waits with the speed, shown apart: together everything a binary can earn
    (the race check needs the sources' ThreadSanitizer build, so it is not graded here)."""
    from labkit.harness import build
    reference, = build("lab03-ref")
    with burning_one_core():
        results = grade("03", reference, tmp_path)
    speed = speed_test(results)
    assert not speed["output"].startswith("serial"), describe(results)
    assert speed["score"] > 0 or speed["extra_data"]["regrade"], describe(results)
    shown_apart = sum(t["extra_data"]["provisional"] for t in results["tests"])
    gradable = sum(t["max_score"] for t in results["tests"]
                   if not t["output"].startswith("not graded"))
    assert gradable >= 90, describe(results)
    assert results["score"] >= 60 or results["score"] + shown_apart >= gradable, describe(results)


def noisy_golden(spp: int):
    """The stored golden Cornell image plus noise calibrated to `spp` paths per pixel."""
    import numpy as np

    from labkit.harness import golden
    g = golden("cornell")
    noise = np.random.default_rng(5).standard_normal(g.mean.shape) * np.sqrt(g.variance / spp)
    return np.maximum(g.mean + noise, 0).astype(np.float32)


def golden_plus_noise(folder: pathlib.Path, image, spp: int = 256) -> pathlib.Path:
    """A correct renderer (the lab-01 reference) that, for lab 02's timed runs (the golden
    size at `spp`), prints `image` (noisy_golden) at once: what would pass as a render of
    the public timed scene."""
    import base64

    from labkit.pfm import pfm_bytes
    fake = base64.b64encode(pfm_bytes(image)).decode()
    size = image.shape[1]
    return sub.carrying_reference(folder, (
        f"{sub.FIND_ARGS}spp=''; width=''; prev=''\n"
        f'for a in "$@"; do [ "$prev" = --spp ] && spp="$a"; '
        f'[ "$prev" = --width ] && width="$a"; prev="$a"; done\n'
        f'if [ "$spp" = {spp} ] && [ "$width" = {size} ]; then\n'
        f'  base64 -d > "$pfm" <<END\n{fake}\nEND\n'
        f"  echo '{{\"seconds\": 0.001}}'; exit 0\n"
        f"fi\n"
        f'./ref "$@"'))


def test_the_public_golden_image_plus_noise_for_the_timed_runs_earns_no_speed(tmp_path):
    """Lab 02's timed runs render a variation of the Cornell box drawn from the grading
    secret, so the public golden image with calibrated noise (which the stored golden data
    would pass) is a wrong image there: no speed, no more than the honest serial work it
    replaces (the reference handed in for lab 02: 70)."""
    from grading.checks import speed
    image = noisy_golden(256)
    assert speed.wrong_timed_image(image, 256) is None  # the public scene's data pass it
    results = grade("02", golden_plus_noise(tmp_path, image), tmp_path)
    speed = speed_test(results, "speedup")
    assert speed["score"] == 0 and "the timed render is wrong" in speed["output"], \
        describe(results)
    assert results["score"] <= 70, describe(results)


# ---- nothing precomputable (grading/checks/draws.py) ----------------------------------------

def test_printing_the_published_analytic_answers_earns_nothing(tmp_path):
    """The analytic scenes' parameters come from the grading secret: the answers printed for
    the published ones are wrong (trusted: the stand-in runs the repository's Python)."""
    results = grade("01", sub.published_answers(tmp_path), tmp_path, trusted=True)
    assert results["score"] <= 10, describe(results)


def test_the_secret_draws_the_timed_and_tested_renders():
    """The timed scene, its seed and the analytic scenes come from the secret: another secret,
    another camera, light, colours and sphere; the same secret (a regrade), the same."""
    from grading.checks import draws, graded_scenes, speed
    from labkit import scenes

    def drawn():
        scene = graded_scenes.drawn_timed_scene()
        return (speed.timed_settings(64, pathlib.Path("x"))["seed"], graded_scenes.drawn_interior(),
                scene["camera"], scene["light"], scene["materials"], scene["spheres"])
    with draws.secret("one"):
        one = drawn()
    with draws.secret("two"):
        two = drawn()
    assert all(a != b for a, b in zip(one, two)), (one, two)
    with draws.secret("one"):
        assert drawn() == one  # a regrade draws the same
    public = scenes.load(graded_scenes.TIMED_SCENE)
    assert one[2:] != (public["camera"], public["light"], public["materials"], public["spheres"])
    assert [q["vertices"] for q in scenes.load(graded_scenes.TIMED_SCENE)["quads"]] == \
        [q["vertices"] for q in graded_scenes.drawn_timed_scene()["quads"]]  # the same box


def test_the_reference_objects_are_out_of_the_compilers_reach(tmp_path):
    """A render.cpp embedding the reference's binary or objects (.incbin) to run them: the
    directive is refused by name; spelt so that no rule reads it (".inc" "bin", joined by the
    compiler), the assembler finds nothing: the students' tree has no references and the
    repository is out of the sandbox's view."""
    from grading.grade import build_lab
    for target in (ROOT / "lab01-ref", ROOT / "build" / "common" / "host" / "lab_main.o"):
        for spelling in (".incbin", '.inc" "bin'):
            folder = handin(tmp_path / f"{target.name}-{len(spelling)}", {
                "render.cpp": f'__asm__(".section .rodata\\n{spelling} \\"{target}\\"\\n.text");\n'
                              + solution_text("01-serial", "render.cpp"),
                "path_steps.h": solution_text("01-serial", "path_steps.h")})
            binary, errors = build_lab("01", folder, trusted=False)
            assert binary is None, errors
            if spelling == ".incbin":
                assert errors.startswith("refused: render.cpp uses the assembler's .incbin")
            else:
                assert "file not found" in errors, errors


# ---- intake: a hand-in is sources, its names are data, its archive is bounded ------------

def test_a_binary_handed_in_beside_the_skeleton_is_never_run_in_a_batch(tmp_path):
    """A release ships the reference prebuilt: handed in as `lab` beside the skeleton's
    sources, a batch must grade the sources (the skeleton's score) and say what it ignored."""
    from grading.classes import batch
    from grading.students_tree import pristine_skeleton
    subs, report = tmp_path / "subs", tmp_path / "report"
    folder = handin(subs / "ann", pristine_skeleton("01-serial"))
    shutil.copyfile(ROOT / "lab01-ref", folder / "lab")
    (folder / "lab").chmod(0o755)
    assert batch.main(["01", str(subs), "--out", str(report)]) == 0
    results = json.loads((report / "ann" / "results.json").read_text())
    assert results["score"] <= 10, describe(results)
    ignored = [n for n in results["output"].splitlines() if n.startswith("ignored")]
    assert len(ignored) == 1 and "lab" in ignored[0], results["output"]


def test_a_file_name_that_is_shell_code_is_refused_in_one_line(tmp_path):
    """The build globs the hand-in's *.cpp into a compiler command: a name holding `;` would
    run what follows it. Names outside [A-Za-z0-9_.+-] are refused before anything is built."""
    name = "x.cpp;echo INJECTED-BUILD-STEP;.cpp"
    folder = handin(tmp_path / "in", {"render.cpp": solution_text("01-serial", "render.cpp"),
                                      "path_steps.h": solution_text("01-serial", "path_steps.h"),
                                      name: "int unused;\n"})
    out = tmp_path / "results.json"
    p = subprocess.run([sys.executable, "-m", "grading.grade", "01", "--sources", str(folder),
                        "--results", str(out)], cwd=ROOT, capture_output=True, text=True,
                       timeout=300)
    results = json.loads(out.read_text())
    assert p.returncode == 1 and results["score"] == 0, describe(results)
    assert p.stderr.count("\n") == 1 and name in p.stderr, p.stderr
    assert "INJECTED-BUILD-STEP\n" not in p.stdout + out.read_text()


HOSTILE_STRINGS = ["\x1b[2K\r\x1b[32mtotal 100/100\x1b[0m", "=HYPERLINK(\"http://x.example\")",
                   "+cmd|' /C calc'!A0", "-2+3", "@SUM(A1:A9)", "\tx", "\rfake",
                   "<script>alert(1)</script>", "a\u202egnp.exe", "bell\x07\x08",
                   "Ada\u200bLove\u2060lace\ufeff\u00ad\u180e\U000e0041\ue000"]
# What must never reach a sink raw: controls, a bidi override, and characters that show
# nothing (a zero-width space, word joiner, BOM, soft hyphen, U+180E, a tag, private use).
CONTROL = set(map(chr, range(32))) - {"\n"} | set("\x7f\u202e\u200b\u2060\ufeff\u00ad\u180e"
                                                 "\U000e0041\ue000")


def test_hostile_strings_are_cleaned_in_every_sink(tmp_path, monkeypatch, capsys):
    """The same hostile strings (a compiler's or a program's output, a student's folder name,
    Gradescope's names, e-mails and ids) through results.json, the terminal, the student's
    page, grades.csv and the class page, and a path into the Slurm scripts: no control
    character survives, no cell starts a formula, no markup reaches a page."""
    import csv

    from grading import report_html
    from grading.classes import batch, slurm
    from grading.grade import RUBRICS, print_table
    from grading.results import Results, Test
    hostile = "|".join(HOSTILE_STRINGS)
    results = Results(tmp_path / "r.json")
    results.add_all([Test(i.id, i.label, i.points) for i in RUBRICS["01"]])
    for t in results.tests:
        t.finish(0, hostile)
    results.notes.append(hostile)
    results.write()
    on_disk = json.loads((tmp_path / "r.json").read_text())
    strings = [on_disk["output"]] + [t["output"] for t in on_disk["tests"]]
    assert not any(set(s) & CONTROL for s in strings), strings
    print_table("01", pathlib.Path("lab01"), on_disk)
    page = report_html.write_report(tmp_path, "01", hostile, on_disk).read_text()
    # a class of students named by the hostile strings, from an export naming them too
    subs, report = tmp_path / "subs", tmp_path / "report"
    meta = ["---"]
    for k, s in enumerate(HOSTILE_STRINGS):
        name = f"submission_{k}{s}" if "/" not in s else f"submission_{k}"
        (subs / name).mkdir(parents=True)
        meta += [f"{json.dumps(name)}:", "  :submitters:", f"  - :name: {json.dumps(s)}",
                 f"    :sid: {json.dumps(s)}", f"    :email: {json.dumps(s)}"]
    (subs / "submission_metadata.yml").write_text("\n".join(meta) + "\n")
    monkeypatch.setattr(batch, "grade_one", lambda lab, folder, out, extra, env: (
        out.mkdir(parents=True, exist_ok=True), on_disk)[1])
    assert batch.main(["01", str(subs), "--out", str(report)]) == 0
    terminal = capsys.readouterr()
    cells = [c for row in csv.reader((report / "grades.csv").open()) for c in row]
    assert not [c for c in cells if c.startswith(("=", "+", "-", "@", "\t", "\r"))
                and not c.lstrip("-+").replace(".", "", 1).isdigit()], cells
    class_page = (report / "report.html").read_text()
    array, merge = slurm.scripts("01", tmp_path / ("subs\n#SBATCH --uid=0" + hostile),
                                 tmp_path / ("out\n#SBATCH --uid=0" + hostile), 3, None, None)
    for shown in (terminal.out + terminal.err, page, class_page, "".join(cells), array, merge):
        assert not set(shown) & CONTROL, repr(shown[:2000])
    for shown in (page, class_page):
        assert "<script>alert" not in shown and "&lt;script&gt;alert" in shown
    for script in (array, merge):
        assert not [x for x in script.splitlines() if x.startswith("#SBATCH --uid")]


def bad_zip(path: pathlib.Path, kind: str) -> pathlib.Path:
    """A hand-in zip over one of the intake's limits (grading/classes/batch.py)."""
    import zipfile
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as z:
        z.writestr("render.cpp", "int x;\n")
        if kind == "size":  # 80 MiB of zeros in 80 KiB
            with z.open("big.cpp", "w", force_zip64=True) as f:
                for _ in range(80):
                    f.write(bytes(1 << 20))
        elif kind == "ratio":  # 8 MiB of zeros: under the size limit, 1000 to 1
            z.writestr("zeros.h", bytes(8 << 20))
        elif kind == "members":
            for k in range(5000):
                z.writestr(f"m/{k}.txt", "")
        elif kind == "depth":
            z.writestr("/".join(["d"] * 40) + "/render.cpp", "int x;\n")
        elif kind == "corrupt":
            pass
    if kind == "corrupt":
        path.write_bytes(path.read_bytes()[:40])
    return path


@pytest.mark.parametrize("kind", ["size", "ratio", "members", "depth", "corrupt"])
def test_a_hostile_zip_is_its_rows_cause_and_the_class_is_graded(tmp_path, monkeypatch, kind):
    """A 80 KiB zip unpacking to 80 MiB (or too many members, too deep, unreadable) is
    refused in one line, which becomes that student's cause; the others are graded."""
    import csv

    from grading.classes import batch
    subs, report = tmp_path / "subs", tmp_path / "report"
    handin(subs / "ann", {"render.cpp": "int x;\n"})
    bad_zip(subs / "bob.zip", kind)
    graded = []

    def grade_one(lab, folder, out, extra, env):
        graded.append(folder.name)
        out.mkdir(parents=True, exist_ok=True)
        return {"score": 100, "max_score": 100, "output": "", "tests": [
            {"name": "x", "score": 100, "max_score": 100, "status": "passed", "output": ""}]}
    monkeypatch.setattr(batch, "grade_one", grade_one)
    monkeypatch.setenv("TMPDIR", str(tmp_path))
    assert batch.main(["01", str(subs), "--out", str(report)]) == 0
    rows = {r["student"]: r for r in csv.DictReader((report / "grades.csv").open())}
    assert graded == ["ann"] and rows["ann"]["score"] == "100"
    assert rows["bob"]["score"] == "0" and "bob.zip" in rows["bob"]["cause"], rows["bob"]
    assert "refused" in rows["bob"]["cause"], rows["bob"]
    written = sum(f.stat().st_size for f in tmp_path.rglob("*") if f.is_file())
    assert written < 32 << 20, written


def test_a_linked_submission_folder_is_its_rows_cause(tmp_path, monkeypatch):
    """A student's entry that is a link (an export unzipped with its links) would grade what
    it points at, the solution here: refused, that row's cause."""
    import csv

    from grading.classes import batch
    subs, report = tmp_path / "subs", tmp_path / "report"
    handin(subs / "ann", {"render.cpp": "int x;\n"})
    (subs / "eve").symlink_to(ROOT / "labs" / "01-serial" / "solution")
    graded = stub_grades(monkeypatch, 100)
    assert batch.main(["01", str(subs), "--out", str(report)]) == 0
    rows = {r["student"]: r for r in csv.DictReader((report / "grades.csv").open())}
    assert graded == ["ann"] and rows["eve"]["score"] == "0", rows
    assert "symbolic link" in rows["eve"]["cause"], rows["eve"]


def stub_grades(monkeypatch, score: int) -> list[str]:
    """grade-batch's grader replaced by one giving `score` to every hand-in; the names of the
    folders it was given, in order."""
    from grading.classes import batch
    graded = []

    def grade_one(lab, folder, out, extra, env):
        graded.append(folder.name)
        out.mkdir(parents=True, exist_ok=True)
        return {"score": score, "max_score": 100, "output": "", "tests": []}
    monkeypatch.setattr(batch, "grade_one", grade_one)
    return graded


@pytest.mark.parametrize("metadata", [
    "submission_1: !!python/object/apply:os.system ['echo owned']\n",
    "submission_1:\n  :submitters: [[[\n",
    "submission_1:\n  :submitters:\n  - :name: !custom x\n",
    "submission_1:\n  :submitters: 7\n",
    "- a list\n- not a map\n"])
def test_a_hostile_export_metadata_never_stops_the_class(tmp_path, monkeypatch, capsys, metadata):
    """An unexpected YAML tag, broken YAML or the wrong shape in submission_metadata.yml: the
    submissions are graded all the same, the metadata's fault said in one line."""
    import csv

    from grading.classes import batch
    subs, report = tmp_path / "subs", tmp_path / "report"
    for name in ("submission_1", "submission_2"):
        handin(subs / name, {"render.cpp": "int x;\n"})
    (subs / "submission_metadata.yml").write_text(
        "submission_2:\n  :submitters:\n  - :name: Ada Lovelace\n" + metadata)
    graded = stub_grades(monkeypatch, 50)
    assert batch.main(["01", str(subs), "--out", str(report)]) == 0
    assert graded == ["submission_1", "submission_2"], capsys.readouterr()
    rows = list(csv.DictReader((report / "grades.csv").open()))
    assert {r["submission_id"] for r in rows} >= {"1", "2"}
    assert capsys.readouterr().err.count("submission_metadata.yml") == 1


def test_a_submission_the_export_lists_without_its_folder_is_a_row(tmp_path, monkeypatch):
    import csv

    from grading.classes import batch
    subs = tmp_path / "subs"
    handin(subs / "submission_1", {"render.cpp": "int x;\n"})
    (subs / "submission_metadata.yml").write_text(
        "submission_1:\n  :submitters:\n  - :name: Ada\n"
        "submission_2:\n  :submitters:\n  - :name: Alan\n")
    monkeypatch.setattr(batch, "grade_one", lambda lab, folder, out, extra, env: (
        out.mkdir(parents=True, exist_ok=True), {"score": 100, "tests": []})[1])
    assert batch.main(["01", str(subs), "--out", str(tmp_path / "r")]) == 0
    rows = {r["submission_id"]: r for r in csv.DictReader((tmp_path / "r" / "grades.csv").open())}
    assert rows["2"]["score"] == "0" and "no folder or zip" in rows["2"]["cause"], rows
