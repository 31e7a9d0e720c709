"""What a lab binary says about the scene it renders (common/host/scene_report.h): one line of
what the scene uses and the precision it renders in, and why (a detail too small for the
scene's reach is no warning: the reference renders it in double), the same in --json, and
nothing on stderr with --quiet."""
import copy
import json
import subprocess

from labkit.harness import ROOT, build

CORNELL = json.loads((ROOT / "common" / "scenes" / "cornell.json").read_text())


def render(scene: dict, tmp_path, *flags):
    path = tmp_path / "scene.json"
    path.write_text(json.dumps(scene))
    binary = build("lab01-ref")[0]
    return subprocess.run([str(binary), "--scene", str(path), "--width", "8", "--height", "8",
                           "--spp", "1", "--out", str(tmp_path / "out.ppm"), *flags],
                          capture_output=True, text=True, timeout=60)


def tiny_bead_in_a_huge_room():
    """The Cornell box 1e4 times larger, centred on the origin, with a bead of radius 1e-2
    floating at its centre: each primitive is fine on its own (the bead is large for its own
    distance from the origin, which the loader checks), but it is 1/5e5 of the room."""
    scene = copy.deepcopy(CORNELL)
    for quad in scene["quads"]:
        quad["vertices"] = [[x * 1e4 - 5e3, y * 1e4 - 5e3, z * 1e4 + 5e3]
                            for x, y, z in quad["vertices"]]
    scene["spheres"] = [{"center": [0, 0, 0], "radius": 0.01, "material": "ball"}]
    scene["camera"] = {"position": [0, 0, 15000], "look_at": [0, 0, 0], "up": [0, 1, 0],
                       "vfov": 55}
    scene["light"]["position"] = [4500, 4500, 2000]
    return scene


def test_the_scene_is_described(tmp_path):
    p = render(CORNELL, tmp_path)
    assert p.returncode == 0, p.stderr
    assert ("scene: 1 sphere, 5 rectangles; materials: 4 diffuse; a point light; "
            "a black background") in p.stderr
    assert "warning" not in p.stderr


def test_a_detail_too_small_for_the_room_is_rendered_in_double(tmp_path):
    p = render(tiny_bead_in_a_huge_room(), tmp_path)
    assert p.returncode == 0, p.stderr
    lines = p.stderr.splitlines()
    assert len(lines) == 1 and "in double: float cannot place /spheres/0/radius" in lines[0], \
        p.stderr
    assert (tmp_path / "out.ppm").exists()


def test_json_says_the_same_and_quiet_says_nothing(tmp_path):
    p = render(tiny_bead_in_a_huge_room(), tmp_path, "--json", "--quiet")
    assert p.returncode == 0 and p.stderr == "", p.stderr
    uses = json.loads(p.stdout)["scene_uses"]
    assert uses["spheres"] == 1 and uses["triangles"] == 0 and uses["lines_left_out"] == 0
    assert uses["quads"] == 0 and uses["rects"] == 5, uses
    assert uses["smallest"] == 0.01 and uses["extent"] >= 5000, uses
    assert json.loads(p.stdout)["precision"] == "double"
