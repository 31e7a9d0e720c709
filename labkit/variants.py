"""Build variants of a CPU lab from edited sources without touching the working tree: the
pristine skeleton (as students first receive it, whatever they have done to theirs since) and
the deliberately broken mutants of the mutation tests.

The Makefile is the one place that knows how a lab is built (`make variant`): this module only
lays out a folder of sources and asks it. A header in that folder stands in for the shared one
of the same name, because the folder comes first on the include path."""
from __future__ import annotations

import pathlib

from labkit.harness import ROOT, make_in_root


def lab_sources(lab: str, source_dir: str = "solution") -> dict[str, str]:
    """The files directly in labs/<lab>/<source_dir> (not its subfolders), by name."""
    folder = ROOT / "labs" / lab / source_dir
    return {p.name: p.read_text() for p in sorted(folder.iterdir()) if p.is_file()}


def build_sources(variant_lab: str, workdir: pathlib.Path, sources: dict[str, str],
                  make_args=(), target: str = "variant") -> pathlib.Path:
    """Write `sources` (bare file names: render.cpp, path_steps.h, ray.h...) into a folder and
    build them as the Makefile builds `variant_lab` (a lab folder name, or 02-simd-a for lab 02
    Part A); `make_args` override Makefile variables (e.g. OPT, BUILD); `target` is
    cuda-variant for a CUDA lab. Returns the binary."""
    src = workdir / "src"
    src.mkdir(parents=True, exist_ok=True)
    for name, text in sources.items():
        (src / name).write_text(text)
    p = make_in_root(target, f"VARIANT_LAB={variant_lab}", f"VARIANT={src}", *make_args,
                     capture_output=True, text=True)
    if p.returncode != 0:
        raise RuntimeError(
            f"building a {variant_lab} variant failed:\n{(p.stdout + p.stderr)[-2000:]}"
        )
    return src / "lab"


def build_variant(lab: str, workdir: pathlib.Path, overrides: dict[str, str],
                  source_dir: str = "solution") -> pathlib.Path:
    """labs/<lab>/<source_dir>'s files with those named in `overrides` replaced or added."""
    return build_sources(lab, workdir, {**lab_sources(lab, source_dir), **overrides})


def pristine_skeleton_sources(lab: str) -> dict[str, str]:
    """The skeleton files of a lab exactly as labkit/skeletons.py generates them, by path
    below skeleton/ (lab 02's Part A is part-a/vec3.h)."""
    from labkit import skeletons  # not in a student release, which has no solutions to read
    base = ROOT / "labs" / lab / "skeleton"
    return {path.relative_to(base).as_posix(): text for path, text in skeletons.generated_files()
            if path.is_relative_to(base)}


def build_pristine_skeleton(lab: str, workdir: pathlib.Path) -> pathlib.Path:
    """The skeleton as students receive it (its top-level files; lab 02's Part A has its own
    builder in test_lab02): the tests of its expected failures use this, so `make test` stays
    green while a student fills in their own copy."""
    files = {name: text for name, text in pristine_skeleton_sources(lab).items() if "/" not in name}
    return build_sources(lab, workdir, files)
