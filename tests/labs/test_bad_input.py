"""Bad input ends with exit status 2 and one line naming the file, the place and what was
expected; no output file is created or damaged (DESIGN.md, "Command line")."""
import json
import signal
import subprocess
import time

import pytest

from labkit.harness import ROOT

GOOD = json.loads((ROOT / "common" / "scenes" / "cornell.json").read_text())


def run(binary, *args):
    return subprocess.run([str(binary), "--quiet", "--width", "8", "--height", "8", "--spp", "1",
                           *args], capture_output=True, text=True, timeout=60)


def assert_one_line_error(p, *fragments):
    assert p.returncode == 2, (p.returncode, p.stderr)
    lines = p.stderr.strip().splitlines()
    assert len(lines) == 1, p.stderr
    for f in fragments:
        assert f in lines[0], (f, lines[0])
    assert p.stdout == ""


def scene_with(tmp_path, text, name="bad.json"):
    path = tmp_path / name
    path.write_text(text)
    return path


SCENE_ERRORS = {
    # name: (scene text transformation, fragments the message must contain)
    "malformed json": (lambda s: s.replace('"camera": {', '"camera": {,', 1),
                       ["line 2, column", "invalid JSON"]),
    "unknown top-level key": (lambda s: s.replace('"background"', '"backgroud"', 1),
                              ["unknown key \"backgroud\"", "expected one of"]),
    "unknown material type": (lambda s: s.replace('"type": "diffuse"', '"type": "metal"', 1),
                              ["unknown material type \"metal\""]),
    "undefined material": (lambda s: s.replace('"material": "ball"', '"material": "gold"'),
                           ["/spheres/0/material", "unknown material \"gold\""]),
    "negative radius": (lambda s: s.replace('"radius": 0.2', '"radius": -0.2'),
                        ["/spheres/0/radius", "expected a radius > 0"]),
    "wrong type": (lambda s: s.replace('"vfov": 55', '"vfov": "wide"'),
                   ["/camera/vfov", "expected a number, found a string"]),
    "zero size in file": (lambda s: s.replace('"width": 600', '"width": 0'),
                          ["/render/width", "expected an integer in 1..16384"]),
    "absurd size in file": (lambda s: s.replace('"height": 600', '"height": 1000000'),
                            ["/render/height", "expected an integer in 1..16384"]),
}


@pytest.mark.parametrize("case", sorted(SCENE_ERRORS))
def test_bad_scene(lab01_ref, tmp_path, case):
    transform, fragments = SCENE_ERRORS[case]
    text = json.dumps(GOOD, indent=2)
    bad = transform(text)
    assert bad != text, "the test's edit did not apply"
    path = scene_with(tmp_path, bad)
    out = tmp_path / "out.ppm"
    p = run(lab01_ref, "--scene", str(path), "--out", str(out))
    assert_one_line_error(p, str(path), *fragments)
    assert "line " in p.stderr and "column " in p.stderr
    assert not out.exists()


def test_error_position_points_at_the_token(lab01_ref, tmp_path):
    text = json.dumps(GOOD, indent=2).replace('"radius": 0.2', '"radius": -0.2')
    line_no = next(i for i, ln in enumerate(text.splitlines(), 1) if '"radius"' in ln)
    column = text.splitlines()[line_no - 1].index("-0.2") + 1
    p = run(lab01_ref, "--scene", str(scene_with(tmp_path, text)))
    assert f"line {line_no}, column {column}" in p.stderr, p.stderr


def test_missing_scene_file(lab01_ref, tmp_path):
    missing = tmp_path / "nope.json"
    assert_one_line_error(run(lab01_ref, "--scene", str(missing)), str(missing), "cannot open")


@pytest.mark.parametrize("flags, fragment", [
    (["--width", "0"], "--width: expected an integer in 1..16384"),
    (["--height", "99999999"], "--height: expected an integer in 1..16384"),
    (["--spp", "-3"], "--spp: expected an integer"),
    (["--bounces", "many"], "--bounces: expected an integer"),
    (["--frobnicate"], "--frobnicate: unknown option"),
    (["--out"], "--out: expected a value"),
])
def test_bad_flags(lab01_ref, flags, fragment):
    assert_one_line_error(run(lab01_ref, *flags), fragment)


def test_unwritable_output_fails_before_rendering(lab01_ref, tmp_path):
    target = tmp_path / "no-such-dir" / "image.ppm"
    p = subprocess.run([str(lab01_ref), "--quiet", "--out", str(target)],  # full baseline size
                       capture_output=True, text=True, timeout=10)
    assert_one_line_error(p, str(target), "cannot write")


def test_existing_output_untouched_on_error(lab01_ref, tmp_path):
    out = tmp_path / "keep.ppm"
    out.write_bytes(b"precious")
    bad = scene_with(tmp_path, "{ not json")
    p = run(lab01_ref, "--scene", str(bad), "--out", str(out))
    assert p.returncode == 2
    assert out.read_bytes() == b"precious"
    assert sorted(x.name for x in tmp_path.iterdir()) == ["bad.json", "keep.ppm"]


def test_output_replaced_whole(lab01_ref, tmp_path):
    out = tmp_path / "img.pfm"
    out.write_bytes(b"old")
    p = run(lab01_ref, "--pfm", str(out))
    assert p.returncode == 0
    assert out.read_bytes().startswith(b"PF\n8 8\n")
    assert sorted(x.name for x in tmp_path.iterdir()) == ["img.pfm"]


def start_long_render(lab01_ref, outputs: list[str], signal_number, action):
    """A render of minutes writing `outputs`, started with `action` for `signal_number`."""
    return subprocess.Popen([str(lab01_ref), "--quiet", "--width", "400", "--height", "400",
                             "--spp", "4096", *outputs],
                            preexec_fn=lambda: signal.signal(signal_number, action))


def wait_for_temporaries(p, folder, count: int) -> None:
    """Until `count` '*.partial-*' temporaries are open in `folder` (30 s at most)."""
    deadline = time.monotonic() + 30
    while len(list(folder.glob("*.partial-*"))) < count:
        assert p.poll() is None and time.monotonic() < deadline, "no temporaries appeared"
        time.sleep(0.01)


@pytest.mark.parametrize("signal_number", [signal.SIGINT, signal.SIGTERM])
def test_interrupted_render_leaves_nothing(lab01_ref, tmp_path, signal_number):
    """Ctrl-C (or a grader's kill) during a long render: the process dies of that signal and
    no '*.partial-*' temporary of --out/--pfm is left; an existing output stays as it was.
    The render starts with the signal's default action, as from a terminal: a program keeps
    a signal ignored that it was started ignoring (a shell does that to commands it starts in
    the background), and so does this one, which would then render to the end."""
    (tmp_path / "old.ppm").write_bytes(b"keep me")
    p = start_long_render(lab01_ref, ["--out", str(tmp_path / "old.ppm"),
                                      "--pfm", str(tmp_path / "new.pfm")],
                          signal_number, signal.SIG_DFL)
    try:
        wait_for_temporaries(p, tmp_path, 2)  # both opened: rendering has begun
        p.send_signal(signal_number)
        assert p.wait(timeout=30) == -signal_number
    finally:
        p.kill()
        p.wait()
    assert sorted(f.name for f in tmp_path.iterdir()) == ["old.ppm"]
    assert (tmp_path / "old.ppm").read_bytes() == b"keep me"


def test_a_render_started_ignoring_ctrl_c_keeps_ignoring_it(lab01_ref, tmp_path):
    """nohup and a shell's background jobs start a program with SIGINT ignored, so that Ctrl-C
    at the terminal leaves it running: the renderer keeps it so, and still removes its
    temporaries when it is killed with SIGTERM."""
    p = start_long_render(lab01_ref, ["--out", str(tmp_path / "out.ppm")],
                          signal.SIGINT, signal.SIG_IGN)
    try:
        wait_for_temporaries(p, tmp_path, 1)  # rendering has begun
        p.send_signal(signal.SIGINT)
        time.sleep(0.5)
        assert p.poll() is None, "an ignored SIGINT ended the render"
        p.send_signal(signal.SIGTERM)
        assert p.wait(timeout=30) == -signal.SIGTERM
    finally:
        p.kill()
        p.wait()
    assert list(tmp_path.iterdir()) == []
