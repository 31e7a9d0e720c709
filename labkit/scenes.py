"""Scenes made in code for checks whose answer is known in closed form, and scene scaling."""
from __future__ import annotations

import json
import math
import pathlib

import numpy as np

from labkit import scene_schema
from labkit.harness import SCENES


def write_scene(path: pathlib.Path, scene: dict) -> pathlib.Path:
    path.write_text(json.dumps(scene, indent=1))
    return path


def sphere_interior(albedo: float, radius: float, intensity: float) -> dict:
    """Camera and point light at the centre of a diffuse sphere, seen from inside.

    Every wall point is at distance R with the light along its normal, so next-event
    estimation gives L1 = albedo/pi * I / R^2 there with zero variance, and the wall, being
    uniformly bright, sends each point an irradiance of pi * L. Hence the radiance after B
    interactions is exactly L1 * (1 + albedo + ... + albedo^(B-1)), at every pixel.
    """
    return {
        "camera": {"position": [0, 0, 0], "look_at": [0, 0, -1], "up": [0, 1, 0], "vfov": 60},
        "light": {"position": [0, 0, 0], "intensity": [intensity] * 3},
        "materials": {"wall": {"type": "diffuse", "albedo": [albedo] * 3}},
        "spheres": [{"center": [0, 0, 0], "radius": radius, "material": "wall"}],
    }


def sphere_interior_radiance(albedo: float, radius: float, intensity: float, bounces: int) -> float:
    direct = albedo / math.pi * intensity / radius**2
    return direct * sum(albedo**k for k in range(bounces))


def lit_plane(albedo: float, height: float, intensity: float, vfov: float) -> dict:
    """A camera above a large diffuse floor, looking straight down, light beside the camera.

    With one bounce the radiance at floor point p is albedo/pi * I * cos(theta) / d^2: smooth,
    known everywhere, so each pixel's expected value is an integral over the pixel.
    """
    half = 1000.0
    return {
        "camera": {"position": [0, height, 0], "look_at": [0, 0, 0], "up": [0, 0, -1],
                   "vfov": vfov},
        "light": {"position": [0.3 * height, height, 0.1 * height], "intensity": [intensity] * 3},
        "materials": {"floor": {"type": "diffuse", "albedo": [albedo] * 3}},
        "quads": [{"vertices": [[-half, 0, -half], [-half, 0, half], [half, 0, half],
                                [half, 0, -half]], "material": "floor"}],
    }


def lit_plane_expected(scene: dict, width: int, height: int, subsamples: int = 8):
    """Per-pixel expected radiance of lit_plane (one bounce), by a midpoint rule over
    subsamples^2 points of each pixel: the integrand is smooth, so this is accurate to ~1e-5."""
    import numpy as np
    cam = scene["camera"]
    h = cam["position"][1]
    light = np.array(scene["light"]["position"])
    intensity = scene["light"]["intensity"][0]
    albedo = scene["materials"]["floor"]["albedo"][0]
    half_h = math.tan(math.radians(cam["vfov"]) / 2)
    half_w = half_h * width / height
    # Camera frame looking down -y with up = -z: right = forward x up = (-y) x (-z) = +x.
    offs = (np.arange(subsamples) + 0.5) / subsamples
    xs = (np.arange(width)[:, None] + offs[None, :]).ravel()   # pixel-space x samples
    ys = (np.arange(height)[:, None] + offs[None, :]).ravel()
    u = -half_w + 2 * half_w * xs / width                       # along +x
    v = half_h - 2 * half_h * ys / height                       # along up = -z
    px = u[None, :] * h                                          # floor hit: t*(dir) with dir.y=-1
    pz = -v[:, None] * h
    px, pz = np.broadcast_arrays(px, pz)
    to_light = np.stack([light[0] - px, np.full_like(px, light[1]), light[2] - pz], axis=-1)
    d2 = (to_light**2).sum(-1)
    cos = to_light[..., 1] / np.sqrt(d2)
    radiance = albedo / math.pi * intensity * cos / d2
    per_pixel = radiance.reshape(height, subsamples, width, subsamples).mean(axis=(1, 3))
    return per_pixel


def glass_slab(ior: float, albedo: float, intensity: float, angle_deg: float = 0.0) -> dict:
    """A camera looking at a thick glass pane at `angle_deg` from its normal, and a small lit
    diffuse wall where the pane's reflection of the camera ray lands.

    The pane is two quads 0.1 apart, each wound so that its front face points out of the
    glass (the core's rule: a glass triangle's medium lies behind its front face, the side
    (v1-v0) x (v2-v0) points to), so a ray inside the glass meets the back face from behind
    and leaves with eta = ior. The camera sees only the pane (a 0.5 degree field of view);
    the pane sends it what it reflects of the wall, with the Fresnel reflectance at that
    angle, and, with four interactions, what refracts in, reflects off the back face and
    refracts out (glass_slab_radiance). The wall is small so that light it scatters back to
    the pane rarely returns to it (a term the closed form leaves out: below 0.2%)."""
    big = 50.0
    a = math.radians(angle_deg)
    sin_a, cos_a = math.sin(a), math.cos(a)
    p1 = _slab_points(ior, angle_deg)["front"]
    wall_centre = [0.0, (p1[1] + _slab_points(ior, angle_deg)["back"][1]) / 2, 1.0]
    def pane(z, front_towards_camera):
        quad = [[-big, -big, z], [big, -big, z], [big, big, z], [-big, big, z]]
        return quad if front_towards_camera else quad[::-1]
    w = 0.6
    cx, cy = wall_centre[0], wall_centre[1]
    return {
        "camera": {"position": [0, 0, 0], "look_at": [0, -sin_a, -cos_a], "up": [0, 1, 0],
                   "vfov": 0.5},
        "light": {"position": [0, cy + 0.9, 0.4], "intensity": [intensity] * 3},
        "materials": {"glass": {"type": "glass", "ior": ior},
                      "wall": {"type": "diffuse", "albedo": [albedo] * 3}},
        "quads": [{"vertices": pane(-1.0, True), "material": "glass"},     # normal +z
                  {"vertices": pane(-1.1, False), "material": "glass"},    # normal -z
                  {"vertices": [[cx - w, cy - w, 1.0], [cx - w, cy + w, 1.0],
                                [cx + w, cy + w, 1.0], [cx + w, cy - w, 1.0]],
                   "material": "wall"}],
    }


def _slab_points(ior: float, angle_deg: float) -> dict:
    """Where the central camera ray's reflected path (front) and its refracted, back-reflected
    path (back) meet the wall plane z = 1."""
    a = math.radians(angle_deg)
    sin_a, cos_a = math.sin(a), math.cos(a)
    tan_a = sin_a / cos_a
    y1 = -tan_a                                   # the pane's front face, z = -1
    sin_t = sin_a / ior
    tan_t = sin_t / math.sqrt(1 - sin_t * sin_t)
    y_out = y1 - 2 * 0.1 * tan_t                  # out through the front after the back face
    return {"front": [0.0, y1 - 2 * tan_a, 1.0], "back": [0.0, y_out - 2 * tan_a, 1.0]}


def fresnel(cos_i: float, eta: float) -> float:
    """Unpolarised Fresnel reflectance, eta = n_incident / n_transmitted."""
    sin2_t = eta * eta * (1 - cos_i * cos_i)
    if sin2_t >= 1:
        return 1.0
    cos_t = math.sqrt(1 - sin2_t)
    rs = (eta * cos_i - cos_t) / (eta * cos_i + cos_t)
    rp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t)
    return 0.5 * (rs * rs + rp * rp)


def glass_slab_radiance(scene: dict, bounces: int, angle_deg: float = 0.0) -> float:
    """The pixels' expected radiance: R L(front) with two interactions (pane, wall), plus
    T R T L(back) with four (in, back face, out, wall); R at the back face, seen from inside
    at the refracted angle, equals R outside (Snell and Fresnel are reciprocal)."""
    ior = scene["materials"]["glass"]["ior"]
    albedo = scene["materials"]["wall"]["albedo"][0]
    intensity = scene["light"]["intensity"][0]
    light = scene["light"]["position"]

    def wall(point):
        to_light = [light[i] - point[i] for i in range(3)]
        d2 = sum(c * c for c in to_light)
        cos = abs(to_light[2]) / math.sqrt(d2)
        return albedo / math.pi * intensity * cos / d2

    points = _slab_points(ior, angle_deg)
    cos_i = math.cos(math.radians(angle_deg))
    r = fresnel(cos_i, 1.0 / ior)
    sin_t = math.sin(math.radians(angle_deg)) / ior
    r_inside = fresnel(math.sqrt(1 - sin_t * sin_t), ior)
    value = r * wall(points["front"])
    if bounces >= 4:
        value += (1 - r) * r_inside * (1 - r_inside) * wall(points["back"])
    return value


def _mapped(scene: dict, point, scale: float, direction=None) -> dict:
    """A copy of `scene` with every point mapped by `point`, every length multiplied by `scale`
    (the light's intensity by its square) and, given `direction`, every direction (the camera's
    up included) mapped by it. What each primitive list's fields are (a point, a list of
    points, a length or a unit direction) is the renderer's own declaration of its kinds, read
    from `--scene-schema` (scene_schema.py)."""
    s = json.loads(json.dumps(scene))
    s["camera"]["position"] = point(s["camera"]["position"])
    s["camera"]["look_at"] = point(s["camera"]["look_at"])
    if direction is not None:
        s["camera"]["up"] = direction(s["camera"].get("up", [0, 1, 0]))
    if "light" in s:
        s["light"]["position"] = point(s["light"]["position"])
        if scale != 1:
            s["light"]["intensity"] = [c * scale**2 for c in s["light"]["intensity"]]
    for key, fields in scene_schema.primitive_fields().items():
        for prim in s.get(key, []):
            for name, what in fields.items():
                if what == "point":
                    prim[name] = point(prim[name])
                elif what == "points":
                    prim[name] = [point(v) for v in prim[name]]
                elif what == "length" and scale != 1:
                    prim[name] *= scale
                elif what == "direction" and direction is not None:
                    prim[name] = direction(prim[name])
    return s


def scaled(scene: dict, factor: float) -> dict:
    """The same scene with every length multiplied by `factor` and the light's intensity by
    factor^2, so that the image should not change at all."""
    return _mapped(scene, lambda p: [c * factor for c in p], factor)


def transformed(scene: dict, matrix=np.eye(3), offset=(0, 0, 0), scale=1.0) -> dict:  # noqa: B008
    """The scene rotated by `matrix`, scaled by `scale` (intensity by its square) and moved by
    `offset`, computed in double: the image should not change. scaled() and
    translated() are its two special cases as the grader's checks compute them."""
    point = lambda p: [float(c) for c in scale * (matrix @ np.asarray(p, float)) + offset]  # noqa: E731
    direction = lambda d: [float(c) for c in matrix @ np.asarray(d, float)]  # noqa: E731
    return _mapped(scene, point, scale, direction)


def load(name: str) -> dict:
    return json.loads((SCENES / f"{name}.json").read_text())


def translated(scene: dict, offset) -> dict:
    """The same scene moved by `offset` (camera, light and every primitive): the image should
    not change, up to float rounding at the new place."""
    return _mapped(scene, lambda p: [c + o for c, o in zip(p, offset)], 1)


# The view of floor_view: a camera 1 above the floor y = 0 looking down at 14 degrees, the
# light 1.5 above the floor ahead. Most shadow rays leave the floor at a slant, which is
# where an offset too small for the floor's coordinates lets them hit the floor itself.
FLOOR_CAMERA = dict(position=[0.0, 1.0, 0.0], look_at=[0.0, 0.0, -4.0], up=[0, 1, 0], vfov=60)
FLOOR_LIGHT = [0.5, 1.5, -3.0]


def floor_view(half: float, albedo: float = 0.5, intensity: float = 2.0,
               kind: str = "quad") -> dict:
    """A diffuse floor under a point light, seen from 1 unit above it: a quad of half-size
    `half` in the plane y = 0 (an axis-aligned rectangle once loaded), the same floor as two
    triangles (kind "triangles"), or (kind "sphere") a sphere of radius `half` whose top is the
    origin. Only the floor within a few units of the camera matters to the image, so a floor
    of any size should render alike (floor_view_expected, one bounce)."""
    scene = {"camera": dict(FLOOR_CAMERA),
             "light": {"position": list(FLOOR_LIGHT), "intensity": [intensity] * 3},
             "materials": {"floor": {"type": "diffuse", "albedo": [albedo] * 3}}}
    corners = [[-half, 0, -half], [-half, 0, half], [half, 0, half], [half, 0, -half]]
    if kind == "quad":
        scene["quads"] = [{"vertices": corners, "material": "floor"}]
    elif kind == "triangles":
        scene["triangles"] = [{"vertices": [corners[a] for a in t], "material": "floor"}
                              for t in ((0, 1, 2), (0, 2, 3))]
    else:
        scene["spheres"] = [{"center": [0, -half, 0], "radius": half, "material": "floor"}]
    return scene


def camera_rays(camera: dict, width: int, height: int, subsamples: int,
                edge_to_edge: bool = False):
    """Unit directions, in double, from the camera through the midpoints of subsamples^2
    cells of every pixel (edge_to_edge: through a grid of subsamples^2 points whose outer rows
    lie on the pixel's borders), as the renderer's Camera maps pixels: an array of shape
    (height * subsamples, width * subsamples, 3), row by row from the top."""
    import numpy as np
    pos = np.array(camera["position"], float)
    forward = np.array(camera["look_at"], float) - pos
    forward /= np.linalg.norm(forward)
    right = np.cross(forward, camera.get("up", [0, 1, 0]))
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    half_h = math.tan(math.radians(camera["vfov"]) / 2)
    half_w = half_h * width / height
    if edge_to_edge:
        offs = np.arange(subsamples) / (subsamples - 1)
    else:
        offs = (np.arange(subsamples) + 0.5) / subsamples
    xs = (np.arange(width)[:, None] + offs[None, :]).ravel()
    ys = (np.arange(height)[:, None] + offs[None, :]).ravel()
    gx, gy = np.meshgrid(xs, ys)
    d = (forward + right * (-half_w + 2 * half_w * gx / width)[..., None]
         + up * (half_h - 2 * half_h * gy / height)[..., None])
    return d / np.linalg.norm(d, axis=-1, keepdims=True)


def _floor_view_samples(scene: dict, width: int, height: int, subsamples: int,
                        edge_to_edge: bool = False):
    """floor_view's one-bounce radiance, in double, at subsamples^2 points of every pixel
    (camera_rays'), and whether each sees the floor: arrays of shape (height, subsamples,
    width, subsamples)."""
    import numpy as np
    pos = np.array(scene["camera"]["position"], float)
    d = camera_rays(scene["camera"], width, height, subsamples, edge_to_edge)
    if "spheres" in scene:
        sphere = scene["spheres"][0]
        centre, radius = np.array(sphere["center"], float), float(sphere["radius"])
        f = pos - centre
        b = -(d @ f)
        disc = radius**2 - ((f + d * b[..., None]) ** 2).sum(-1)
        t = b - np.sqrt(np.maximum(disc, 0.0))
        hit = (disc >= 0) & (t > 0)
        p = pos + t[..., None] * d
        normal = (p - centre) / radius
    else:
        floor_y = (scene.get("quads") or scene["triangles"])[0]["vertices"][0][1]
        t = (floor_y - pos[1]) / np.where(d[..., 1] < 0, d[..., 1], -1.0)
        hit = d[..., 1] < 0
        p = pos + t[..., None] * d
        normal = np.array([0.0, 1.0, 0.0])
    to_light = np.array(scene["light"]["position"], float) - p
    d2 = (to_light**2).sum(-1)
    cos = (to_light * normal).sum(-1) / np.sqrt(d2)
    albedo = scene["materials"]["floor"]["albedo"][0]
    intensity = scene["light"]["intensity"][0]
    radiance = np.where(hit, albedo / math.pi * intensity * np.maximum(cos, 0.0) / d2, 0.0)
    shape = (height, subsamples, width, subsamples)
    return radiance.reshape(shape), hit.reshape(shape)


def floor_view_expected(scene: dict, width: int, height: int, subsamples: int = 8):
    """Per-pixel expected radiance of floor_view (one bounce; the scene may be scaled or
    translated, not rotated), computed in double for the exact plane or sphere, by a midpoint
    rule over subsamples^2 points of each pixel. Also returns, per pixel, whether every one of
    those points sees the floor (pixels across the horizon are not smooth: compare the rest)."""
    radiance, hit = _floor_view_samples(scene, width, height, subsamples)
    return radiance.mean(axis=(1, 3)), hit.all(axis=(1, 3))


def floor_view_range(scene: dict, width: int, height: int, subsamples: int = 9):
    """The least and the greatest one-bounce radiance of floor_view over each pixel (over
    subsamples^2 points of it, the pixel's edges included): every sample a renderer takes in
    that pixel lies between them, so at 1 spp every pixel of a right image does, whatever the
    seed. Pixels not wholly on the floor get (0, inf)."""
    import numpy as np
    radiance, hit = _floor_view_samples(scene, width, height, subsamples, edge_to_edge=True)
    seen = hit.all(axis=(1, 3))
    lo = np.where(seen, radiance.min(axis=(1, 3)), 0.0)
    hi = np.where(seen, radiance.max(axis=(1, 3)), np.inf)
    return lo, hi


def fan_disk(count: int = 10000, radius: float = 8.0, centre=(0.0, 0.3)) -> dict:
    """floor_view's floor as a disk of `count` triangles around one centre vertex (at (x, 0, z)
    = `centre`, off the camera's foot), each a needle of aspect about count / (2 pi): 1,600 for
    10,000. The camera looks down at 34 degrees with a 40-degree view, so every pixel sees the
    disk well inside its rim, and floor_view_expected / floor_view_range give its image."""
    scene = floor_view(radius, kind="triangles")
    scene["camera"]["look_at"] = [0.0, 0.0, -1.5]
    scene["camera"]["vfov"] = 40
    cx, cz = centre
    rim = [[cx + radius * math.cos(2 * math.pi * k / count), 0.0,
            cz + radius * math.sin(2 * math.pi * k / count)] for k in range(count)]
    # (v1 - v0) x (v2 - v0) points up (+y), toward the camera and the light.
    scene["triangles"] = [{"vertices": [[cx, 0.0, cz], rim[(k + 1) % count], rim[k]],
                           "material": "floor"} for k in range(count)]
    return scene


def mixed_scale(half: float, radius: float = 1e-4) -> dict:
    """A diffuse sphere of `radius` resting on a floor of half-size `half`, seen from a few
    radii away, lit from the side so its shadow falls across the view. At half 1e4 float
    cannot place the sphere (it is below 2^-20 of the scene's extent): the references render
    it in double. At half 1, float renders the same view: the floor beyond the view adds
    nothing at one bounce, so the two images differ by rounding only."""
    r = radius
    return {"camera": {"position": [0, 4 * r, 8 * r], "look_at": [0, r, 0], "vfov": 40},
            "light": {"position": [0.5, 1, 0], "intensity": [1, 1, 1]},
            "materials": {"w": {"type": "diffuse", "albedo": [0.5, 0.5, 0.5]}},
            "spheres": [{"center": [0, r, 0], "radius": r, "material": "w"}],
            "quads": [{"vertices": [[-half, 0, -half], [-half, 0, half], [half, 0, half],
                                    [half, 0, -half]], "material": "w"}]}
