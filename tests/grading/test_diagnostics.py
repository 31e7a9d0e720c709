"""Every diagnostic, and only true ones: lab 01 built with the classic mistakes in its source
(one bounce too many or too few, the diffuse BRDF without its 1/pi) and lab 03 with a racy
or a split-dependent loop, each graded and told exactly its mistake by the check that
identifies it (grading/checks/symptoms.py, identity.check_bitwise_equal), and never another's."""
import pytest

from grading.checks import draws, identity
from grading.grade import LAB01_REFERENCE, describe, grade
from labkit.harness import ROOT, build
from labkit.variants import build_variant
from tests.grading import submissions as sub

PATH_STEPS = (ROOT / "common" / "core" / "path_steps.h").read_text()
LOOP_END = "path.alive = path.bounce < max_bounces;"
BRDF_PI = "(cos_theta / (kPi * distance2))"
# mistake -> (the edit to the shared path tracer, words the sphere interior must say)
SOURCE_MISTAKES = {
    "one bounce too many": ((LOOP_END, "path.alive = path.bounce <= max_bounces;"),
                            "one bounce too many"),
    "one bounce too few": ((LOOP_END, "path.alive = path.bounce + 1 < max_bounces;"),
                           "one bounce too few"),
    "missing 1/pi": ((BRDF_PI, "(cos_theta / distance2)"), "1/pi is missing"),
}


def output_of(results: dict, check: str) -> str:
    return next(t["output"] for t in results["tests"] if t["extra_data"]["check"] == check)


@pytest.mark.parametrize("mistake", sorted(SOURCE_MISTAKES))
def test_a_source_mistake_is_identified(mistake, tmp_path):
    (old, new), words = SOURCE_MISTAKES[mistake]
    assert PATH_STEPS.count(old) == 1, f"the path tracer no longer holds {old!r}"
    binary = build_variant("01-serial", tmp_path,
                           {"path_steps.h": PATH_STEPS.replace(old, new)})
    results = grade("01", binary, tmp_path, trusted=True)
    interior = output_of(results, "sphere-interior")
    assert words in interior, describe(results)
    text = describe(results)
    # Only true ones: no statistical guess contradicts what the closed form identified.
    assert "gamma" not in text, text
    for other, (_, other_words) in SOURCE_MISTAKES.items():
        if other != mistake:
            assert other_words not in text, text
    # At home every check runs: the golden images say what they saw while the hidden scene
    # fails, their points waiting for it. (The hidden scene is drawn from a new secret each
    # grade, and a mistake as small as one bounce too many does not fail every draw of it.)
    golden = output_of(results, "golden-cornell")
    waiting = "not counted until the hidden scene passes; it saw: "
    assert (golden.removeprefix(waiting) if golden.startswith(waiting) else golden).startswith(
        "FAIL"), text
    assert (tmp_path / "cornell-yours.png").exists() and (tmp_path / "cornell-diff.png").exists()


def test_a_gamma_encoded_pfm_is_named_gamma(lab01_ref, tmp_path):
    """The reference's images raised to 1/2.2: the closed forms identify the curve."""
    altered = sub.altered_reference(tmp_path, "image ** (1 / 2.2)", lab01_ref)
    results = grade("01", altered, tmp_path, trusted=True)
    assert "gamma-encoded" in output_of(results, "sphere-interior"), describe(results)
    assert "gamma-encoded" in output_of(results, "lit-plane"), describe(results)
    assert "1/pi" not in describe(results), describe(results)


def test_lab01_hints_speak_of_lab01(lab01_ref, tmp_path):
    """Rows left black: lab 01 has no ranks, threads or kernels to blame."""
    altered = sub.altered_reference(tmp_path, "np.concatenate([image[:-5], 0 * image[-5:]])",
                                    lab01_ref)
    text = describe(grade("01", altered, tmp_path, trusted=True))
    assert "rows are exactly black" in text, text
    for word in ("rank", "thread", "kernel", "gathered"):
        assert word not in text, text


@pytest.fixture(scope="module")
def reference_bits():
    build("lab01-ref")


@pytest.mark.parametrize("variant", ["lab03-shared-rng-race", "lab03-shared-rng"])
def test_a_racy_lab03_is_told_nondeterministic_with_rows(variant, reference_bits):
    binary = build(variant)[0]
    with draws.secret("diagnostics"):
        result = identity.check_bitwise_equal(binary, LAB01_REFERENCE)
    assert not result.passed, result
    assert "nondeterministic: a data race or shared generator" in result.detail, result
    assert "rows " in result.detail and "work split" not in result.detail, result


def test_a_split_dependent_image_is_told_work_split(lab01_ref, reference_bits, tmp_path):
    """Deterministic, but the seed depends on the thread count (random numbers drawn by
    thread): the same image every run, another one for each count but 1."""
    wrapper = sub.carrying_reference(tmp_path, """threads=1; prev=""
for a in "$@"; do
  [ "$prev" = "--threads" ] && threads="$a"
  prev="$a"
done
n=$#; prev=""
for a in "$@"; do
  [ "$prev" = "--seed" ] && [ "$threads" != 1 ] && a=$((a + threads * 7919))
  set -- "$@" "$a"; prev="$a"
done
shift "$n"
exec ./ref "$@"
""", reference=lab01_ref)
    with draws.secret("diagnostics"):
        result = identity.check_bitwise_equal(wrapper, LAB01_REFERENCE)
    assert not result.passed, result
    assert "deterministic but different: work split" in result.detail, result
    assert "2 threads, 3 threads, 7 threads" in result.detail, result
    assert "nondeterministic" not in result.detail, result


def test_lab03_bit_check_runs_while_the_speedup_fails(tmp_path):
    """The racy loop fails the speed check first; the bit check still runs and names the race
    (its points wait for the speedup)."""
    results = grade("03", build("lab03-shared-rng-race")[0], tmp_path, trusted=True)
    bitwise = output_of(results, "bitwise")
    assert "nondeterministic" in bitwise and "rows " in bitwise, describe(results)


def test_make_grade_shows_progress_and_this_run_only(lab01_ref, tmp_path):
    """Each check is printed as it finishes, before the table; an earlier grade's images are
    gone from the report folder, and nothing else there is touched."""
    import subprocess
    import sys
    maps = tmp_path / "maps"
    maps.mkdir()
    (maps / "stale-yours.png").write_bytes(b"old")
    (maps / "stale-diff.png").write_bytes(b"old")
    (maps / "notes.txt").write_text("mine")
    p = subprocess.run([sys.executable, "-m", "grading.grade", "01", "--binary", str(lab01_ref),
                        "--trusted", "--results", str(tmp_path / "r.json"),
                        "--heatmaps", str(maps)], cwd=ROOT, capture_output=True, text=True,
                       timeout=300)
    assert p.returncode == 0, p.stderr
    lines = p.stdout.splitlines()
    progress = [i for i, line in enumerate(lines) if line.startswith("  analytic sphere interior")]
    table = [i for i, line in enumerate(lines) if line.startswith("total")]
    assert progress and table and progress[0] < table[0], p.stdout
    assert "PASS 15/15" in lines[progress[0]], p.stdout
    assert not (maps / "stale-yours.png").exists() and not (maps / "stale-diff.png").exists()
    assert (maps / "notes.txt").read_text() == "mine"
    assert (maps / "cornell-yours.png").exists()


def test_build_warnings_are_kept():
    from grading.grade import build_warnings
    text = "render.cpp:12:9: warning: unused variable 'x' [-Wunused-variable]\n   12 | int x;\n"
    assert "unused variable" in build_warnings(text)
    assert build_warnings("") == "" and build_warnings("g++ -O2 -c render.cpp\n") == ""


def test_a_build_that_stopped_without_a_message_shows_its_last_lines():
    """nvcc, running its compilers in parallel threads, exits 255 and prints nothing when one
    of them crashes: make's own line alone would name no cause."""
    from grading.grade import first_errors
    silent = "exited with status 2\nnvcc -O3 render.cu -o lab\nmake: *** [cuda.mk:103: x] Error 255"
    shown = first_errors(silent)
    assert "without an error message" in shown and "exited with status 2" in shown, shown
    assert "nvcc -O3 render.cu" in shown, shown
    fatal = "exited with status 2\nptxas fatal   : Memory allocation failure\n" \
            "make: *** [cuda.mk:103: x] Error 255"
    assert first_errors(fatal).splitlines()[0].startswith("ptxas fatal"), first_errors(fatal)
    compiler = "render.cpp:3:1: error: expected ';'\nmake: *** [Makefile:9: variant] Error 1"
    assert first_errors(compiler).splitlines()[0] == "render.cpp:3:1: error: expected ';'"
