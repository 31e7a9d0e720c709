"""`make bench` (tools/bench/report.py): the quick mode runs end to end and writes a sane
report; --merge adds made-up GPU rows; --gpu-only writes its rows with a stand-in GPU and
binary and without matplotlib; bad input is one line and exit 2; the report's numbers as
transcribed agree with the speedups the report prints.

CI cost, measured on a busy two-core VM: about 30 s (the quick run, with the CPU labs built).
"""
import csv
import json
import os
import pathlib
import re
import subprocess
import sys

import pytest

from labkit.harness import ROOT, available_cores
from tools.bench import report_data as data

SETTINGS = 7  # the baseline, and two more points of each of the three sweeps


def tool(*args, env=None, timeout=600):
    return subprocess.run([sys.executable, "-m", "tools.bench.report", *map(str, args)],
                          cwd=ROOT, capture_output=True, text=True, env=env, timeout=timeout)


@pytest.fixture(scope="module")
def quick(tmp_path_factory):
    out = tmp_path_factory.mktemp("bench")
    p = tool("--quick", "--out", out)
    assert p.returncode == 0, p.stdout[-2000:] + p.stderr[-2000:]
    return out


def cpu_model() -> str:
    out = subprocess.run(["lscpu"], capture_output=True, text=True).stdout
    return next(ln.split(":", 1)[1].strip() for ln in out.splitlines()
                if ln.startswith("Model name"))


def test_quick_run_writes_csv_markdown_and_plots(quick):
    rows = list(csv.DictReader(open(quick / "bench.csv")))
    binaries = {r["binary"] for r in rows}
    assert "lab01-ref" in binaries and len(binaries) >= 2, binaries
    for b in binaries:  # every implementation at every setting, each with a positive time
        assert len([r for r in rows if r["binary"] == b]) == SETTINGS, b
    assert all(float(r["seconds"]) > 0 for r in rows)
    assert all(float(r["speedup"]) == 1.0 for r in rows if r["binary"] == "lab01-ref")
    # The quick plan: sides / 5 and spp / 4 of the report's settings.
    assert {(r["side"], r["spp"], r["bounces"]) for r in rows if r["binary"] == "lab01-ref"} \
        == {("120", "128", "4"), ("30", "128", "4"), ("60", "128", "4"), ("120", "64", "4"),
            ("120", "256", "4"), ("120", "128", "2"), ("120", "128", "8")}
    md = (quick / "bench.md").read_text()
    assert cpu_model() in md                      # the machine is named
    if available_cores() > 1:                     # and how much of it this run got
        assert re.search(r"Capacity at the start of each round .*: \d+\.\d\d of ", md)
    for n in ("102.46", "6.64", "3.12", "189.46", "36.42"):  # the report's numbers appear
        assert n in md, n
    for t in (4, 5, 6, 7):
        assert f"## Table {t}:" in md
    for png in ("bench-baseline.png", "bench-size.png", "bench-spp.png", "bench-bounces.png"):
        blob = (quick / png).read_bytes()
        assert blob[:8] == b"\x89PNG\r\n\x1a\n" and len(blob) > 10_000, png
        assert f"]({png})" in md


def made_up_gpu_rows(report_dir: pathlib.Path, factor: float) -> dict:
    """--gpu-only's JSON for lab05-ref at the report's settings, `factor` x faster than its
    lab01-ref: the speedups the merged report must then show."""
    base = json.loads((report_dir / "bench.json").read_text())
    serial = [r for r in base["rows"] if r["binary"] == "lab01-ref"]
    return {"format": base["format"], "plan": base["plan"], "note": "",
            "machine": {"cpu": "Made-up CPU", "cores": 16, "date": "2026-12-02",
                        "gpu": "Made-up GPU X1, driver 1.2"},
            "skipped": {},
            "rows": [{"binary": "lab05-ref", "label": "CUDA megakernel", "gpu": True,
                      "side": r["side"], "spp": r["spp"], "bounces": r["bounces"],
                      "seconds": r["seconds"] / factor, "runs": [r["seconds"] / factor],
                      "device": "Made-up GPU X1"} for r in serial]}


def test_merge_adds_gpu_rows_with_speedups_over_this_reports_serial(quick, tmp_path):
    out = tmp_path / "report"
    out.mkdir()
    for f in quick.iterdir():
        (out / f.name).write_bytes(f.read_bytes())
    gpu = tmp_path / "gpu.json"
    gpu.write_text(json.dumps(made_up_gpu_rows(out, 10.0)))
    p = tool("--merge", gpu, "--out", out)
    assert p.returncode == 0, p.stderr
    rows = [r for r in csv.DictReader(open(out / "bench.csv")) if r["binary"] == "lab05-ref"]
    assert len(rows) == SETTINGS
    assert all(float(r["speedup"]) == pytest.approx(10.0, rel=1e-3) for r in rows)
    md = (out / "bench.md").read_text()
    assert "Made-up GPU X1, driver 1.2" in md and "| lab05-ref | " in md and "(10.00x)" in md
    # Merging again replaces the rows rather than adding a second set.
    gpu.write_text(json.dumps(made_up_gpu_rows(out, 20.0)))
    assert tool("--merge", gpu, "--out", out).returncode == 0
    rows = [r for r in csv.DictReader(open(out / "bench.csv")) if r["binary"] == "lab05-ref"]
    assert len(rows) == SETTINGS and float(rows[0]["speedup"]) == pytest.approx(20.0, rel=1e-3)
    # ... and its note: the machine line of the first merge no longer names these rows.
    merged = json.loads((out / "bench.json").read_text())["merged"]
    assert len(merged) == 1 and merged[0]["binaries"] == ["lab05-ref"], merged


def test_merge_refuses_rows_measured_at_other_settings(quick, tmp_path):
    rows = made_up_gpu_rows(quick, 10.0)
    rows["plan"]["size_div"] = 1  # the full plan's rows into a quick report
    gpu = tmp_path / "gpu.json"
    gpu.write_text(json.dumps(rows))
    p = tool("--merge", gpu, "--out", quick)
    assert p.returncode == 2 and "same --quick/--scale" in p.stderr, p.stderr


STAND_IN = r'''#!/usr/bin/env python3
# A stand-in GPU lab: parses the lab command line, writes a grey PFM, prints --json.
import json, struct, sys
a, args = {}, sys.argv[1:]
for i, x in enumerate(args):
    if x.startswith("--") and i + 1 < len(args) and not args[i + 1].startswith("--"):
        a[x] = args[i + 1]
w, h = int(a["--width"]), int(a["--height"])
with open(a["--pfm"], "wb") as f:
    f.write(f"PF\n{w} {h}\n-1.0\n".encode() + struct.pack("<f", 0.5) * (3 * w * h))
seconds = 1e-6 * w * h * int(a["--spp"]) * int(a["--bounces"])
print(json.dumps({"lab": "stand-in", "width": w, "height": h, "spp": int(a["--spp"]),
                  "bounces": int(a["--bounces"]), "seconds": seconds,
                  "device": "Stand-in GPU"}))
'''


def test_gpu_only_writes_rows_without_matplotlib(tmp_path):
    bins, shims = tmp_path / "bin", tmp_path / "shims"
    bins.mkdir()
    (shims / "matplotlib").mkdir(parents=True)
    # matplotlib that cannot be imported: --gpu-only must not need it.
    (shims / "matplotlib" / "__init__.py").write_text("raise ImportError('no matplotlib')\n")
    (bins / "lab05-ref").write_text(STAND_IN)
    (bins / "nvidia-smi").write_text("#!/bin/sh\necho 'Stand-in GPU, 999.9'\n")
    for f in bins.iterdir():
        f.chmod(0o755)
    env = {**os.environ, "PATH": f"{bins}:{os.environ['PATH']}",
           "PYTHONPATH": f"{shims}:{ROOT}"}
    out = tmp_path / "gpu.json"
    p = tool("--gpu-only", "--quick", "--bin-dir", bins, "--labs", "lab05-ref",
             "--json-out", out, env=env)
    assert p.returncode == 0, p.stdout + p.stderr
    got = json.loads(out.read_text())
    assert got["machine"]["gpu"] == "Stand-in GPU, driver 999.9"
    assert [r["binary"] for r in got["rows"]] == ["lab05-ref"] * SETTINGS
    for r in got["rows"]:  # the time the binary printed, at the setting it was given
        assert r["seconds"] == pytest.approx(1e-6 * r["side"] ** 2 * r["spp"] * r["bounces"],
                                             rel=1e-5)
        assert r["device"] == "Stand-in GPU"


@pytest.mark.parametrize("args, says", [
    (["--no-such-flag"], "unrecognized arguments"),
    (["--labs", "lab09-ref"], "unknown lab09-ref"),
    (["--quick", "--bin-dir", "{empty}", "--labs", "lab01-ref"], "no binary"),
    (["--merge", "{garbage}", "--out", "{tmp}"], "not JSON"),
    (["--merge", "{tmp}/missing.json", "--out", "{tmp}"], "cannot read"),
    (["--gpu-only"], "--json-out"),
])
def test_bad_input_is_one_line_and_exit_2(tmp_path, args, says):
    (tmp_path / "empty").mkdir()
    (tmp_path / "garbage.json").write_text("{not json")
    subs = {"{empty}": tmp_path / "empty", "{garbage}": tmp_path / "garbage.json",
            "{tmp}": tmp_path}
    args = [str(subs.get(a, a)).replace("{tmp}", str(tmp_path)) for a in args]
    p = tool(*args, timeout=120)
    assert p.returncode == 2, (p.returncode, p.stdout, p.stderr)
    lines = p.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("bench: error:") and says in lines[0], lines


def test_transcribed_numbers_agree_with_the_speedups_the_report_prints():
    """A misread time shows as a speedup that no longer matches: each printed speedup is the
    report's serial time over the row's time (Table 4: its row without SIMD; Tables 5-7: the
    'Serial' row at the same value). The report's own slips, kept as printed: Table 6's CUDA
    at 512 spp (30.25x for 95.00 / 3.12 = 30.45), and MPI at the baseline in Tables 5-7
    (6.55x, Table 4's 102.46 / 15.65, where their Serial row is 95.00 s: 6.07x)."""
    serial = {(e, v): s for e, row, _, v, s, _ in data.ROWS if row == "Serial"}
    slips = {("spp", "CUDA", 512), ("size", "MPI", 600), ("spp", "MPI", 512),
             ("bounces", "MPI", 4)}
    for e, row, _, v, seconds, speedup in data.ROWS:
        if (e, row, v) in slips:
            continue
        assert serial[(e, v)] / seconds == pytest.approx(speedup, abs=0.011 * speedup), \
            (e, row, v)
    assert len(data.ROWS) == 8 + 3 * 12
