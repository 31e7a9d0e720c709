"""What every check returns (CheckResult: passed or not, and a line saying what it saw) and
the decorator that turns a render without a usable image into a failed check."""
from __future__ import annotations

import dataclasses
import functools

from labkit.harness import ROOT, ImageError

# The trusted renderer that makes golden data on the spot (the timed scene drawn for a grade).
LAB01_REFERENCE = ROOT / "lab01-ref"


@dataclasses.dataclass
class CheckResult:
    name: str
    passed: bool
    detail: str
    # The machine could not measure this (too busy, even after retries): marked for a
    # regrade. Its points stay out of the score; `provisional` (a fraction of the points) is
    # what the regrade may add, shown apart.
    regrade: bool = False
    # A timed check's fraction of its points (speed_credit); None: all or nothing by `passed`.
    credit: float | None = None
    provisional: float = 0.0
    # What it rendered and what that should be, by scene, for the page the grade writes
    # (grading/report_html.py): a check judges and returns what it saw, it writes no report.
    images: dict = dataclasses.field(default_factory=dict)

    def __str__(self) -> str:
        return f"{'PASS' if self.passed else 'FAIL'} {self.name}: {self.detail}"


def worst_of(*values: float) -> float:
    """The largest of `values`, NaN if any is NaN: `max(0.0, nan)` is 0.0, which would read
    a NaN error as no error. Compare its result as `not (worst <= bound)`."""
    values = [float(v) for v in values]
    return float("nan") if any(v != v for v in values) else max(values)


def image_checked(name: str):
    """A check whose renders raise ImageError (no image, wrong size, NaN/Inf pixels) fails
    with that message instead of raising: a NaN makes every comparison false, so no check may
    look at such an image, and the mutation tests still get a CheckResult from each check."""
    def wrap(check):
        @functools.wraps(check)
        def checked(*args, **kwargs) -> CheckResult:
            try:
                return check(*args, **kwargs)
            except ImageError as e:
                return CheckResult(name, False, str(e))
        return checked
    return wrap
