"""What runs is what the hand-in built, in both sandboxes: a program carried in a hand-in and
run from a memory file, a written file or the loader scores nothing and is marked for course
staff; sources are text sized like a lab; the sweep after a run cannot be broken; the class's
hand-ins are out of a run's reach; and a reference's double build still runs, staged."""
import os
import pathlib

import pytest

from grading import source_rules
from grading.checks import graded_scenes
from grading.grade import build_lab, describe, grade
from labkit import boxes, sandbox, scenes
from labkit.harness import run_lab
from tests.grading import submissions as sub
from tests.grading.sandbox_modes import py, sh

LOADER = "/lib64/ld-linux-x86-64.so.2"


# ---- nothing runs that the run was not given ----------------------------------------------

def test_a_written_program_does_not_run(mode):
    """A copy of a program the run writes (here the system's echo) is never run: Landlock
    refuses the exec, or, where there is none, the grader sees its mapping and stops it."""
    out = sh("cp /bin/echo ./mine && chmod +x ./mine && ./mine CARRIED; "
             "cp /bin/echo $TMPDIR/t && chmod +x $TMPDIR/t && $TMPDIR/t CARRIED; exit 0")
    assert "CARRIED" not in out.stdout, out
    if sandbox.landlock_available():
        assert out.foreign is None and "Permission denied" in out.stderr, out


def test_a_written_program_run_by_the_loader_is_stopped_and_named(mode):
    """ld.so is the system's, but what it maps is not: the run stops there, named."""
    out = sh(f"cp /bin/sleep ./mine; {LOADER} ./mine 5; echo survived")
    assert "survived" not in out.stdout, out
    assert out.foreign and "mine" in out.foreign, out
    assert out.failure.startswith("ran a program it did not build"), out


@pytest.mark.parametrize("how", ["memfd", "memfd-noexec", "execveat", "anonymous", "mprotect",
                                 "shm-exec"])
def test_code_that_is_no_file_is_refused(mode, how):
    """Each way to run bytes that are not a file of the system's: an executable memory file
    (fexecve: execveat, or /proc/self/fd), anonymous memory made executable, SysV shared
    memory attached executable. Each is refused (EPERM) before anything runs."""
    code = {
        "memfd": "fd = os.memfd_create('x'); os.write(fd, open('/bin/true', 'rb').read()); "
                 "os.execv(f'/proc/self/fd/{fd}', ['x'])",
        "memfd-noexec": "fd = os.memfd_create('x', 8); os.write(fd, open('/bin/true', 'rb')"
                        ".read()); os.execv(f'/proc/self/fd/{fd}', ['x'])",
        "execveat": "fd = os.open('/bin/true', os.O_RDONLY); libc.syscall(322, fd, b'', None, "
                    "None, 0x1000); raise OSError(ctypes.get_errno(), 'execveat')",
        "anonymous": "mmap.mmap(-1, 4096, prot=mmap.PROT_READ | mmap.PROT_WRITE | "
                     "mmap.PROT_EXEC)",
        "mprotect": "m = mmap.mmap(-1, 4096); a = ctypes.addressof(ctypes.c_char.from_buffer(m))"
                    "; rc = libc.mprotect(ctypes.c_void_p(a), 4096, 7); "
                    "assert rc == 0, 'refused'",
        "shm-exec": "i = libc.shmget(0, 4096, 0o1600); libc.shmat.restype = ctypes.c_void_p; "
                    "p = libc.shmat(i, None, 0o100000); libc.shmctl(i, 0, None); "
                    "assert p not in (None, 2**64 - 1), 'refused'",
    }[how]
    out = py("import ctypes, mmap, os\nlibc = ctypes.CDLL(None, use_errno=True)\n"
             f"try:\n    {code}\n    print('RAN')\nexcept (OSError, AssertionError) as e:\n"
             "    print('refused', e)\n")
    assert "refused" in out.stdout and "RAN" not in out.stdout, out


def carries_the_reference(folder: pathlib.Path, run: str) -> pathlib.Path:
    """A program (a shell script) holding the lab-01 reference's bytes, which it writes to its
    scratch folder and runs with the grader's arguments: by exec, or through the loader."""
    payload = sub.REFERENCE.read_bytes()
    path = folder / "lab"
    path.write_bytes(b"#!/bin/sh\n" + (f"tail -c {len(payload)} \"$0\" > ./ref && chmod +x ./ref"
                                       f" || exit 99\n{run} \"$@\"\nexit $?\n").encode() + payload)
    path.chmod(0o755)
    return path


@pytest.mark.parametrize("run", ["exec ./ref", f"exec {LOADER} ./ref"], ids=["exec", "loader"])
def test_a_reference_carried_and_run_scores_nothing(mode, tmp_path, run):
    """The release's reference, carried inside what was handed in and run from a file it
    wrote: 0 however it is started, and where it ran, marked for course staff."""
    results = grade("01", carries_the_reference(tmp_path, run), tmp_path / "maps")
    assert results["score"] == 0, describe(results)
    if "LOADER" in run or LOADER in run or not sandbox.landlock_available():
        assert "ran a program it did not build" in results.get("for_staff", ""), results
        assert all("ran a program it did not build" in t["output"] for t in results["tests"])


# A hand-in's own source that, at start-up, copies its own build to its scratch folder and
# runs that copy through the loader: its own code, but not the program the grader staged.
RUNS_A_COPY = r"""
#include <cstdio>
#include <cstdlib>
#include <string>
#include <unistd.h>
__attribute__((constructor)) static void run_a_copy(int argc, char** argv) {
    if (std::getenv("COPIED")) return;
    std::string copy = std::string(std::getenv("TMPDIR") ? std::getenv("TMPDIR") : ".") + "/x";
    std::system(("cp /proc/" + std::to_string(getpid()) + "/exe " + copy).c_str());
    setenv("COPIED", "1", 1);
    char* args[256] = {const_cast<char*>("ld.so"), const_cast<char*>(copy.c_str())};
    for (int i = 1; i < argc && i < 250; ++i) args[i + 1] = argv[i];
    execv("/lib64/ld-linux-x86-64.so.2", args);
}
"""


def test_a_hand_in_running_a_copy_of_itself_scores_nothing(mode, tmp_path):
    """Built from sources: the solution, and a file whose constructor runs a written copy."""
    from tests.grading.test_hostile import handin, solution_text
    folder = handin(tmp_path / "in", {
        "render.cpp": solution_text("01-serial", "render.cpp"),
        "path_steps.h": solution_text("01-serial", "path_steps.h"),
        "copy.cpp": RUNS_A_COPY})
    binary, errors = build_lab("01", folder, trusted=False)
    assert binary is not None, errors
    results = grade("01", binary, tmp_path / "maps")
    assert results["score"] == 0, describe(results)
    assert "ran a program it did not build" in results["for_staff"], results


def test_the_references_double_build_runs_staged(mode, tmp_path, lab01_ref):
    """The reference hands a scene float cannot place to the double build it carries: in the
    sandbox the grader stages that build and the reference runs it from there."""
    scene = scenes.write_scene(tmp_path / "big.json", scenes.scaled(
        scenes.sphere_interior(**graded_scenes.INTERIOR), 1e12))
    from labkit.harness import RunPolicy, policy
    with policy(RunPolicy(trusted=False, limits=sandbox.Limits(wall_seconds=60))):
        run = run_lab(lab01_ref, scene, width=8, height=8, spp=4, bounces=2)
    want = scenes.sphere_interior_radiance(**graded_scenes.INTERIOR, bounces=2)
    assert run.json["precision"] == "double" and abs(run.image / want - 1).max() < 3e-4


# ---- sources are text, sized like a lab ---------------------------------------------------

@pytest.mark.parametrize("name,data,says", [
    ("payload.h", (pathlib.Path("/bin/true")).read_bytes(), "NUL bytes"),
    ("payload.h", b"// caf\xe9\n", "not UTF-8"),
    ("render.cpp", b'asm(".incbin \\"payload.h\\"");\n', ".incbin"),
    ("render.cpp", b"const char x[] = {\n#embed \"payload.h\"\n};\n", "#embed"),
    ("render.cpp", b"#include \"/etc/passwd\"\n", "outside the hand-in's tree"),
    ("render.cpp", b"#  include <../../labs/01-serial/solution/render.cpp>\n", "outside"),
    ("render.cpp", b"#define F \"/x\"\n#include F\n", "through a macro"),
    ("render.cpp", b"#inc\\\nlude \"/etc/passwd\"\n", "outside"),
    ("render.cpp", b"%:include \"/etc/passwd\"\n", "outside"),
])
def test_a_source_that_is_not_source_text_is_refused_in_one_line(name, data, says):
    with pytest.raises(source_rules.SourceError) as e:
        source_rules.check({name: data}, 64, "01")
    assert says in str(e.value) and name in str(e.value) and "\n" not in str(e.value)


def test_the_labs_own_sources_pass():
    """Every solution and skeleton file of every lab is source text by these rules."""
    from labkit import registry
    for lab in registry.labs():
        for folder in ("solution", "skeleton"):
            files = {p.name: p.read_bytes() for p in (lab.path / folder).iterdir() if p.is_file()}
            source_rules.check(files, lab.handin_kib * 4, lab.number)


def test_a_reference_carried_as_text_is_refused_in_one_line(tmp_path):
    """The reference as base64 text in a header: more than lab 03 takes, refused before
    anything is built."""
    import base64

    from tests.grading.test_hostile import handin, solution_text
    text = base64.b64encode(sub.REFERENCE.read_bytes()[:600_000]).decode()
    folder = handin(tmp_path / "in", {
        "render.cpp": solution_text("03-openmp", "render.cpp"),
        "payload.h": "\n".join(text[i:i + 76] for i in range(0, len(text), 76))})
    binary, errors = build_lab("03", folder, trusted=False)
    assert binary is None and errors.startswith("refused: "), errors
    assert "lab 03 takes at most 16 KiB" in errors and "\n" not in errors, errors


# ---- the sweep ----------------------------------------------------------------------------

def test_a_chain_of_folders_thousands_deep_is_swept(tmp_path):
    """~3000 nested folders (each name 20 characters: 60,000 characters of path, past
    PATH_MAX) owned by a box: all removed, nothing raised."""
    uid = 1_999_999_001
    place = tmp_path / "shared"
    place.mkdir(mode=0o777)
    fd = os.open(place, os.O_RDONLY)
    try:
        for _ in range(3000):
            os.mkdir("f" * 20, dir_fd=fd)
            os.chown("f" * 20, uid, uid, dir_fd=fd, follow_symlinks=False)
            inner = os.open("f" * 20, os.O_RDONLY, dir_fd=fd)
            os.close(fd)
            fd = inner
        os.close(os.open("left", os.O_CREAT | os.O_WRONLY, 0o666, dir_fd=fd))
    finally:
        os.close(fd)
    try:
        assert boxes.remove_files(uid, places=(str(place),)) == []
        assert os.listdir(place) == []
    finally:  # whatever the sweep left, out of the way of pytest's own (recursive) cleanup
        fd = os.open(tmp_path, os.O_RDONLY)
        boxes._remove_tree(fd, "shared")
        os.close(fd)


def test_a_sweep_that_fails_still_ends_the_rest(monkeypatch):
    """Whatever one step of the sweep meets, the next ones run and it says what was left."""
    done = []

    def broken(uid):
        raise RecursionError("maximum recursion depth exceeded")
    monkeypatch.setattr(boxes, "remove_files", broken)
    monkeypatch.setattr(boxes, "end_processes", lambda uid, gid: [])
    monkeypatch.setattr(boxes, "remove_ipc", lambda uid: done.append(uid))
    problems = boxes.seal(1_999_999_002, 1_999_999_002)
    assert done == [1_999_999_002] and "RecursionError" in problems[0], problems


# ---- nothing of other students ------------------------------------------------------------

def test_a_runs_inputs_are_closed_to_other_runs(mode, tmp_path):
    """Another run, another student's, cannot read what this one was given."""
    given = tmp_path / "given"
    given.write_text("SECRET-OF-ONE\n")
    with sandbox.Runner(trusted=False) as first:
        staged = first.input(given)
        if sandbox.isolation() == sandbox.USER:
            second = sh(f"cat {staged}; exit 0")
            assert "SECRET-OF-ONE" not in second.stdout, second
        assert first.run(["/bin/cat", staged]).stdout == "SECRET-OF-ONE\n"


def test_a_class_open_to_every_user_is_refused_without_landlock(monkeypatch):
    """In the user sandbox without Landlock only permissions keep a run from the class's
    hand-ins: a batch whose folder any user may enter is refused in one line."""
    from grading.classes import batch
    if os.geteuid() != 0:
        pytest.skip("the user sandbox needs the grader to run as root")
    monkeypatch.setattr(sandbox, "_probe_result", [None])
    monkeypatch.setattr(sandbox, "_isolation", [sandbox.USER])
    monkeypatch.setattr(sandbox, "landlock_available", lambda: False)
    import shutil
    import tempfile
    base = pathlib.Path(tempfile.mkdtemp())  # pytest's tmp_path lies in a closed folder
    try:
        subs = base / "subs"
        (subs / "alice").mkdir(parents=True)
        for folder in (base, subs):
            folder.chmod(0o755)
        line = batch.exposure_problem([subs])
        assert line and "chmod 700" in line and "\n" not in line, line
        subs.chmod(0o700)
        assert batch.exposure_problem([subs]) is None
    finally:
        shutil.rmtree(base)
