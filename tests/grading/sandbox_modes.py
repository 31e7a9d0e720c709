"""One command in a sandboxed Runner of its own, as the grader makes one per run, for the
hostile tests (in the sandbox the `mode` fixture picks: tests/grading/conftest.py)."""
from labkit.sandbox import Limits, Runner

QUICK = Limits(wall_seconds=10)


def sh(script: str, limits: Limits = QUICK):
    """One run in a Runner of its own, as the grader makes one per run."""
    with Runner(trusted=False) as r:
        return r.run(["/bin/sh", "-c", script], limits)


def py(code: str, limits: Limits = QUICK):
    with Runner(trusted=False) as r:
        return r.run(["/usr/bin/python3", "-I", "-c", code], limits)
