"""Grade a whole class: one folder per student, graded one after the other, each in its own
grader process (a grader that dies on one submission does not take the class with it), all
with the same hidden scene; a CSV for the gradebook and an HTML page to read.

    python3 -m grading.batch 01 SUBMISSIONS --out REPORT
    make grade-batch LAB=01 SUBMISSIONS=DIR REPORT=DIR

SUBMISSIONS/<student>/ holds either a lab binary named `lab` or the student's sources
(render.cpp...). REPORT/<student>/results.json is each student's results.json;
REPORT/grades.csv and REPORT/report.html sum them up.
"""
from __future__ import annotations

import argparse
import csv
import html
import json
import os
import pathlib
import subprocess
import sys

from grading import hidden
from grading.grade import RUBRICS
from grading.harness import ROOT


def grade_one(lab: str, folder: pathlib.Path, out: pathlib.Path, extra: list[str],
              env: dict) -> dict:
    out.mkdir(parents=True, exist_ok=True)
    binary = folder / "lab"
    what = ["--binary", str(binary)] if binary.is_file() else ["--sources", str(folder)]
    results = out / "results.json"
    subprocess.run([sys.executable, "-m", "grading.grade", lab, *what, "--results", str(results),
                    "--heatmaps", str(out / "heatmaps"), *extra],
                   cwd=ROOT, env=env, stdout=(out / "grader.log").open("w"),
                   stderr=subprocess.STDOUT)
    try:
        return json.loads(results.read_text())
    except (OSError, ValueError) as e:  # the grader always writes one; say so if it did not
        return {"score": 0, "output": f"the grader left no results.json: {e}", "tests": []}


def write_csv(path: pathlib.Path, lab: str, rows: dict[str, dict]) -> None:
    labels = [i.label for i in RUBRICS[lab]]
    with path.open("w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["student", "score", "max_score", "regrade", *labels])
        for student, r in rows.items():
            by_name = {t["name"]: t for t in r.get("tests", [])}
            regrade = [t["name"] for t in r.get("tests", []) if t.get("extra_data", {}).get("regrade")]
            w.writerow([student, r.get("score", 0), r.get("max_score", ""), ";".join(regrade),
                        *(by_name.get(label, {}).get("score", "") for label in labels)])


def write_html(path: pathlib.Path, lab: str, rows: dict[str, dict]) -> None:
    labels = [i.label for i in RUBRICS[lab]]
    e = html.escape
    head = "".join(f"<th>{e(label)}</th>" for label in labels)
    body = []
    for student, r in rows.items():
        by_name = {t["name"]: t for t in r.get("tests", [])}
        cells = []
        for label in labels:
            t = by_name.get(label)
            if t is None:
                cells.append("<td></td>")
                continue
            cls = "regrade" if t.get("extra_data", {}).get("regrade") else t.get("status", "failed")
            cells.append(f'<td class="{cls}" title="{e(t.get("output", ""))}">'
                         f'{t["score"]}/{t["max_score"]}</td>')
        note = e(r.get("output", "").splitlines()[0]) if r.get("output") else ""
        # Each student's own page (images, heatmaps, what each check saw), where the grader
        # wrote one: grading/report_html.py.
        page = path.parent / student / "heatmaps" / "report.html"
        name = (f'<a href="{e(student)}/heatmaps/report.html">{e(student)}</a>' if page.exists()
                else e(student))
        body.append(f"<tr><th>{name}</th><td>{r.get('score', 0)}</td>{''.join(cells)}"
                    f"<td>{note}</td></tr>")
    path.write_text(f"""<!doctype html><meta charset="utf-8"><title>Lab {lab} grades</title>
<style>body{{font-family:sans-serif}} td,th{{padding:2px 8px;border:1px solid #ccc}}
.passed{{background:#cfc}} .failed{{background:#fcc}} .regrade{{background:#ffc}}
table{{border-collapse:collapse}}</style>
<h1>Lab {lab}: {len(rows)} submissions</h1>
<p>Hover a cell for what the check saw; yellow: marked for regrade (machine too busy).</p>
<table><tr><th>student</th><th>score</th>{head}<th>note</th></tr>
{chr(10).join(body)}</table>
""")


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("lab", choices=sorted(RUBRICS))
    p.add_argument("submissions", type=pathlib.Path)
    p.add_argument("--out", type=pathlib.Path, default=pathlib.Path("grades"))
    p.add_argument("--run-seconds", type=float)
    a = p.parse_args(argv)
    if not a.submissions.is_dir():
        print(f"error: {a.submissions}: not a folder of submissions", file=sys.stderr)
        return 2
    # One secret for the batch: every student gets the same hidden scene.
    env = {**os.environ, "GRADING_SECRET": hidden.secret_from_environment()}
    extra = ["--run-seconds", str(a.run_seconds)] if a.run_seconds else []
    rows = {}
    for folder in sorted(f for f in a.submissions.iterdir() if f.is_dir()):
        rows[folder.name] = grade_one(a.lab, folder, a.out / folder.name, extra, env)
        print(f"{folder.name}: {rows[folder.name].get('score', 0)}", flush=True)
    write_csv(a.out / "grades.csv", a.lab, rows)
    write_html(a.out / "report.html", a.lab, rows)
    print(f"wrote {a.out / 'grades.csv'} and {a.out / 'report.html'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
