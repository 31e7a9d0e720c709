"""The class page of a batch (REPORT/report.html): one row per submission, named as the export
names its students, linking to that submission's own page, with the measured numbers, the
cause of a failure as the failing check's verdict, columns sorted by a click, the class's
score and speedup distributions drawn, and a note said of several submissions said once.

Every string on it a hand-in or an export controls passes grading/shown.py.
"""
from __future__ import annotations

import collections
import pathlib
import urllib.parse

from grading import report_html, shown
from grading.classes.verdicts import failure_cause, flagged, provisional_points, waiting
from grading.speed_numbers import speed_numbers

MOST_NOTE_LINES = 3  # of a row's own notes (a compile error's lines are in its cause and page)

SORT_SCRIPT = """<script>
// Sorts the rows by the clicked column: numbers (data-v) as numbers, highest first; text as
// text, A to Z; a second click reverses.
function sortBy(th) {
  const table = th.closest("table"), body = table.tBodies[0];
  const k = Array.from(th.parentNode.children).indexOf(th);
  const key = tr => { const c = tr.children[k]; const v = c.dataset.v;
    return v !== undefined && v !== "" ? parseFloat(v) : c.textContent.trim().toLowerCase(); };
  const numbers = Array.from(body.rows).some(r => typeof key(r) === "number");
  const first = numbers ? "down" : "up";
  const down = (th.dataset.dir ? (th.dataset.dir === "down" ? "up" : "down") : first) === "down";
  th.dataset.dir = down ? "down" : "up";
  const rows = Array.from(body.rows).sort((a, b) => {
    const x = key(a), y = key(b);
    const order = typeof x === "number" && typeof y === "number" ? x - y
      : String(x).localeCompare(String(y));
    return down ? -order : order; });
  rows.forEach(r => body.appendChild(r));
}
</script>"""


def histogram_svg(values: list[float], edges: list[float], title: str, unit: str) -> str:
    """An inline SVG bar chart of how many `values` fall in each bin of `edges` (the last bin
    takes everything above)."""
    counts = [0] * (len(edges) - 1)
    for v in values:
        k = next((i for i in range(len(counts)) if v < edges[i + 1]), len(counts) - 1)
        counts[max(k, 0)] += 1
    width, height, bar = 40 * len(counts) + 40, 160, 36
    top = max(counts, default=0) or 1
    parts = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height + 40}" '
             f'role="img" aria-label="{shown.html(title)}"><title>{shown.html(title)}</title>',
             f'<text x="4" y="14" font-size="12">{shown.html(title)} '
             f'({len(values)} measured)</text>']
    for i, n in enumerate(counts):
        h = round(n / top * (height - 40))
        x = 20 + 40 * i
        parts.append(f'<rect x="{x}" y="{height - h}" width="{bar}" height="{h}" '
                     f'fill="#69c"><title>{n}</title></rect>')
        if n:
            parts.append(f'<text x="{x + bar / 2}" y="{height - h - 3}" font-size="11" '
                         f'text-anchor="middle">{n}</text>')
        parts.append(f'<text x="{x + bar / 2}" y="{height + 14}" font-size="10" '
                     f'text-anchor="middle">{edges[i]:g}</text>')
    parts.append(f'<text x="{width / 2}" y="{height + 32}" font-size="11" '
                 f'text-anchor="middle">{shown.html(unit)}</text></svg>')
    return "".join(parts)


def plots(rows: dict[str, dict]) -> str:
    scores = [float(r.get("score", 0)) for r in rows.values()]
    most = max((float(r.get("max_score", 0) or 0) for r in rows.values()), default=100) or 100
    speedups = []
    for r in rows.values():
        try:
            speedups.append(float(speed_numbers(r)["speedup"]))
        except ValueError:
            pass
    step = most / 10
    score_plot = histogram_svg(scores, [step * i for i in range(11)], "scores",
                               f"points (of {most:g})")
    if not speedups:
        return f"<div class=plots>{score_plot}</div>"
    high = max(4.0, max(speedups))
    edges = [round(0.5 * i, 2) for i in range(int(high / 0.5) + 2)]
    return (f"<div class=plots>{score_plot}"
            f"{histogram_svg(speedups, edges, 'speedups', 'speedup over the serial reference')}"
            f"</div>")


def note_lines(results: dict) -> list[str]:
    return [line for line in results.get("output", "").splitlines() if line.strip()]


def student_page(report: pathlib.Path, student: str, lab: str, who: str, results: dict) -> str:
    """The link to a submission's own page, written where the grader wrote none (a compile
    error, a refused hand-in): every row links to one."""
    page = report / student / "heatmaps" / "report.html"
    if not page.exists():
        page.parent.mkdir(parents=True, exist_ok=True)
        report_html.write_report(page.parent, lab, who, results)
    return f"{urllib.parse.quote(student)}/heatmaps/report.html"


def write_html(path: pathlib.Path, lab: str, rows: dict[str, dict], labels: list[str],
               submitters: dict[str, str] | None = None) -> None:
    e = shown.html
    shared_count = collections.Counter(line for r in rows.values() for line in set(note_lines(r)))
    shared = [line for line, n in shared_count.items() if n > 1]
    head = "".join(f'<th onclick="sortBy(this)">{e(label)}</th>' for label in labels)
    named = submitters is not None
    body = []
    for student, r in rows.items():
        who = (submitters or {}).get(student) or student
        names = "; ".join(p.split(" <")[0] for p in who.split("; ")) if named else student
        href = student_page(path.parent, student, lab, who, r)
        flag = " (flagged)" if flagged(r) else ""
        cells = [f'<th><a href="{e(href)}">{e(names)}</a>{flag}</th>']
        if named:
            cells.append(f"<td>{e(student.removeprefix('submission_'))}</td>")
        cells.append(f'<td data-v="{r.get("score", 0)}">{r.get("score", 0)}</td>')
        provisional = provisional_points(r)
        cells.append(f'<td data-v="{provisional}">{provisional or ""}</td>')
        numbers = speed_numbers(r)
        for k in ("reference_s", "yours_s", "speedup", "capacity"):
            cells.append(f'<td data-v="{e(numbers[k])}">{e(numbers[k])}</td>')
        by_name = {t["name"]: t for t in r.get("tests", [])}
        for label in labels:
            t = by_name.get(label)
            if t is None:
                cells.append('<td data-v=""></td>')
                continue
            cls = ("regrade" if t.get("extra_data", {}).get("regrade")
                   else "waiting" if waiting(t) else t.get("status", "failed"))
            cells.append(f'<td class="{e(cls)}" data-v="{t["score"]}" '
                         f'title="{e(t.get("output", ""))}">{t["score"]}/{t["max_score"]}</td>')
        own = [line for line in note_lines(r) if line not in shared][:MOST_NOTE_LINES]
        cells.append(f'<td class="words">{e(failure_cause(r))}</td>'
                     f'<td class="words">{"<br>".join(map(e, own))}</td>')
        body.append(f"<tr>{''.join(cells)}</tr>")
    said = "".join(f"<li>{e(line)} <i>({shared_count[line]} submissions)</i></li>"
                   for line in shared)
    notes = f"<h2>Said of several submissions</h2><ul>{said}</ul>" if shared else ""
    columns = ["student" if not named else "students", *(["submission"] if named else []),
               "score", "provisional", "reference s", "seconds", "speedup", "capacity"]
    columns_html = "".join(f'<th onclick="sortBy(this)">{c}</th>' for c in columns)
    flagged_count = sum(flagged(r) for r in rows.values())
    path.write_text(f"""<!doctype html><meta charset="utf-8"><title>Lab {e(lab)} grades</title>
<style>body{{font-family:sans-serif}} td,th{{padding:2px 8px;border:1px solid #ccc}}
.passed{{background:#cfc}} .failed{{background:#fcc}} .regrade{{background:#ffc}}
.waiting{{background:#eee}} table{{border-collapse:collapse}} thead th{{cursor:pointer}}
td.words{{min-width:16em;max-width:28em;overflow-wrap:anywhere}}
.plots svg{{margin-right:2em}}</style>
{SORT_SCRIPT}
<h1>Lab {e(lab)}: {len(rows)} submissions, {flagged_count} flagged</h1>
{plots(rows)}
{notes}
<p>Click a column's title to sort by it; hover a cell for what the check saw; yellow: marked
for regrade (machine too busy); grey: points waiting for a gate that failed; each name links
to that submission's page.</p>
<table><thead><tr>{columns_html}{head}<th onclick="sortBy(this)">cause</th>
<th>notes</th></tr></thead>
<tbody>
{chr(10).join(body)}
</tbody></table>
""")
