"""A reference's double build, found in its binary and staged as a file of its own.

A reference renders in double what float cannot place by running the double build it carries
(common/host/double_twin.h) from an anonymous memory file. The sandbox runs no code that is no
file it staged (labkit/confine.py), so the grader stages the carried bytes as a program beside
the binary and names it in RT_DOUBLE_TWIN, which the reference runs instead. The bytes lie in
the binary's section `rt_double_twin` (common/host/double_twin.S), found from the ELF section
headers, which even a stripped binary keeps.

Only a binary the course gave the grader carries one that is staged: a hand-in's build could
name a section so as well, so the grader never stages one for it (grading/compile.py).
"""
from __future__ import annotations

import os
import pathlib
import struct

SECTION = b"rt_double_twin"
ENVIRONMENT = "RT_DOUBLE_TWIN"  # where the staged double build lies, as the run sees it
ELF64_LITTLE = b"\x7fELF\x02\x01"


_handin_builds: set[str] = set()


def built_from_a_handin(binary: os.PathLike | str) -> None:
    """Mark `binary` as a hand-in's build: no double build is staged for it."""
    _handin_builds.add(str(pathlib.Path(binary).resolve()))


def carried(binary: os.PathLike | str) -> bytes | None:
    """The double build `binary` carries, or None (not a 64-bit little-endian ELF file, no
    such section, an empty one, or headers that do not hold together)."""
    try:
        with open(binary, "rb") as f:
            header = f.read(64)
            if len(header) < 64 or not header.startswith(ELF64_LITTLE):
                return None
            shoff, = struct.unpack_from("<Q", header, 0x28)
            shentsize, shnum, shstrndx = struct.unpack_from("<HHH", header, 0x3A)
            if shentsize < 64 or not 0 < shnum < 4096 or shstrndx >= shnum:
                return None
            f.seek(shoff)
            table = f.read(shentsize * shnum)
            if len(table) < shentsize * shnum:
                return None
            sections = [struct.unpack_from("<IIQQQQ", table, k * shentsize)
                        for k in range(shnum)]  # name, type, flags, addr, offset, size
            _, _, _, _, names_at, names_size = sections[shstrndx]
            f.seek(names_at)
            names = f.read(min(names_size, 1 << 20))
            for name, kind, _, _, offset, size in sections:
                if names[name:name + len(SECTION) + 1] == SECTION + b"\0" and kind != 8:
                    f.seek(offset)
                    data = f.read(size)  # NOBITS (8) would hold nothing
                    return data if len(data) == size and data.startswith(b"\x7fELF") else None
    except (OSError, struct.error, IndexError):
        return None
    return None


def stage(binary: pathlib.Path, folder: pathlib.Path, name: str) -> pathlib.Path | None:
    """Write the double build `binary` carries to `folder`/`name` (mode 555); None where it
    carries none, or is a hand-in's build."""
    if str(pathlib.Path(binary).resolve()) in _handin_builds:
        return None
    data = carried(binary)
    if data is None:
        return None
    target = folder / name
    target.write_bytes(data)
    target.chmod(0o555)
    return target
