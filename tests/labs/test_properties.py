"""Properties of the physics that hold for any scene, at every bounce and every coordinate,
tested on scenes drawn to break them rather than on the shipped ones:

- closed mirror and glass enclosures trap every path: with a background of 1 and no light, a
  camera inside sees exactly 0 at 8, 16 and 64 bounces (a specular direction that drifts off
  unit length, or an edge hit offset along one face only, lets paths out);
- a scene moved by a generic offset (not exact in float, up to 1e4 of its sizes), rotated
  about a generic axis and scaled by a generic factor renders as the unmoved one, or is
  refused with one line: centring and every load-time transform happen in double
  (common/host/scene_centring.h, host/scene.h's written coordinates);
- a light placed on a surface (in a floor's plane, at a quad's corner, on a sphere's pole)
  never puts NaN or Inf in an image;
- a scene is refused for the true reason at any scale.

Each runs on the float and the double build of lab 01's reference; lab 02's packet tracer
(its edge steps and renormalised reflections, common/simd/packet_tracer.h) must keep lab 01's
bits on them; lab 01 built with -ffast-math, and the GPU references (lab 05, its fast-math
build, labs 06 and 07) where a GPU is, run the enclosures and the lights.
"""
import json
import math
import subprocess

import numpy as np
import pytest
from cuda_env import missing_gpu

from labkit import scenes
from labkit.compare import compare
from labkit.harness import ROOT, build, cpu_has_avx2, golden, run_lab
from labkit.variants import build_sources, lab_sources


@pytest.fixture(scope="module", params=["lab01-ref", "lab01-ref-double"])
def renderer(request):
    """The lab-01 reference in float, then in double."""
    return build(request.param)[0]


# ---- scene transforms ---------------------------------------------------------------------

def rotation(axis, degrees):
    """The rotation matrix about `axis` (Rodrigues)."""
    a = np.asarray(axis, float) / np.linalg.norm(axis)
    t = math.radians(degrees)
    k = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return np.eye(3) + math.sin(t) * k + (1 - math.cos(t)) * (k @ k)


def box_quads(lo, hi, material):
    """The six faces of the box lo..hi as quads."""
    corner = lambda i, j, k: [(lo[0], hi[0])[i], (lo[1], hi[1])[j], (lo[2], hi[2])[k]]  # noqa: E731
    faces = [
        [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)],
        [(0, 0, 1), (0, 1, 1), (1, 1, 1), (1, 0, 1)],
        [(0, 0, 0), (0, 1, 0), (0, 1, 1), (0, 0, 1)],
        [(1, 0, 0), (1, 0, 1), (1, 1, 1), (1, 1, 0)],
        [(0, 0, 0), (0, 0, 1), (1, 0, 1), (1, 0, 0)],
        [(0, 1, 0), (1, 1, 0), (1, 1, 1), (0, 1, 1)],
    ]
    return [{"vertices": [corner(*c) for c in face], "material": material} for face in faces]


def outward(faces):
    """The same faces wound the other way: box_quads' fronts face into the box, these out of
    it, as a closed glass solid's must (DESIGN.md, section 5)."""
    return [{**f, "vertices": f["vertices"][::-1]} for f in faces]


def as_triangles(faces):
    """Each quad as its two triangles (v0 v1 v2), (v0 v2 v3): the same surface, whose edges
    the neighbouring quads then share with triangles."""
    return [{"vertices": [f["vertices"][a] for a in corners], "material": f["material"]}
            for f in faces for corners in ((0, 1, 2), (0, 2, 3))]


# ---- closed specular enclosures -------------------------------------------------------------

IOR = 1.5


def mirror_sphere():
    """A camera well off the centre of a closed mirror sphere, background 1, no light."""
    return {"camera": {"position": [0.41, -0.27, 0.19], "look_at": [0.9, 0.33, -1.7],
                       "up": [0, 1, 0], "vfov": 75},
            "background": [1, 1, 1],
            "materials": {"mirror": {"type": "mirror", "albedo": [1, 1, 1]}},
            "spheres": [{"center": [0.13, -0.07, 0.05], "radius": 1.37, "material": "mirror"}]}


def glass_sphere():
    """A camera inside a glass sphere, 0.8 radii from its centre, looking across it: every ray
    meets the surface beyond the critical angle, and the angle is the same at every bounce
    (a chord of a sphere), so total internal reflection keeps each path inside."""
    r = 1.0
    cam = [0.8 * r, 0.1 * r, 0.05 * r]
    return {"camera": {"position": cam, "look_at": [cam[0], cam[1], cam[2] - 1.0],
                       "up": [0, 1, 0], "vfov": 30},
            "background": [1, 1, 1],
            "materials": {"glass": {"type": "glass", "ior": IOR}},
            "spheres": [{"center": [0, 0, 0], "radius": r, "material": "glass"}]}


def beyond_critical_angle(scene, width, height, samples=6):
    """Per pixel of glass_sphere: whether every ray through the pixel (a grid of samples and
    the corners, with a margin) meets the sphere beyond the critical angle."""
    cam = scene["camera"]
    pos = np.array(cam["position"], float)
    forward = np.array(cam["look_at"], float) - pos
    forward /= np.linalg.norm(forward)
    right = np.cross(forward, cam["up"])
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    half_h = math.tan(math.radians(cam["vfov"]) / 2)
    half_w = half_h * width / height
    offs = np.linspace(0.0, 1.0, samples)
    xs = (np.arange(width)[:, None] + offs[None, :]).ravel()
    ys = (np.arange(height)[:, None] + offs[None, :]).ravel()
    gx, gy = np.meshgrid(xs, ys)
    d = (forward + right * (-half_w + 2 * half_w * gx / width)[..., None]
         + up * (half_h - 2 * half_h * gy / height)[..., None])
    d /= np.linalg.norm(d, axis=-1, keepdims=True)
    sphere = scene["spheres"][0]
    f = pos - np.array(sphere["center"], float)
    miss = np.linalg.norm(f + d * (-(d @ f))[..., None], axis=-1)  # centre-to-ray distance
    sin_incidence = miss / sphere["radius"]
    trapped = sin_incidence > 1.0 / IOR * 1.01
    return trapped.reshape(height, samples, width, samples).all(axis=(1, 3))


def mirror_room():
    """A closed mirror box rotated about a generic axis, holding a glass sphere and a glass
    tetrahedron (closed, so its edges are hit from inside and out): light can go nowhere."""
    room = {"camera": {"position": [0.1234, 0.2345, 0.3456], "look_at": [0.5, -0.3, -1],
                       "up": [0, 1, 0], "vfov": 80},
            "background": [1, 1, 1],
            "materials": {"mirror": {"type": "mirror", "albedo": [1, 1, 1]},
                          "glass": {"type": "glass", "ior": IOR}},
            "spheres": [{"center": [-0.45, -0.5, -0.4], "radius": 0.3, "material": "glass"}],
            "quads": box_quads([-1, -1, -1], [1, 1, 1], "mirror")}
    a, b, c, d = [0.2, -0.9, -0.6], [0.8, -0.9, -0.3], [0.5, -0.9, 0.2], [0.5, -0.2, -0.25]
    room["triangles"] = [{"vertices": t, "material": "glass"}
                         for t in ([a, c, b], [a, b, d], [b, c, d], [c, a, d])]
    return scenes.transformed(room, rotation([0.3, 1.0, 0.2], 23.7), offset=[0.37, -0.21, 0.11])


def mirror_box():
    """A closed axis-aligned mirror box of quads (six rectangles once loaded) holding a glass
    box of rectangles, wound outward: their edges and corners are the rectangles' own."""
    return {"camera": {"position": [0.1234, 0.2345, 0.3456], "look_at": [0.5, -0.3, -1],
                       "up": [0, 1, 0], "vfov": 80},
            "background": [1, 1, 1],
            "materials": {"mirror": {"type": "mirror", "albedo": [1, 1, 1]},
                          "glass": {"type": "glass", "ior": IOR}},
            "quads": box_quads([-1, -1, -1], [1, 1, 1], "mirror")
            + outward(box_quads([-0.7, -0.9, -0.8], [-0.1, -0.3, -0.2], "glass"))}


def mixed_room(rotated=True):
    """mirror_box with half of each box's faces as quads and half as two triangles, so that
    quads (or rectangles, unrotated) share edges with triangles; rotated about a generic axis
    (then every quad is a convex quad), or as written (then the loader makes the rectangles
    that meet triangles quads)."""
    room = mirror_box()
    walls, glass = room["quads"][:6], room["quads"][6:]
    room["quads"] = walls[0::2] + glass[1::2]
    room["triangles"] = as_triangles(walls[1::2] + glass[0::2])
    if not rotated:
        return room
    return scenes.transformed(room, rotation([0.3, 1.0, 0.2], 23.7), offset=[0.37, -0.21, 0.11])


def enclosure_image(binary, scene, tmp_path, bounces, width=48, height=48, spp=48):
    path = scenes.write_scene(tmp_path / "enclosure.json", scene)
    return run_lab(binary, path, width=width, height=height, spp=spp, bounces=bounces,
                   seed=11).image


def ceiling_inside_rising_walls(kind, ulps=260, size=24):
    """A closed mirror cell whose four walls rise past its ceiling to an open top, so that the
    ceiling's edges run across the walls' faces, as convex quads or as triangles, turned about
    a generic axis; background 1, no light. The camera looks from inside at a point of the
    ceiling's edge through a view of `ulps` units of rounding of a unit direction a pixel
    (float's narrowest, common/host/scene_limits.h), so many of its rays meet the joint
    within rounding."""
    lo, hi, top = -1.0, 1.0, 1.8

    def corner(i, j, k):
        return [(lo, hi)[i], (lo, hi)[j], (lo, hi)[k]]

    def wall(face):
        return [[x, top if y == hi else y, z] for x, y, z in face]

    faces = [[corner(0, 0, 0), corner(0, 0, 1), corner(1, 0, 1), corner(1, 0, 0)],  # floor
             [corner(0, 1, 0), corner(1, 1, 0), corner(1, 1, 1), corner(0, 1, 1)],  # ceiling
             wall([corner(0, 0, 0), corner(0, 1, 0), corner(0, 1, 1), corner(0, 0, 1)]),
             wall([corner(1, 0, 0), corner(1, 0, 1), corner(1, 1, 1), corner(1, 1, 0)]),
             wall([corner(0, 0, 1), corner(0, 1, 1), corner(1, 1, 1), corner(1, 0, 1)]),
             wall([corner(0, 0, 0), corner(1, 0, 0), corner(1, 1, 0), corner(0, 1, 0)])]
    faces = [{"vertices": f, "material": "mirror"} for f in faces]
    vfov = math.degrees(2 * math.atan(size / 2 * ulps * 2.0**-23))
    cell = {"camera": {"position": [0.1234, -0.2345, 0.3456], "look_at": [hi, hi, -0.3],
                       "up": [0, 1, 0], "vfov": vfov},
            "background": [1, 1, 1],
            "materials": {"mirror": {"type": "mirror", "albedo": [1, 1, 1]}}}
    if kind == "triangles":
        cell["triangles"] = as_triangles(faces)
    else:
        cell["quads"] = faces
    return scenes.transformed(cell, rotation([0.3, 1.0, 0.2], 23.7), offset=[0.37, -0.21, 0.11])


@pytest.mark.parametrize("kind", ["quads", "triangles"])
def test_a_ceiling_inside_rising_walls_traps_every_path(renderer, tmp_path, kind):
    """The loader cuts each wall along the ceiling's edge (common/host/t_junctions.h), and a
    mirror path that meets the cut steps off it to the side it came from (triangle.h's
    step_off_cut_edge). Before, paths aimed at the joint hit the wall just above the ceiling
    and left through the open top: 2 pixels of 576 saw the background in float, for quads and
    for triangles (none in double, whose rounding is far below a pixel of this view:
    tests/unit/test_t_junctions.cpp aims at the joint within double's rounding)."""
    image = enclosure_image(renderer, ceiling_inside_rising_walls(kind), tmp_path, 64,
                            width=24, height=24, spp=64)
    assert not image.any(), f"{int((image > 0).any(axis=2).sum())} pixels see the background"


@pytest.mark.parametrize("bounces", [8, 16, 64])
def test_mirror_sphere_traps_every_path(renderer, tmp_path, bounces):
    image = enclosure_image(renderer, mirror_sphere(), tmp_path, bounces)
    escaped = float((image > 0).any(axis=2).mean())
    assert not image.any(), f"{escaped:.2%} of the pixels see the background"


@pytest.mark.parametrize("bounces", [8, 16, 64])
def test_glass_sphere_beyond_the_critical_angle_traps_every_path(renderer, tmp_path, bounces):
    scene = glass_sphere()
    image = enclosure_image(renderer, scene, tmp_path, bounces)
    trapped = beyond_critical_angle(scene, image.shape[1], image.shape[0])
    assert trapped.mean() > 0.9, "the scene no longer tests total internal reflection"
    lit = image[trapped].any(axis=-1)
    assert not lit.any(), f"{lit.mean():.2%} of the pixels beyond the critical angle see light"


@pytest.mark.parametrize("bounces", [8, 16, 64])
def test_closed_mirror_room_with_glass_traps_every_path(renderer, tmp_path, bounces):
    image = enclosure_image(renderer, mirror_room(), tmp_path, bounces, spp=96)
    assert not image.any(), f"{int((image > 0).any(axis=2).sum())} pixels see the background"


ROOMS_OF_QUADS = {"mirror-box": mirror_box, "mixed-room": mixed_room,
                  "mixed-box": lambda: mixed_room(rotated=False)}


@pytest.mark.parametrize("bounces", [8, 64])
@pytest.mark.parametrize("name", ROOMS_OF_QUADS)
def test_closed_rooms_of_quads_trap_every_path(renderer, tmp_path, name, bounces):
    """Rectangles, convex quads and triangles meeting at edges and corners: no path leaves."""
    image = enclosure_image(renderer, ROOMS_OF_QUADS[name](), tmp_path, bounces, spp=96)
    assert not image.any(), f"{int((image > 0).any(axis=2).sum())} pixels see the background"


def test_rooms_of_quads_load_as_the_kinds_they_test(tmp_path):
    """The rooms above test what they say: rectangles only, quads with triangles, and
    rectangles made quads where they meet triangles."""
    lab01 = build("lab01-ref")[0]

    def uses(scene):
        path = scenes.write_scene(tmp_path / "room.json", scene)
        run = subprocess.run([str(lab01), "--scene", str(path), "--width", "2", "--height", "2",
                              "--spp", "1", "--json", "--quiet", "--out",
                              str(tmp_path / "o.ppm")], capture_output=True, text=True,
                             check=True)
        u = json.loads(run.stdout.strip().splitlines()[-1])["scene_uses"]
        return u["triangles"], u["quads"], u["rects"]

    assert uses(mirror_box()) == (0, 0, 12)
    assert uses(mixed_room()) == (12, 6, 0)
    triangles, quads, rects = uses(mixed_room(rotated=False))
    assert (triangles, quads + rects) == (12, 6) and quads == 6


ENCLOSURES = {"mirror-sphere": mirror_sphere, "glass-sphere": glass_sphere,
              "mirror-room": mirror_room, **ROOMS_OF_QUADS}


@pytest.mark.parametrize("name", ENCLOSURES)
def test_lab02_keeps_lab01s_bits_in_specular_enclosures(tmp_path, name):
    """Edge steps, renormalised reflections: the packet tracer mirrors the core lane by lane.
    A lit version of each enclosure (a light, a grey background), so the image is not 0."""
    if not cpu_has_avx2():
        pytest.skip("no AVX2 on this CPU")
    scene = ENCLOSURES[name]()
    scene["camera"]["vfov"] = 100  # wide, so that some rays reach the lit sphere inside
    scene["background"] = [0.5, 0.5, 0.5]
    scene["light"] = {"position": [0.05, 0.1, -0.2], "intensity": [1, 1, 1]}
    scene["materials"]["grey"] = {"type": "diffuse", "albedo": [0.5, 0.5, 0.5]}
    scene.setdefault("spheres", []).append(
        {"center": [-0.2, 0.3, -0.5], "radius": 0.15, "material": "grey"})
    path = scenes.write_scene(tmp_path / "lit.json", scene)
    settings = dict(width=24, height=24, spp=13, bounces=16, seed=5)
    lab01, lab02 = build("lab01-ref", "lab02-ref")
    want = run_lab(lab01, path, **settings).image
    assert want.any()
    assert (run_lab(lab02, path, **settings).image == want).all()


# ---- generic translations, rotations and scales ---------------------------------------------

def close_look_at_scene():
    """A lit floor seen from 1 above, its look_at only 1e-3 from the camera, the lamp 1e-2
    above the floor: the aim and the lamp's height are finer than float's spacing 1e4 away."""
    scene = scenes.floor_view(10.0)
    scene["camera"]["look_at"] = [0.0, 1.0 - 0.8e-3, -0.6e-3]
    scene["light"]["position"] = [0.3, 1e-2, -0.7]
    scene["light"]["intensity"] = [0.02] * 3
    return scene


def generic_offsets(size, count=3, seed=5):
    """Offsets of 20, 500 and 1e4 sizes along random directions, not exact in float."""
    rng = np.random.default_rng(seed)
    out = []
    for magnitude in np.geomspace(20, 1e4, count):
        d = rng.normal(size=3)
        out.append(list(d / np.linalg.norm(d) * magnitude * size * (1 + rng.uniform(0, 0.1))))
    return out


def same_image(moved, base):
    """The criterion of the scale check: same seed, so almost the same paths."""
    mean_err = abs(float(moved.mean()) / float(base.mean()) - 1.0)
    bad = float(((abs(moved - base) / (abs(base) + 1e-3 * base.mean())) > 0.05).mean())
    return (
        mean_err < 0.01 and bad < 0.02,
        f"mean off by {mean_err:.2%}, {bad:.2%} of values off by > 5%",
    )


def render_or_refusal(binary, scene, tmp_path, name, **settings):
    path = scenes.write_scene(tmp_path / name, scene)
    run = run_lab(binary, path, check=False, **settings)
    if run.returncode != 0:
        lines = run.stderr.strip().splitlines()
        assert run.returncode == 2 and len(lines) == 1 and lines[0].startswith("error:"), \
            (run.returncode, run.stderr)
        return None
    assert run.image is not None and np.isfinite(run.image).all()
    return run.image


def test_generic_translation_with_a_close_look_at(renderer, tmp_path):
    """Moved by generic offsets of up to 1e4 of its sizes (10), the close-look-at floor renders
    as it does unmoved, or is refused in one line."""
    settings = dict(width=32, height=32, spp=16, bounces=2, seed=3)
    base_scene = close_look_at_scene()
    base = render_or_refusal(renderer, base_scene, tmp_path, "base.json", **settings)
    assert base is not None and base.mean() > 0
    for i, offset in enumerate(generic_offsets(10.0)):
        moved = render_or_refusal(renderer, scenes.transformed(base_scene, offset=offset), tmp_path,
                                  f"moved-{i}.json", **settings)
        if moved is None:
            continue
        ok, how = same_image(moved, base)
        assert ok, f"moved by {np.linalg.norm(offset):.3g}: {how}"


RIGID_MOTIONS = {
    "rotated": dict(matrix=rotation([0.6, -0.3, 0.74], 37.3)),
    "rotated-moved-far": dict(matrix=rotation([-0.2, 0.9, 0.4], 151.7),
                              offset=[8123.4567, -4321.987, 2718.2818]),
    "scaled-small-moved": dict(scale=3.71e-3, offset=[-12.345678, 9.87654, 45.6789]),
    "scaled-large-rotated": dict(matrix=rotation([1, 1, 1], -71.1), scale=2.93e3,
                                 offset=[1.234e6, -3.21e5, 7.7e5]),
}


@pytest.mark.parametrize("motion", RIGID_MOTIONS)
def test_rotated_moved_scaled_cornell_is_the_golden_image(renderer, tmp_path, motion):
    """The Cornell box under a generic rotation, translation and scale is still the golden
    image's scene: the noise-aware comparison passes (or the loader refuses it in one line)."""
    g = golden("cornell")
    scene = scenes.transformed(scenes.load("cornell"), **RIGID_MOTIONS[motion])
    spp = 64
    image = render_or_refusal(renderer, scene, tmp_path, "moved.json", width=g.meta["width"],
                              height=g.meta["height"], spp=spp, bounces=g.meta["bounces"],
                              seed=7)
    if image is None:
        return
    report = compare(image, spp, g.mean, g.variance, g.meta["golden_spp"])
    assert report.passed, report.summary()


# ---- lights on surfaces: never NaN or Inf ---------------------------------------------------

def light_on_floor_plane():
    """A floor of half-size 1e4 with the light in its plane far from its centre, seen from just
    above: float hit points land on the light's position to the last bit."""
    h = 1e4
    light = [5000.0, 0.0, 5000.0]
    return {"camera": {"position": [5000.0, 0.1, 5000.0], "look_at": light, "up": [0, 0, -1],
                       "vfov": 2},
            "light": {"position": light, "intensity": [1, 1, 1]},
            "materials": {"w": {"type": "diffuse", "albedo": [0.5] * 3}},
            "quads": [{"vertices": [[-h, 0, -h], [-h, 0, h], [h, 0, h], [h, 0, -h]],
                       "material": "w"}]}


def light_at_a_corner():
    """The light at the shared corner of two quads (a floor and a wall), looked at closely."""
    return {"camera": {"position": [0.3, 0.2, 0.3], "look_at": [0, 0, 0], "up": [0, 1, 0],
                       "vfov": 3},
            "light": {"position": [0, 0, 0], "intensity": [1, 1, 1]},
            "materials": {"w": {"type": "diffuse", "albedo": [0.7] * 3}},
            "quads": [{"vertices": [[0, 0, 0], [0, 0, 1], [1, 0, 1], [1, 0, 0]], "material": "w"},
                      {"vertices": [[0, 0, 0], [0, 1, 0], [0, 1, 1], [0, 0, 1]], "material": "w"}]}


def light_on_a_pole():
    """The light on a sphere's pole, looked at from above and from the side."""
    r = 512.0
    return {"camera": {"position": [0.01, r + 0.05, 0.02], "look_at": [0, r, 0],
                       "up": [0, 0, -1], "vfov": 4},
            "light": {"position": [0, r, 0], "intensity": [1, 1, 1]},
            "materials": {"w": {"type": "diffuse", "albedo": [0.6] * 3}},
            "spheres": [{"center": [0, 0, 0], "radius": r, "material": "w"}]}


DEGENERATE_LIGHTS = {"floor-plane": light_on_floor_plane, "corner": light_at_a_corner,
                     "sphere-pole": light_on_a_pole}


def assert_finite_on_degenerate_lights(binary, tmp_path):
    for name, make in DEGENERATE_LIGHTS.items():
        path = scenes.write_scene(tmp_path / f"{name}.json", make())
        for bounces in (1, 3):
            run = run_lab(binary, path, width=32, height=32, spp=16, bounces=bounces, seed=2,
                          check=False)
            assert run.returncode == 0, run.stderr
            bad = int((~np.isfinite(run.image)).sum())
            assert bad == 0, f"{name}, {bounces} bounces: {bad} NaN or Inf values"


def test_a_light_on_a_surface_never_gives_nan_or_inf(renderer, tmp_path):
    assert_finite_on_degenerate_lights(renderer, tmp_path)


def test_a_light_on_a_surface_in_lab02(tmp_path):
    if not cpu_has_avx2():
        pytest.skip("no AVX2 on this CPU")
    assert_finite_on_degenerate_lights(build("lab02-ref")[0], tmp_path)


def test_cpu_fast_math_build_traps_every_path_and_never_gives_nan(tmp_path):
    """Lab 01's reference compiled with -ffast-math (make variant, as make tradeoff builds it),
    which lets the compiler assume no NaN: the guards still hold and the enclosures trap."""
    binary = build_sources("01-serial", ROOT / "build" / "properties" / "fast-math",
                           lab_sources("01-serial"),
                           make_args=("VARIANT_FLAGS_01-serial=-ffast-math",))
    assert_traps_and_finite(binary, tmp_path)


def assert_traps_and_finite(binary, tmp_path):
    for name, make in ENCLOSURES.items():
        scene = make()
        image = enclosure_image(binary, scene, tmp_path, 64)
        if name == "glass-sphere":
            image = image[beyond_critical_angle(scene, image.shape[1], image.shape[0])]
        assert not image.any(), f"{name}: {float((image > 0).mean()):.2%} of values lit"
    assert_finite_on_degenerate_lights(binary, tmp_path)


GPU_REFERENCES = ["lab05-ref", "lab05-ref-fast-math", "lab06-ref", "lab07-ref"]


@pytest.mark.parametrize("target", GPU_REFERENCES)
def test_gpu_references_trap_every_path_and_never_give_nan(tmp_path, target):
    """The GPU labs' kernels call the core's bounce step: the enclosures trap every path at 64
    bounces and the lights on surfaces give no NaN or Inf, --use_fast_math included (its
    guards are written so that NaN fails them)."""
    if reason := missing_gpu():
        pytest.skip(reason)
    assert_traps_and_finite(build(target)[0], tmp_path)


# ---- refusals give the true reason ------------------------------------------------------------

def refusal(binary, scene, tmp_path):
    path = scenes.write_scene(tmp_path / "scene.json", scene)
    p = subprocess.run([str(binary), "--quiet", "--scene", str(path), "--width", "4",
                        "--height", "4", "--spp", "1"], capture_output=True, text=True,
                       timeout=60)
    lines = p.stderr.strip().splitlines()
    return p.returncode, lines


@pytest.mark.parametrize("spheres", [True, False], ids=["with-sphere", "triangles-only"])
@pytest.mark.parametrize("factor", [1e-25, 1e-15, 1e15])
def test_a_scene_too_small_or_large_is_refused_for_its_size(lab01_ref, tmp_path, factor,
                                                            spheres):
    """The Cornell box scaled far beyond float's bounds: the students' float build refuses it
    for a size (as large as it is, not 0) or a coordinate, never as a camera looking at
    itself; the reference, within double's bounds, renders it in double."""
    scene = scenes.scaled(scenes.load("cornell"), factor)
    if not spheres:
        scene.pop("spheres")
    code, lines = refusal(build("lab01")[0], scene, tmp_path)
    assert code == 2 and len(lines) == 1, lines
    assert "camera position" not in lines[0] and ("1e-9" in lines[0] or "1e9" in lines[0]), lines
    assert " of 0 " not in lines[0], lines
    code, lines = refusal(lab01_ref, scene, tmp_path)
    assert code == 0 and not lines, lines


def test_a_look_at_very_close_to_the_camera_is_a_view(tmp_path):
    """A look_at 1e-23 from a camera at the origin is a direction (the file's numbers are
    distinct): the sphere interior renders its closed form."""
    scene = scenes.sphere_interior(albedo=0.6, radius=2.0, intensity=3.0)
    scene["camera"]["look_at"] = [0.0, 0.3e-23, -1e-23]
    path = scenes.write_scene(tmp_path / "close.json", scene)
    image = run_lab(build("lab01-ref")[0], path, width=8, height=8, spp=2, bounces=2).image
    want = scenes.sphere_interior_radiance(0.6, 2.0, 3.0, bounces=2)
    assert abs(image / want - 1).max() < 3e-4


def test_mixed_scales_beyond_float_are_refused_with_what_to_do(lab01_ref, tmp_path):
    """A sphere of radius 1e-4 on a floor of half-size 1e4: the students' float build refuses
    it in one line saying double places it; the reference renders it in double by itself
    (test_precision.py checks its image)."""
    h = 1e4
    scene = {"camera": {"position": [0, 5e-4, 1e-3], "look_at": [0, 1e-4, 0], "up": [0, 1, 0],
                        "vfov": 60},
             "light": {"position": [3e-4, 8e-4, 2e-4], "intensity": [1e-6] * 3},
             "materials": {"w": {"type": "diffuse", "albedo": [0.5] * 3}},
             "spheres": [{"center": [0, 1e-4, 0], "radius": 1e-4, "material": "w"}],
             "quads": [{"vertices": [[-h, 0, -h], [-h, 0, h], [h, 0, h], [h, 0, -h]],
                        "material": "w"}]}
    code, lines = refusal(build("lab01")[0], scene, tmp_path)
    assert code == 2 and len(lines) == 1 and "double places it" in lines[0], lines
    path = scenes.write_scene(tmp_path / "mixed.json", scene)
    run = run_lab(lab01_ref, path, width=8, height=8, spp=4)
    assert run.json["precision"] == "double" and run.image.mean() > 0
