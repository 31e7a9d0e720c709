#!/usr/bin/env python3
"""Where a kernel's innermost loops branch, from its machine code (`cuobjdump -sass`).

A loop is a backward branch. For each innermost loop of each kernel this prints its length in
instructions and the branches inside it other than the loop's own: a `BSSY` (the compiler
marks where a warp that may split must rejoin) followed by a forward `BRA` is a branch the
lanes can take differently. Those that only skip a `CALL` to a slow path (of IEEE division or
square root, taken for extreme operands) are counted apart: the lanes take them together in
practice. So are those on a predicate that a `VOTE.ANY` or `VOTE.ALL` set (`__any_sync`,
`__all_sync`: every lane gets the same answer, so the warp takes them whole). Needs no GPU,
only an object or binary and cuobjdump.

    cuobjdump -sass build/labs/05-cuda-mega/solution/render.o | loop_branches.py [--kernel TEXT]
"""
from __future__ import annotations

import argparse
import re
import sys

FUNCTION = re.compile(r"Function : (\S+)")
INSTRUCTION = re.compile(r"/\*([0-9a-f]{4,})\*/\s+(.*?)\s*;")
TARGET = re.compile(r"\bBRA(?:\.\S+)?\s+(?:`\()?(0x[0-9a-f]+)")


def kernels(sass: str) -> dict[str, list[tuple[int, str]]]:
    """Each function's instructions as (address, text)."""
    out: dict[str, list[tuple[int, str]]] = {}
    current = None
    for line in sass.splitlines():
        if m := FUNCTION.search(line):
            current = out.setdefault(m[1], [])
        elif current is not None and (m := INSTRUCTION.search(line)):
            current.append((int(m[1], 16), m[2]))
    return out


def innermost_loops(code: list[tuple[int, str]]) -> list[tuple[int, int]]:
    """(first, last) addresses of the loops that hold no other loop."""
    loops = []
    for address, text in code:
        if (m := TARGET.search(text)) and int(m[1], 16) <= address:
            loops.append((int(m[1], 16), address))
    loops = [(a, b) for a, b in loops if a < b]  # not the trap at a kernel's end (BRA to itself)
    # A backward branch from the code the compiler parks after the kernel's end (where a warp
    # that reached a vote split goes) starts inside a loop and ends past it: no loop of its own.
    loops = [(a, b) for a, b in loops if not any(c < a < d < b for c, d in loops)]
    return [(a, b) for a, b in loops
            if not any((a, b) != (c, d) and a <= c and d <= b for c, d in loops)]


def set_by_vote(body: list[tuple[int, str]], i: int, predicate: str) -> bool:
    """Whether the last instruction before body[i] that writes `predicate` is a warp vote."""
    for _, text in reversed(body[:i]):
        operands = re.sub(r"^@!?U?P\d+\s+", "", text).split(None, 1)
        if len(operands) < 2:
            continue
        destinations = [d.strip() for d in operands[1].split(",")[:2]]
        if predicate in destinations:
            return operands[0].startswith(("VOTE.ANY", "VOTE.ALL"))
    return False


def branches_in(code: list[tuple[int, str]], first: int, last: int) -> tuple[int, int, int]:
    """(divergent, slow-path, warp-uniform) forward branches between first and last, the loop's
    own excluded: a conditional BRA is a slow-path guard when the next instructions before its
    target hold a CALL (the compiler's slow path of division or square root), and warp-uniform
    when a vote set its predicate."""
    body = [(a, t) for a, t in code if first <= a < last]
    divergent = slow = uniform = 0
    for i, (address, text) in enumerate(body):
        m = TARGET.search(text)
        if not m or not text.startswith("@") or int(m[1], 16) <= address:
            continue
        target = int(m[1], 16)
        skipped = [t for a, t in body[i + 1:] if a < target]
        if any(t.startswith("CALL") for t in skipped) and len(skipped) <= 5:
            slow += 1
        elif set_by_vote(body, i, text.split()[0].lstrip("@!")):
            uniform += 1
        else:
            divergent += 1
    return divergent, slow, uniform


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("sass", nargs="?", help="cuobjdump -sass output (default: stdin)")
    parser.add_argument("--kernel", default="render_kernel",
                        help="only functions whose (mangled) name contains this")
    args = parser.parse_args()
    text = open(args.sass).read() if args.sass else sys.stdin.read()
    found = False
    for name, code in kernels(text).items():
        if args.kernel not in name:
            continue
        found = True
        print(name)
        for first, last in innermost_loops(code):
            divergent, slow, uniform = branches_in(code, first, last)
            length = sum(1 for a, _ in code if first <= a <= last)
            print(f"  loop {first:#06x}-{last:#06x}: {length} instructions, "
                  f"{divergent} divergent branches, {slow} slow-path guards, "
                  f"{uniform} warp-uniform branches")
    if not found:
        print(f"loop_branches: no function matching {args.kernel!r}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
