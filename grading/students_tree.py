"""The tree a submission is compiled in: exactly what a student of the lab holds, never more.

In the course repository (and in the Gradescope bundle, which is that repository) the shared
files students write, such as lab 01's common/core/path_steps.h, are the solutions: a
hand-in that leaves its copy out would be built against the solution, and the objects in
build/ are the references'. So a submission is compiled in a students' tree made for its lab:

- the Makefile, cuda.mk, grading/grading.mk, the lab registry (labs/labs.toml and
  labkit/registry.py, which the Makefile reads), every lab's lab.mk and top-level files (the
  drivers a lab links), and common/ with every shared file whose solution regions belong to
  this lab or a later one in its skeleton form (what a student release holds:
  grading/releases/release.py); an earlier lab's shared files stay solutions (lab 07 builds on lab
  06's reference queue and stage loop in common/wavefront/);
- in its own build/, the driver objects compiled from those files, by the grader, outside the
  sandbox (course code), once per content: cached under build/students-trees/ and copied for
  each grade into a fresh folder the sandbox user may read, wherever the repository lives;
- the submission's files, read without following links (`collect`), above the pristine
  skeleton: a file the lab expects that the hand-in lacks is the skeleton's stub, and a
  hand-in holding none of the expected files is refused in one line that names them.

A hand-in is sources and nothing else: a program or any other file in it is never run or
built, only named in one line (`ignored`); and a source's name is data, never code: one
outside `PLAIN_NAME` is refused before it reaches the build's command line.
"""
from __future__ import annotations

import hashlib
import importlib
import importlib.util
import os
import pathlib
import re
import shutil
import stat
import subprocess
import tempfile

from grading import shown
from labkit.harness import ROOT

SOURCE_SUFFIXES = (".cpp", ".h", ".hpp", ".cu", ".cuh")
MAX_FILE_BYTES = 1 << 20      # a source file of a lab is tens of KiB
MAX_FILES = 64                # source files taken from the chosen folder
MAX_WALK_ENTRIES = 20000      # entries looked at while searching a hand-in
# The names a built file may have: the build globs them into a compiler's command line.
PLAIN_NAME = re.compile(r"[A-Za-z0-9_.+-]+")

class HandInError(Exception):
    """A hand-in that cannot be built as it is: one line for the student."""


def _skeletons():
    """labkit.skeletons, or None in a student release, which ships neither it nor the
    solutions it reads: there every file already is what a student holds."""
    if importlib.util.find_spec("labkit.skeletons") is None:
        return None
    return importlib.import_module("labkit.skeletons")


def lab_number(lab_folder: str) -> str:
    return lab_folder.split("-")[0]


def skeleton_form(lab_folder: str) -> set[str]:
    """Shared files (paths from the root) that a student of `lab_folder` holds as skeletons:
    those of this lab and of every later one, as in a release (grading/releases/release.py).
    Empty in a release, whose shared files are skeletons already."""
    skeletons = _skeletons()
    if skeletons is None:
        return set()
    return {path for name, paths in skeletons.SHARED_SOURCES.items() if name >= lab_folder
            for path in paths}


def pristine_skeleton(lab_folder: str) -> dict[str, str]:
    """The skeleton's top-level files as labkit/skeletons.py makes them from the solutions
    (not the checkout's skeleton/ folder, which an instructor may have edited). In a release,
    the skeleton as its one commit holds it (the student's edits are their hand-in)."""
    base = ROOT / "labs" / lab_folder / "skeleton"
    skeletons = _skeletons()
    if skeletons is None:
        return {name: _committed(base / name) for name in sorted(
            p.name for p in base.iterdir() if p.is_file() and not p.is_symlink())}
    return {path.relative_to(base).as_posix(): text
            for path, text in skeletons.generated_files()
            if path.is_relative_to(base) and "/" not in path.relative_to(base).as_posix()}


def _committed(path: pathlib.Path) -> str:
    """A file as the release's commit holds it, else as it is."""
    rel = path.relative_to(ROOT).as_posix()
    p = subprocess.run(["git", "-C", str(ROOT), "show", f"HEAD:{rel}"], capture_output=True,
                       text=True)
    return p.stdout if p.returncode == 0 else path.read_text()


def expected_files(lab_folder: str) -> list[str]:
    return sorted(pristine_skeleton(lab_folder))


# ---- reading a hand-in --------------------------------------------------------------------

def read_regular(path: pathlib.Path, where: str) -> bytes:
    """A regular file's bytes, never through a link (O_NOFOLLOW on the file; its folders were
    reached by a walk that does not follow links either)."""
    where = shown.line(where)
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK | os.O_CLOEXEC)
    except OSError as e:
        if os.path.islink(path):
            raise HandInError(f"{where} is a symbolic link: hand in the file itself") from None
        raise HandInError(f"{where} cannot be read: {e.strerror}") from None
    with os.fdopen(fd, "rb") as f:
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            raise HandInError(f"{where} is not a regular file")
        data = f.read(MAX_FILE_BYTES + 1)
    if len(data) > MAX_FILE_BYTES:
        raise HandInError(f"{where} is larger than {MAX_FILE_BYTES >> 10} KiB")
    return data


def _candidates(root: pathlib.Path) -> dict[pathlib.Path, list[str]]:
    """Folder (relative) -> the names of source files and links in it, found by a walk that
    follows no link. Build products, version control and hidden folders are skipped."""
    found: dict[pathlib.Path, list[str]] = {}
    seen = 0
    for dirpath, dirs, files in os.walk(root, followlinks=False):
        # A link to a folder is listed among dirs (and not entered): a source-named one is
        # a link handed in as a file, refused when its folder is taken.
        links = [d for d in dirs if os.path.islink(os.path.join(dirpath, d))]
        dirs[:] = sorted(d for d in dirs if d not in links and not d.startswith(".")
                         and d not in ("build", "__MACOSX"))
        seen += len(dirs) + len(files)
        if seen > MAX_WALK_ENTRIES:
            raise HandInError(f"the hand-in holds more than {MAX_WALK_ENTRIES} files and folders")
        names = [n for n in files + links if n_is_source(n)]
        if names:
            found[pathlib.Path(dirpath).relative_to(root)] = sorted(set(names))
    return found


def n_is_source(name: str) -> bool:
    return name.endswith(SOURCE_SUFFIXES) and not name.startswith(".")


def collect(handin: pathlib.Path, lab_folder: str) -> tuple[dict[str, bytes], list[str]]:
    """The submission's source files by name, and the expected names it did not hand in.

    The files may sit in a folder (a zipped folder, a repository checkout): the folder holding
    the most of the lab's expected files is taken, the shallowest on a tie. A link or anything
    but a regular file there is refused; so is a hand-in holding none of the expected files."""
    expected = expected_files(lab_folder)
    listing = _candidates(handin)
    ranked = sorted(listing.items(),
                    key=lambda kv: (-len(set(kv[1]) & set(expected)), len(kv[0].parts), str(kv[0])))
    if not ranked or not set(ranked[0][1]) & set(expected):
        raise HandInError(f"no file of lab {lab_number(lab_folder)} was handed in: "
                          f"expected {', '.join(expected)}")
    folder, names = ranked[0]
    for name in names:
        if not PLAIN_NAME.fullmatch(name):
            raise HandInError(f"the file name {shown.line(repr((folder / name).as_posix()))} "
                              f"may hold only letters, digits and _ . + -: rename it")
    if len(names) > MAX_FILES:
        where = shown.line(folder.as_posix()) if folder.parts else "the hand-in"
        raise HandInError(f"{where} holds {len(names)} source files; at most {MAX_FILES} "
                          f"are built")
    files = {}
    for name in names:
        files[name] = read_regular(handin / folder / name, (folder / name).as_posix())
    return files, [n for n in expected if n not in files]


def _looks_executable(path: str, mode: int) -> bool:
    """Executable bits, or a program's first bytes (a zip keeps no mode): ELF, a script."""
    if mode & 0o111:
        return True
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK | os.O_CLOEXEC)
    except OSError:
        return False
    with os.fdopen(fd, "rb") as f:
        return f.read(4).startswith((b"\x7fELF", b"#!"))


def _listed(names: list[str], most: int = 5) -> str:
    more = f" and {len(names) - most} more" if len(names) > most else ""
    return ", ".join(names[:most]) + more


def ignored(handin: pathlib.Path) -> str:
    """One line naming what the hand-in holds besides sources (programs first), none of which
    is run or built; "" when it holds nothing else. Build products, version control and
    hidden folders are passed over, as the search for sources passes them."""
    programs, others, seen = [], [], 0
    for dirpath, dirs, files in os.walk(handin, followlinks=False):
        dirs[:] = sorted(d for d in dirs if not os.path.islink(os.path.join(dirpath, d))
                         and not d.startswith(".") and d not in ("build", "__MACOSX"))
        seen += len(dirs) + len(files)
        if seen > MAX_WALK_ENTRIES:  # the search for sources refuses such a hand-in
            break
        for name in sorted(files):
            if n_is_source(name) or name.startswith("."):
                continue
            path = os.path.join(dirpath, name)
            try:
                st = os.lstat(path)
            except OSError:
                continue
            rel = os.path.relpath(path, handin)
            program = stat.S_ISREG(st.st_mode) and _looks_executable(path, st.st_mode)
            (programs if program else others).append(rel)
    parts = []
    if programs:
        parts.append(f"{len(programs)} program(s), never run: {_listed(programs)}")
    if others:
        parts.append(f"{len(others)} other file(s), not sources: {_listed(others)}")
    return shown.line(f"ignored, graded from its sources: {'; '.join(parts)}") if parts else ""


# ---- the tree -----------------------------------------------------------------------------

def _tree_files(lab_folder: str) -> dict[str, bytes]:
    """Path -> content of the students' tree's sources."""
    # The Makefile reads the lab registry through labkit/registry.py (build/labs.mk).
    picked = [ROOT / "Makefile", ROOT / "cuda.mk", ROOT / "grading" / "grading.mk",
              ROOT / "labs" / "labs.toml", ROOT / "labkit" / "__init__.py",
              ROOT / "labkit" / "registry.py"]
    for lab in sorted((ROOT / "labs").iterdir()):
        if lab.is_dir():
            picked += [f for f in sorted(lab.iterdir()) if f.is_file() and not f.is_symlink()]
    picked += sorted(p for p in (ROOT / "common").rglob("*") if p.is_file())
    # A skeleton's folders (lab 02's part-a/vec3.h): the driver a part is linked with is
    # built with them (labs/02-simd/lab.mk).
    picked += sorted(p for p in (ROOT / "labs").glob("*/skeleton/*/*") if p.is_file())
    as_skeleton = skeleton_form(lab_folder)
    skeletons = _skeletons()
    files = {}
    for path in picked:
        rel = path.relative_to(ROOT).as_posix()
        if rel in as_skeleton:
            files[rel] = skeletons.skeleton_text(path.read_text(), rel).encode()
        else:
            files[rel] = path.read_bytes()
    return files


def _driver_target(variant_target: str) -> str:
    return {"cuda-variant": "cuda-variant-driver",
            "race-variant": "race-variant-driver"}.get(variant_target, "variant-driver")


def cached_tree(lab_folder: str, target: str = "variant",
                variant_lab: str | None = None) -> pathlib.Path:
    """The students' tree of `lab_folder` with the driver objects of `variant_lab` (default:
    the lab itself; 02-simd-a: lab 02's Part A) built (once per content and compiler:
    build/students-trees/<variant>-<digest>/)."""
    variant_lab = variant_lab or lab_folder
    files = _tree_files(lab_folder)
    digest = hashlib.sha256()
    for rel, data in sorted(files.items()):
        digest.update(rel.encode() + b"\0" + hashlib.sha256(data).digest())
    digest.update(subprocess.run(["c++", "--version"], capture_output=True).stdout)
    digest.update(target.encode())
    cache = ROOT / "build" / "students-trees"
    tree = cache / f"{variant_lab}-{digest.hexdigest()[:16]}"
    if (tree / ".complete").exists():
        return tree
    cache.mkdir(parents=True, exist_ok=True)
    partial = pathlib.Path(tempfile.mkdtemp(prefix=f".{lab_folder}-", dir=cache))
    try:
        for rel, data in files.items():
            (partial / rel).parent.mkdir(parents=True, exist_ok=True)
            (partial / rel).write_bytes(data)
        p = subprocess.run(["make", "-s", "-j2", "-C", str(partial), _driver_target(target),
                            f"VARIANT_LAB={variant_lab}"], capture_output=True, text=True,
                           errors="replace", env={**os.environ, "MAKEFLAGS": ""})
        if p.returncode != 0:
            raise RuntimeError(f"the students' tree of {variant_lab} does not build its "
                               f"driver: {(p.stdout + p.stderr)[-1500:]}")
        # The tree is never built again: its make dependency files would only reach the
        # repository's own make, which includes every *.d under build/.
        for dep in partial.rglob("*.d"):
            dep.unlink()
        (partial / ".complete").write_text("")
        try:
            partial.rename(tree)
        except OSError:  # another grader made it meanwhile
            pass
    finally:
        shutil.rmtree(partial, ignore_errors=True)
    return tree


def stage(lab_folder: str, handin_files: dict[str, bytes], missing: list[str],
          target: str = "variant", variant_lab: str | None = None) -> pathlib.Path:
    """A fresh copy of the students' tree (mode 755, outside the repository, so the sandbox
    user reaches it wherever the repository lives) with the submission in `submission/` above
    the stubs of what it lacks. The caller removes the folder."""
    tree = cached_tree(lab_folder, target, variant_lab)
    work = pathlib.Path(tempfile.mkdtemp(prefix="students-tree-"))
    work.chmod(0o755)
    root = work / "tree"
    shutil.copytree(tree, root, symlinks=False)  # copy2: the objects stay newer than sources
    for dirpath, _dirs, files in os.walk(root):
        os.chmod(dirpath, 0o755)
        for f in files:
            os.chmod(os.path.join(dirpath, f), 0o644)
    src = root / "submission"
    src.mkdir(mode=0o755)
    stubs = pristine_skeleton(lab_folder)
    for name in missing:
        (src / name).write_text(stubs[name])
    for name, data in handin_files.items():
        (src / name).write_bytes(data)
    return work
