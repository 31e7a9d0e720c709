"""What a grade draws from its secret: the seeds of the timed and tested renders and the
analytic scenes' parameters, so that no image the grader asks for can be rendered at home and
printed. The same secret draws the same values (a regrade with GRADING_SECRET sees the same
renders); without a grade in progress (the labs' own tests) the draws come from a fixed
course secret and stay the same from run to run."""
from __future__ import annotations

import contextlib
import hashlib

COURSE_SECRET = "parallel-ray-tracer-labs"
_secret = [COURSE_SECRET]


@contextlib.contextmanager
def secret(value: str):
    """Every draw inside the block comes from `value`."""
    _secret.append(value)
    try:
        yield
    finally:
        _secret.pop()


def _unit(label: str) -> int:
    digest = hashlib.sha256(f"{_secret[-1]}\0{label}".encode()).digest()
    return int.from_bytes(digest[:8], "little")


def uniform(label: str, low: float, high: float) -> float:
    """A number in [low, high) drawn for `label`."""
    return low + (high - low) * (_unit(label) / 2**64)


def seed(label: str) -> int:
    """A render seed for `label`, in 1..2^31-1 (any value the command line accepts)."""
    return 1 + _unit(label) % (2**31 - 2)
