"""The golden data's checksums: reference/golden/SHA256SUMS records the SHA-256 of every file
the image comparisons read (each scene's golden.pfm, variance.pfm and meta.json, and the scene
file meta.json names). The grader verifies them before it grades anything: golden data that
was edited, truncated or overwritten would grade every submission against the wrong image,
and the grader would rather refuse, saying which file and what to do. `make golden` rewrites
the record with the data it makes (tools/make_golden.py).
"""
from __future__ import annotations

import hashlib
import json
import pathlib

from labkit.harness import GOLDEN, ROOT

RECORD = GOLDEN / "SHA256SUMS"


class GoldenDataError(RuntimeError):
    """Golden data that does not match its recorded checksum, or has none."""


def sha256(path: pathlib.Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def covered_files(golden: pathlib.Path = GOLDEN) -> list[pathlib.Path]:
    """Every file the comparisons read, for each scene folder of `golden`."""
    files = []
    for folder in sorted(p for p in golden.iterdir() if p.is_dir()):
        meta = folder / "meta.json"
        files += [folder / "golden.pfm", folder / "variance.pfm", meta]
        files.append(ROOT / json.loads(meta.read_text())["scene"])
    return files


def record(golden: pathlib.Path = GOLDEN) -> str:
    """The checksum file's text for the golden data as it is now ("HASH  PATH" lines, paths
    relative to the repository, as `sha256sum` writes and `sha256sum -c` reads)."""
    return "".join(f"{sha256(f)}  {f.relative_to(ROOT)}\n" for f in covered_files(golden))


def problem(golden: pathlib.Path = GOLDEN, record_path: pathlib.Path | None = None) -> str | None:
    """What is wrong with the golden data against its record, or None."""
    record_path = record_path or golden / "SHA256SUMS"
    if not record_path.exists():
        return (
            f"{record_path.relative_to(ROOT)} is missing: regenerate the golden data (make golden)"
        )
    recorded = {}
    for line in record_path.read_text().splitlines():
        digest, _, name = line.partition("  ")
        recorded[name] = digest
    for f in covered_files(golden):
        name = str(f.relative_to(ROOT))
        if name not in recorded:
            return (
                f"{name} has no recorded checksum in {record_path.relative_to(ROOT)}: make golden"
            )
        if sha256(f) != recorded[name]:
            return (f"{name} does not match its recorded checksum "
                    f"({record_path.relative_to(ROOT)}): restore it (git checkout) or "
                    f"regenerate the golden data (make golden)")
    return None

