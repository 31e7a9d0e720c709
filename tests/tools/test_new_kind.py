"""A kind is declared once: a disk primitive and a rough metal, written as a course would write
them (tests/tools/new_kind/*.diff), each touch a handful of files and work in every CPU lab.

Both diffs are applied with `git apply` to one scratch copy of the repository (test_new_lab's);
then, in the copy:
- each diff touches at most its number of files, tests included (disk 4, rough metal 3), none
  under labkit/ and not DESIGN.md, and `git status` shows those files and nothing else but
  DESIGN.md, whose table of scene-file lists and types is regenerated from the built
  renderer's `--scene-schema` (python3 -m labkit.scene_schema --write) and now lists both;
- labkit/scenes.py, unchanged, moves, turns and scales a disk by its declared fields;
- the CPU references and the unit tests build (the diffs' own unit tests run there), and the
  references render the Cornell box and the showcase to the bits this checkout's render;
- a disk renders right in labs 01, 02 and 03: a lit disk seen from above, one bounce, against
  its closed form pixel by pixel;
- a rough metal renders right in labs 01, 02 and 03: a rough metal floor under a uniform sky,
  two bounces, against its closed form (the albedo times the sky times the share of blurred
  directions that stay above the floor), row by row;
- the labs render the hidden scene, which now holds both, to the same bits;
- the core's headers compile for the GPU (`make check-nvcc`) where there is nvcc.
The diffs are not part of the kit itself."""
import json
import math
import os
import pathlib
import shutil

import numpy as np
import pytest

from labkit import scene_schema
from labkit.harness import ROOT
from labkit.pfm import read_pfm
from labkit.scenes import camera_rays
from tests.tools.test_new_lab import run, scratch_copy

EXAMPLES = pathlib.Path(__file__).parent / "new_kind"
MOST_FILES = {"disk.diff": 4, "rough_metal.diff": 3}
# What a kind never edits by hand: Python reads its schema from the renderer, and DESIGN.md's
# table of it is generated.
NEVER_TOUCHED = ("labkit/", "DESIGN.md")
LABS = ("lab01-ref", "lab02-ref", "lab03-ref")


def touched(diff: pathlib.Path) -> set[str]:
    """The files a unified diff changes or adds."""
    return {line[len("+++ b/"):].strip() for line in diff.read_text().splitlines()
            if line.startswith("+++ b/")}


@pytest.fixture(scope="module")
def copy(tmp_path_factory):
    """The scratch copy with both examples applied, the CPU references built and DESIGN.md's
    generated table rewritten."""
    root = scratch_copy(tmp_path_factory.mktemp("new_kind"))
    for diff in sorted(EXAMPLES.glob("*.diff")):
        run(root, "git", "apply", "--whitespace=error-all", str(diff))
    run(root, "make", f"-j{os.cpu_count() or 1}", *LABS, "build/unit_tests", "CI=true",
        timeout=1800)
    run(root, "python3", "-m", "labkit.scene_schema", "--write")
    return root


def render(root: pathlib.Path, lab: str, scene: pathlib.Path, out: pathlib.Path, **flags):
    args = [f"./{lab}", "--scene", str(scene), "--quiet", "--pfm", str(out)]
    for key, value in flags.items():
        args += [f"--{key}", str(value)]
    run(root, *args)
    return read_pfm(out).astype(np.float64).mean(axis=2)


def per_pixel(values: np.ndarray, width: int, height: int, subsamples: int) -> np.ndarray:
    return values.reshape(height, subsamples, width, subsamples).mean(axis=(1, 3))


def test_each_example_touches_few_files_and_nothing_else_changes(copy):
    changed = set()
    for name, most in MOST_FILES.items():
        files = touched(EXAMPLES / name)
        assert 0 < len(files) <= most, f"{name} touches {len(files)} files: {sorted(files)}"
        assert not [f for f in files if f.startswith(NEVER_TOUCHED)], sorted(files)
        changed |= files
    status = run(copy, "git", "status", "--porcelain", "--untracked-files=all").stdout
    # What the build writes is ignored; what the examples wrote, and the regenerated table, is
    # all that git sees.
    assert {line[3:] for line in status.splitlines()} == changed | {"DESIGN.md"}, status


def test_design_lists_both_kinds_and_changes_only_in_its_generated_table(copy):
    run(copy, "python3", "-m", "labkit.scene_schema", "--check")
    text = (copy / "DESIGN.md").read_text()
    table = scene_schema.current(text)
    assert "| `disks` | `center`: a point [x, y, z]; `normal`: a direction" in table
    assert "| `rough_metal` | `albedo`: RGB, each in [0, 1]; `roughness`: a roughness in [0, 1] |" \
        in table
    here = (ROOT / "DESIGN.md").read_text()
    assert text.replace(table, "") == here.replace(scene_schema.current(here), "")


def test_scenes_move_a_disk_by_its_declared_fields(copy):
    """The copy's labkit/scenes.py, untouched, reads the disk's fields from the copy's
    renderer: a quarter turn about z turns its normal, a scale of 2 doubles its radius."""
    made = run(copy, "python3", "-c", "import json, numpy as np; from labkit import scenes; "
               f"s = json.loads({json.dumps(DISK)!r}); "
               "m = np.array([[0.0, -1, 0], [1, 0, 0], [0, 0, 1]]); "
               "print(json.dumps(scenes.transformed(s, m, offset=(0, 0, 1), scale=2.0)))")
    disk = json.loads(made.stdout)["disks"][0]
    assert np.allclose(disk["center"], [0, 0, 1]) and np.allclose(disk["normal"], [-1, 0, 0])
    assert disk["radius"] == 2 * DISK["disks"][0]["radius"]


def test_the_examples_unit_tests_pass(copy):
    out = run(copy, "./build/unit_tests", "--gtest_filter=Disk*:RoughMetal*").stdout
    assert "[  PASSED  ] 4 tests." in out, out


@pytest.mark.parametrize("scene", ["cornell", "showcase"])
def test_the_labs_render_the_shipped_scenes_to_the_same_bits(copy, scene, tmp_path):
    path = ROOT / "common" / "scenes" / f"{scene}.json"
    for lab in LABS:
        mine = render(copy, lab, path, tmp_path / "copy.pfm", width=48, height=40, spp=8)
        theirs = render(ROOT, lab, path, tmp_path / "here.pfm", width=48, height=40, spp=8)
        assert np.array_equal(mine, theirs), f"{lab} renders {scene} otherwise with the kinds"


DISK = {"camera": {"position": [0, 2, 0], "look_at": [0, 0, 0], "up": [0, 0, -1], "vfov": 60},
        "light": {"position": [0.3, 1.5, -0.2], "intensity": [2, 2, 2]},
        "materials": {"m": {"type": "diffuse", "albedo": [0.6, 0.6, 0.6]}},
        "disks": [{"center": [0, 0, 0], "normal": [0, 1, 0], "radius": 0.8, "material": "m"}]}


def test_a_disk_renders_its_closed_form(copy, tmp_path):
    """Direct light on a diffuse disk, albedo/pi * I * cos / d^2 where a camera ray meets it
    (a midpoint rule over 8 x 8 points of each pixel), nothing elsewhere."""
    size, sub = 32, 8
    d = camera_rays(DISK["camera"], size, size, sub)
    pos = np.array(DISK["camera"]["position"], float)
    t = -pos[1] / d[..., 1]
    p = pos + t[..., None] * d
    inside = np.hypot(p[..., 0], p[..., 2]) <= DISK["disks"][0]["radius"]
    to_light = np.array(DISK["light"]["position"], float) - p
    d2 = (to_light**2).sum(-1)
    radiance = np.where(inside, 0.6 / math.pi * 2 * (to_light[..., 1] / np.sqrt(d2)) / d2, 0.0)
    want = per_pixel(radiance, size, size, sub)
    whole = per_pixel(inside.astype(float), size, size, sub) == 1.0
    assert 0.3 < whole.mean() < 0.7  # the disk and its rim are both in view
    scene = tmp_path / "disk.json"
    scene.write_text(json.dumps(DISK))
    for lab in LABS:
        got = render(copy, lab, scene, tmp_path / "disk.pfm", width=size, height=size, spp=256,
                     bounces=1)
        err = np.abs(got[whole] / want[whole] - 1)
        assert err.mean() <= 3e-3 and err.max() <= 2e-2, f"{lab}: mean {err.mean():.2e}"
        # The rim: the disk's radius, through the light it gathers in all.
        assert abs(got.sum() / want.sum() - 1) <= 1e-2, f"{lab}: {got.sum()} vs {want.sum()}"


ALBEDO, SKY, ROUGHNESS = 0.8, 0.5, 0.8
METAL = {"camera": {"position": [0, 1, 0], "look_at": [0, 0, -1.5], "up": [0, 1, 0], "vfov": 40},
         "background": [SKY] * 3,
         "materials": {"m": {"type": "rough_metal", "albedo": [ALBEDO] * 3,
                             "roughness": ROUGHNESS}},
         "quads": [{"vertices": [[-1e3, 0, -1e3], [-1e3, 0, 1e3], [1e3, 0, 1e3], [1e3, 0, -1e3]],
                    "material": "m"}]}


def test_a_rough_metal_renders_its_closed_form(copy, tmp_path):
    """A camera ray reflects off the floor at elevation cos a = -d.y; the blurred direction
    R + roughness * u (u uniform on the sphere) stays above the floor when u.y > -cos a /
    roughness, with probability (1 + cos a / roughness) / 2 (u.y is uniform on [-1, 1]), and
    then sees the sky: the pixel's radiance is albedo * sky * that probability."""
    width, height, sub, spp = 48, 32, 8, 256
    d = camera_rays(METAL["camera"], width, height, sub)
    assert (d[..., 1] < 0).all()  # every ray meets the floor
    stays = np.clip((1 - d[..., 1] / ROUGHNESS) / 2, 0, 1)
    want = per_pixel(ALBEDO * SKY * stays, width, height, sub)
    assert want.min() < 0.85 * ALBEDO * SKY  # the blur shows: a mirror would give 1 everywhere
    scene = tmp_path / "metal.json"
    scene.write_text(json.dumps(METAL))
    for lab in LABS:
        got = render(copy, lab, scene, tmp_path / "metal.pfm", width=width, height=height,
                     spp=spp, bounces=2)
        # Each sample is the sky or nothing: a row's mean has a standard error below
        # albedo * sky * 0.5 / sqrt(width * spp), ~0.005 of albedo * sky.
        rows = np.abs(got.mean(axis=1) - want.mean(axis=1)) / (ALBEDO * SKY)
        assert rows.max() <= 0.025, f"{lab}: rows off by up to {rows.max():.3f}"


def test_the_labs_render_the_hidden_scene_with_both_kinds_alike(copy, tmp_path):
    made = run(copy, "python3", "-c", "import json; from grading.checks import hidden; "
               "print(json.dumps(hidden.hidden_scene('0123456789abcdef0123456789abcdef')))")
    scene = json.loads(made.stdout)
    assert scene["disks"] and any(m["type"] == "rough_metal" for m in scene["materials"].values())
    path = tmp_path / "hidden.json"
    path.write_text(made.stdout)
    images = [render(copy, lab, path, tmp_path / "h.pfm", width=40, height=40, spp=8)
              for lab in LABS]
    assert all(np.array_equal(images[0], image) for image in images[1:])


@pytest.mark.skipif(shutil.which("nvcc") is None, reason="no CUDA toolkit (nvcc)")
def test_the_core_compiles_for_the_gpu_with_both_kinds(copy):
    run(copy, "make", "check-nvcc", "CI=true", timeout=1800)
