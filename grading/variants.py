"""Build variants of a CPU lab from edited sources without touching the working tree: the
pristine skeleton (as students first receive it, whatever they have done to theirs since) and
the deliberately broken mutants of the mutation tests."""
from __future__ import annotations

import importlib.util
import pathlib
import shlex
import shutil
import subprocess

from grading.harness import ROOT, build

# The shared driver every lab binary links: common/<name>.cpp, built as build/common/<name>.o.
DRIVER_SOURCES = ("scene_loader", "image", "cli", "progress", "lab_main", "main")


def build_command() -> list[str]:
    """The Makefile's compiler command for lab binaries (make print-build-command), without
    its dependency-file flags, with RT_SOURCE_DIR quoted for a direct call."""
    out = subprocess.run(["make", "-s", "-C", str(ROOT), "print-build-command"],
                         capture_output=True, text=True, check=True).stdout
    flags = [f for f in shlex.split(out) if not f.startswith(("-DRT_SOURCE_DIR", "-MMD", "-MP"))]
    return flags + [f'-DRT_SOURCE_DIR="{ROOT}"']


def build_variant(lab: str, workdir: pathlib.Path, overrides: dict[str, str],
                  source_dir: str = "solution", extra_flags=()) -> pathlib.Path:
    """Compile labs/<lab>/<source_dir>/*.cpp against copies of common/'s headers, with the
    files named in `overrides` (bare file names: render.cpp, path_tracer.h, ray.h...) replaced
    by the given text. Links the shared driver objects; returns the binary's path."""
    build("lab01-ref")  # makes sure the driver objects exist
    src = workdir / "src"
    shutil.copytree(ROOT / "common", src, ignore=shutil.ignore_patterns("scenes", "*.cpp"))
    for cpp in (ROOT / "labs" / lab / source_dir).glob("*"):
        shutil.copy(cpp, src)
    for name, text in overrides.items():
        (src / name).write_text(text)
    objects = [str(ROOT / "build" / "common" / f"{o}.o") for o in DRIVER_SOURCES]
    binary = workdir / "lab"
    sources = sorted(str(p) for p in src.glob("*.cpp"))
    p = subprocess.run([*build_command(), *extra_flags, "-w", f"-I{src}", *sources, *objects,
                        "-o", str(binary)], capture_output=True, text=True)
    if p.returncode != 0:
        raise RuntimeError(f"building a {lab} variant failed:\n{p.stderr[-2000:]}")
    return binary


def pristine_skeleton_sources(lab: str) -> dict[str, str]:
    """The skeleton files of a lab exactly as tools/skeletons.py generates them."""
    spec = importlib.util.spec_from_file_location("skeletons", ROOT / "tools" / "skeletons.py")
    skeletons = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(skeletons)
    return {path.name: text for path, text in skeletons.generated_files()
            if path.parent.parent.name == lab}


def build_pristine_skeleton(lab: str, workdir: pathlib.Path, extra_flags=()) -> pathlib.Path:
    """The skeleton as students receive it: the tests of its expected failures use this, so
    `make test` stays green while a student fills in their own copy."""
    return build_variant(lab, workdir, pristine_skeleton_sources(lab), extra_flags=extra_flags)
