"""The numbers of a grade's speed check, read back from its results.json: the grader's
times, the speedup and the capacity. grades.csv (grading/classes/batch.py) and Gradescope's
leaderboard (grading/results.py) show them."""
from __future__ import annotations

import re

SPEED_CHECKS = ("parallel-speedup", "speedup", "speed")
# What the speed checks print (grading/checks/speed.py): "... 1.85x over the serial reference
# (0.600 s -> 0.324 s) on 2 cores giving 1.98x capacity ..." and "1.62x (0.412 s -> 0.254 s
# wall clock ...)". Structured numbers in a test's extra_data, where the grader gives them,
# come first.
SPEED = re.compile(r"(?P<speedup>\d+(?:\.\d+)?)x (?:over the serial reference )?"
                   r"\((?P<reference>\d+(?:\.\d+)?) s -> (?P<yours>\d+(?:\.\d+)?) s")
CAPACITY = re.compile(r"giving (?P<capacity>\d+(?:\.\d+)?)x capacity|"
                      r"gave only (?P<busy>\d+(?:\.\d+)?) cores|"
                      r"machine giving (?P<serial>\d+(?:\.\d+)?)")  # a serial verdict's


def speed_numbers(results: dict) -> dict[str, str]:
    """Times, speedup and capacity of the speed check, as strings ("" where not measured)."""
    found = dict(reference_s="", yours_s="", speedup="", capacity="")
    for t in results.get("tests", []):
        if t.get("extra_data", {}).get("check") not in SPEED_CHECKS:
            continue
        extra = t.get("extra_data", {})
        m = SPEED.search(t.get("output", ""))
        if m:
            found.update(reference_s=m["reference"], yours_s=m["yours"], speedup=m["speedup"])
        c = CAPACITY.search(t.get("output", ""))
        if c:
            found["capacity"] = c["capacity"] or c["busy"] or c["serial"]
        for key, name in (
            ("reference_seconds", "reference_s"),
            ("seconds_reference", "reference_s"),
            ("yours_seconds", "yours_s"),
            ("seconds_yours", "yours_s"),
            ("speedup", "speedup"),
            ("capacity", "capacity"),
        ):
            if isinstance(extra.get(key), (int, float)):
                found[name] = f"{extra[key]:.3f}"
    return found


def leaderboard(results: dict) -> list[dict]:
    """Gradescope's leaderboard entries for a grade whose speed check measured a correct
    image (points above 0): the speedup (higher first) and the time (lower first). Empty
    otherwise, so a wrong or unmeasured program never ranks."""
    for t in results.get("tests", []):
        if (t.get("extra_data", {}).get("check") in SPEED_CHECKS and t.get("score", 0) > 0
                and not t.get("extra_data", {}).get("regrade")):
            numbers = speed_numbers({"tests": [t]})
            if numbers["speedup"] and numbers["yours_s"]:
                return [{"name": "speedup", "value": float(numbers["speedup"]), "order": "desc"},
                        {"name": "time (s)", "value": float(numbers["yours_s"]), "order": "asc"}]
    return []
