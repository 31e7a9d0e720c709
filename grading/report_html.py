"""One submission's grade as a page an instructor (or a student at home) looks at: the score
table with what each check saw (the named symptoms included: grading/checks/symptoms.py), and for
each golden scene the submission's image, the golden image and, where the comparison failed,
the diff heatmap, side by side. Written next to the images, as `report.html` in the folder
the grader was given for heatmaps (`--heatmaps`; `make grade-batch` gives each student one).
"""
from __future__ import annotations

import pathlib

import numpy as np

from grading import shown
from labkit.heatmap import heatmap_scale, write_png


def display_rgb(image: np.ndarray) -> np.ndarray:
    """Linear radiance as 8-bit sRGB-ish display values (clamped, gamma 2.2, NaN black), upscaled
    to a visible size as the heatmaps are."""
    clean = np.nan_to_num(np.asarray(image, dtype=np.float64), nan=0.0, posinf=1.0, neginf=0.0)
    rgb = np.clip(clean, 0.0, 1.0) ** (1 / 2.2) * 255.0 + 0.5
    k = heatmap_scale(*rgb.shape[:2])
    return np.kron(rgb, np.ones((k, k, 1))).astype(np.uint8)


def write_images(folder: pathlib.Path, scene: str, yours: np.ndarray, golden: np.ndarray) -> None:
    """`<scene>-yours.png` and `<scene>-golden.png` in `folder`, for the page."""
    folder.mkdir(parents=True, exist_ok=True)
    write_png(folder / f"{scene}-yours.png", display_rgb(yours))
    write_png(folder / f"{scene}-golden.png", display_rgb(golden))


def write_report(folder: pathlib.Path, lab: str, who: str, results: dict) -> pathlib.Path:
    """`folder/report.html` from a grade's results.json content and the images in `folder`."""
    e = shown.html  # every string here may come from the submission
    rows = []
    for t in results.get("tests", []):
        state = "regrade" if t.get("extra_data", {}).get("regrade") else t.get("status", "failed")
        if t.get("output", "").startswith("not counted until"):
            state = "waiting"  # ran and shows what it saw; its points wait for a gate
        rows.append(f'<tr class="{state}"><td>{e(t["name"])}</td>'
                    f'<td>{t["score"]}/{t["max_score"]}</td><td>{e(t.get("output", ""))}</td></tr>')
    scenes = []
    for yours in sorted(folder.glob("*-yours.png")):
        scene = yours.name[: -len("-yours.png")]
        cells = [f'<figure><img src="{e(yours.name)}"><figcaption>yours</figcaption></figure>',
                 f'<figure><img src="{e(scene)}-golden.png">'
                 f'<figcaption>golden</figcaption></figure>']
        if (folder / f"{scene}-diff.png").exists():
            cells.append(f'<figure><img src="{e(scene)}-diff.png"><figcaption>where they differ '
                         f'(blue: within the noise, red: beyond it)</figcaption></figure>')
        scenes.append(f"<h2>{e(scene)}</h2><div>{''.join(cells)}</div>")
    note = e(results.get("output", "")).replace("\n", "<br>")
    page = folder / "report.html"
    page.write_text(f"""<!doctype html><meta charset="utf-8"><title>Lab {e(lab)}: {e(who)}</title>
<style>body{{font-family:sans-serif}} td{{padding:2px 8px;border:1px solid #ccc;vertical-align:top}}
table{{border-collapse:collapse}} .passed{{background:#cfc}} .failed{{background:#fcc}}
.regrade{{background:#ffc}} .waiting{{background:#eee}}
figure{{display:inline-block;margin:4px}} img{{image-rendering:pixelated}}</style>
<h1>Lab {e(lab)}: {e(who)}, {results.get("score", 0)}/{results.get("max_score", 0)}</h1>
<p>{note}</p>
<table><tr><th>check</th><th>points</th><th>what it saw</th></tr>
{chr(10).join(rows)}</table>
{chr(10).join(scenes)}
""")
    return page
