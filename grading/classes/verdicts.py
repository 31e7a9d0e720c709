"""A grade's verdict in a few words, as the class page and grades.csv show it: why points were
lost (the first failing check's own words, never a check that passed), which points wait for a
regrade, and whether the row is flagged for one."""
from __future__ import annotations

import re

# The cause of a failure, from what the failing check or the grader said: first match wins.
CAUSES = [
    ("foreign program", re.compile(r"ran a program it did not build")),
    ("timeout", re.compile(r"the grader did not finish in")),  # stopped by the batch
    ("no results", re.compile(r"left no results\.json")),
    ("compile error", re.compile(r"does not compile")),
    ("no hand-in", re.compile(r"the hand-in holds (none|lab)")),
    ("refused", re.compile(r"the hand-in was refused")),
    ("timeout", re.compile(r"timed out")),
    ("rows missing", re.compile(r"never (rendered|gathered)")),
    ("threads took turns", re.compile(r"the threads ran one at a time")),
    ("work split", re.compile(r"deterministic but different")),
    ("race", re.compile(r"nondeterministic|data race|differs? for|differs from the serial")),
    ("signal", re.compile(r"killed by|signal|SIG[A-Z]+")),
    ("crash", re.compile(r"exit status|exited with|could not run")),
    ("no sandbox", re.compile(r"without a sandbox")),
    ("no GPU", re.compile(r"NVIDIA GPU|cannot render on this machine's GPU")),
]


CAUSE_CHARS = 200  # of a cause's words: the row's whole story is on the submission's page


def clipped(text: str, most: int = CAUSE_CHARS) -> str:
    """`text` cut at most `most` characters, at a space where there is one, marked with an
    ellipsis: never a word cut in half."""
    if len(text) <= most:
        return text
    cut = text[:most - 1]
    return (cut[:cut.rfind(" ")] if " " in cut else cut).rstrip(" ,;:") + "…"


def around(line: str, pattern: re.Pattern, most: int = CAUSE_CHARS) -> str:
    """`line`, or where the words that name the cause would be cut off, the clause holding
    them onward: the label's evidence is always shown."""
    found = pattern.search(line)
    if not found or found.end() <= most - 20:
        return line
    start = max(line.rfind("; ", 0, found.start()), line.rfind(": ", 0, found.start()))
    return "…" + line[start + 2:] if start >= 0 else line


def provisional_points(results: dict) -> int:
    """Points waiting for a regrade (a machine too busy to measure them), which results.json
    keeps apart from the score ("+N if the regrade confirms"): the regrade decides them."""
    return sum(t.get("extra_data", {}).get("provisional", 0) for t in results.get("tests", [])
               if t.get("extra_data", {}).get("regrade"))


def flagged(results: dict) -> bool:
    """To be graded again on a quiet machine: provisional points, or refused for the
    machine's sake (no GPU), or no results at all; or for course staff to look at (a
    program it did not build ran, or a run's leftovers could not be removed)."""
    return (any(t.get("extra_data", {}).get("regrade") for t in results.get("tests", []))
            or not results.get("tests") or bool(results.get("for_staff")))


def waiting(test: dict) -> bool:
    """A check whose points wait for a gate and which lost none of its own: not run yet, or
    run and passed ("not counted until ...; it saw: PASS ..."). The gate's verdict is the
    cause, never a check that passed."""
    output = test.get("output", "")
    return output.startswith("not graded until") or (
        output.startswith("not counted until") and "it saw: PASS" in output)


def failure_cause(results: dict) -> str:
    """Why points were lost, in a few words, with the first failing check's words: the
    compiler's first error, a signal, a timeout, a race, which image check."""
    tests = results.get("tests", [])
    top = results.get("output", "")
    failing = [t for t in tests if t.get("status") != "passed" and not waiting(t)]
    texts = [top] + [f"{t['name']}: {t.get('output', '')}" for t in failing]
    for cause, pattern in CAUSES:
        for text in texts:
            if pattern.search(text):
                if cause == "refused":  # the grader's one line, once
                    why = text.split("the hand-in was refused: ", 1)[1].splitlines()
                    return f"refused: {clipped(why[0]) if why else ''}"
                if cause == "compile error":  # the compiler's first line after the note
                    lines = top.splitlines()
                    at = next((i for i, line in enumerate(lines) if "does not compile" in line), 0)
                    after = [line for line in lines[at + 1:] if line.strip()]
                    return f"compile error: {clipped(after[0]) if after else ''}".rstrip(": ")
                return f"{cause}: {clipped(around(text.splitlines()[0], pattern))}"
    if failing:
        t = failing[0]
        kind = "image check" if t.get("extra_data", {}).get("check", "").startswith(
            ("golden", "hidden", "sphere", "lit", "glass", "scale")) else "check"
        first = clipped(t.get("output", "").splitlines()[0]) if t.get("output") else ""
        return f"{kind} {t['name']}: {first}"
    return ""
