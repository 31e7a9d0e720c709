"""results.json in Gradescope's format, kept complete at every moment of a grade.

Every test of the rubric is in the file from the start ("not graded yet"), the file is
rewritten atomically after each test, and a refused, interrupted or failed grade is written
too: whatever happens to the grader, the instructor finds a results.json that says what
happened.
"""
from __future__ import annotations

import dataclasses
import json
import os
import pathlib
import tempfile
import time

from grading import shown
from grading.speed_numbers import leaderboard

# Gradescope shows the output of a test as is; a submission's stderr must not make it huge.
MAX_OUTPUT_CHARS = 4000


@dataclasses.dataclass
class Test:
    __test__ = False  # a graded check, not a pytest test class (the grader's tests import it)

    id: str
    label: str
    max_score: int
    score: int = 0
    output: str = "not graded yet"
    seconds: float = 0.0
    finished: bool = False
    ok: bool = False       # the check passed (a 0-point gate passes without points)
    regrade: bool = False  # the machine could not measure it: marked for regrade
    provisional: int = 0   # points a regrade may add; never in `score` or the total
    # Gradescope's: "visible", or "after_published" for a hidden test, whose outcome the
    # top-level output states in one line meanwhile (Results.complete)
    visibility: str = "visible"

    @property
    def passed(self) -> bool:
        return self.finished and self.ok

    def finish(self, score: int, output: str, seconds: float = 0.0, regrade: bool = False,
               ok: bool = False, provisional: int = 0):
        """`ok`: the check ran and passed; a test not graded (refused, interrupted, gated) is
        never ok, whatever its points. `provisional`: points a regrade may add (shown in the
        output and extra_data, never in the score)."""
        if provisional:
            output = f"{output} (+{provisional} if the regrade confirms)"
        # What a check saw quotes the submission (its stderr, the compiler): cleaned here,
        # before results.json, a terminal or a page shows it (grading/shown.py).
        self.score, self.output, self.seconds = score, clip(shown.clean(output)), seconds
        self.finished, self.regrade, self.ok = True, regrade, ok
        self.provisional = provisional if regrade else 0

    def as_dict(self) -> dict:
        return {"name": self.label, "score": self.score, "max_score": self.max_score,
                "status": "passed" if self.passed and not self.regrade else "failed",
                "output": self.output,
                "execution_time": round(self.seconds, 3), "visibility": self.visibility,
                "extra_data": {"check": self.id, "regrade": self.regrade,
                               "provisional": self.provisional}}


def clip(text: str, limit: int = MAX_OUTPUT_CHARS) -> str:
    if len(text) <= limit:
        return text
    return text[:limit] + f" ... [{len(text) - limit} characters cut]"


class Results:
    def __init__(self, path: pathlib.Path | None = None):
        self.path = path
        self.tests: list[Test] = []
        self.notes: list[str] = []
        self.refused = False
        self.start = time.perf_counter()
        self.sandbox = "none (--trusted)"  # which sandbox ran the submission (labkit/sandbox.py)
        self.for_staff: list[str] = []  # what course staff must look at (a foreign program)

    def add(self, test: Test) -> None:
        if not any(t.id == test.id for t in self.tests):
            self.tests.append(test)

    def add_all(self, tests) -> None:
        for t in tests:
            self.add(t)
        self.changed()

    def test(self, id: str) -> Test:
        return next(t for t in self.tests if t.id == id)

    def refuse(self, reason: str, detail: str = "", regrade: bool = False) -> None:
        """Nothing was graded (no sandbox, no binary, a compile error): every test scores 0
        and says why; `detail` (the compiler's errors) goes to the top-level output.
        `regrade`: the machine, not the submission, is at fault (a GPU lab where there is no
        GPU); every test is marked for regrade, with no points meanwhile: provisional full
        points would give them to an empty hand-in."""
        self.refused = True
        self.notes.append(clip(f"{reason}:\n{detail}" if detail else reason))
        for t in self.tests:
            if not t.finished:
                t.finish(0, f"not graded: {reason}", regrade=regrade)
        self.changed()

    def ran_foreign_code(self, what: str) -> None:
        """A run of the submission mapped code it did not build (labkit/sandbox.py, ExecCheck):
        a copy of a program it was given is no hand-in, whatever its images. Every test
        scores 0, finished or not, and the grade is marked for course staff."""
        reason = f"ran a program it did not build ({what}): scored 0 and marked for course staff"
        self.for_staff.append(reason)
        self.notes.append(reason)
        for t in self.tests:
            t.finish(0, f"not graded: {reason}")
        self.changed()

    def interrupt(self, reason: str) -> None:
        self.notes.append(reason)
        for t in self.tests:
            if not t.finished:
                t.finish(0, f"not graded: {reason}")
        self.changed()

    def complete(self, seconds: float) -> None:
        for t in self.tests:
            if t.visibility != "visible" and t.finished:
                self.notes.append(f"{t.label}: {'passed' if t.passed else 'failed'} (its details "
                                  f"are shown once the grades are published)")
        regrade = [t.label for t in self.tests if t.regrade]
        if regrade:
            score = sum(t.score for t in self.tests)
            most = sum(t.max_score for t in self.tests)
            extra = sum(t.provisional for t in self.tests)
            self.notes.append(f"{score}/{most}, +{extra} if the regrade confirms; marked for "
                              f"regrade (the machine could not measure them): "
                              + ", ".join(regrade))
        self.changed()

    def as_dict(self) -> dict:
        d = {"score": sum(t.score for t in self.tests),
             "max_score": sum(t.max_score for t in self.tests),
             "execution_time": round(time.perf_counter() - self.start, 3),
             "output": shown.clean("\n".join(self.notes)), "visibility": "visible",
             "sandbox": self.sandbox,
             **({"for_staff": shown.clean("\n".join(self.for_staff))} if self.for_staff else {}),
             "tests": [t.as_dict() for t in self.tests]}
        board = leaderboard(d)  # labs 02-07, once their speed was measured on a correct image
        if board:
            d["leaderboard"] = board
        return d

    def changed(self) -> None:
        if self.path:
            self.write()

    def write(self) -> None:
        """Atomically: a reader sees the old file or the new one, never half of one."""
        if not self.path:
            return
        folder = self.path.parent.resolve()
        folder.mkdir(parents=True, exist_ok=True)
        with tempfile.NamedTemporaryFile("w", dir=folder, delete=False, suffix=".partial") as f:
            json.dump(self.as_dict(), f, indent=2)
        os.replace(f.name, self.path)
