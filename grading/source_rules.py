"""What a hand-in's sources may be: text a student wrote, sized like a lab.

A hand-in is built from its sources, and only what it builds may run (labkit/sandbox.py). So
a source file must be source: UTF-8 text without NUL bytes (a program's bytes under a `.h`
name are neither), the hand-in's files together at most the lab's `handin_kib` in
labs/labs.toml (a few times its skeleton's size: room for any solution, none for a program
carried as text), and no directive that pulls other files' bytes into the build: the
assembler's `.incbin`, C23's `#embed`, or an `#include` of a path outside the hand-in's own
tree (absolute, `..`, or a name made by a macro). Each refusal is one line naming the file.

The directives are read from the text as the preprocessor reads it (lines spliced at a
backslash, comments removed) but without running it; what a macro could still assemble
reaches only what the compile's sandbox shows (grading/compile.py): the students' tree and
the system's headers, never a reference or another student's files.
"""
from __future__ import annotations

import re

from grading import shown

SPLICE = re.compile(r"\\\r?\n")
COMMENT = re.compile(r"/\*.*?\*/|//[^\n]*", re.S)
# A directive starts a line: `#` or its digraph `%:`, then the directive's name.
DIRECTIVE = re.compile(r"^[ \t]*(?:#|%:)[ \t]*(include_next|include|import|embed)\b[ \t]*(.*)$",
                       re.M)
INCBIN = re.compile(r"incbin", re.I)
HAS_EMBED = re.compile(r"__has_embed")


class SourceError(Exception):
    """Why a hand-in's source cannot be built: one line naming the file."""


def text_of(name: str, data: bytes) -> str:
    """`data` as text, or SourceError: a NUL byte or bytes that are not UTF-8."""
    where = shown.line(name)
    if b"\0" in data:
        raise SourceError(f"{where} holds NUL bytes: a hand-in is source text, not a program "
                          f"or data")
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as e:
        raise SourceError(f"{where} is not UTF-8 text (byte {e.start}): a hand-in is source "
                          f"text, not a program or data") from None


def check_directives(name: str, text: str) -> None:
    """SourceError for a directive that pulls in bytes from outside the hand-in's tree."""
    where = shown.line(name)
    if INCBIN.search(text):
        raise SourceError(f"{where} uses the assembler's .incbin: a hand-in's code is its own "
                          f"text, never another file's bytes")
    code = COMMENT.sub(" ", SPLICE.sub("", text))
    if HAS_EMBED.search(code):
        raise SourceError(f"{where} uses #embed: a hand-in's code is its own text, never "
                          f"another file's bytes")
    for m in DIRECTIVE.finditer(code):
        directive, operand = m.group(1), m.group(2).strip()
        if directive == "embed":
            raise SourceError(f"{where} uses #embed: a hand-in's code is its own text, never "
                              f"another file's bytes")
        quoted = re.match(r'"([^"]*)"|<([^>]*)>', operand)
        if not quoted:
            raise SourceError(f"{where}: #{directive} {shown.line(operand)[:60]} names its file "
                              f"through a macro: write the file's name")
        path = quoted.group(1) if quoted.group(1) is not None else quoted.group(2)
        if path.startswith(("/", "~")) or ".." in path.replace("\\", "/").split("/"):
            raise SourceError(f"{where}: #{directive} {shown.line(operand)[:60]} reaches outside "
                              f"the hand-in's tree: include the lab's files by their names")


def check(files: dict[str, bytes], limit_kib: int, lab: str) -> None:
    """SourceError for the first file of `files` (name -> bytes) that is no source, or for
    files that together pass the lab's limit."""
    total = sum(len(data) for data in files.values())
    if total > limit_kib << 10:
        raise SourceError(f"the hand-in's sources hold {total / 1024:.0f} KiB; lab {lab} takes "
                          f"at most {limit_kib} KiB (a few times its skeleton)")
    for name, data in sorted(files.items()):
        check_directives(name, text_of(name, data))
