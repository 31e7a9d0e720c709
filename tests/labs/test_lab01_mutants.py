"""Mutation tests: the checks must catch deliberately broken solutions.

Each mutant is the lab-01 reference with one plausible student bug. It is built from a copy
of a solution or shared file with one edit (the edited header comes first on the include
path), then run through the correctness checks
(grading/checks/). A mutant must fail the checks named for it: that documents which bug
each check catches, and proves that no check is one that cannot fail. Run with `-s` to see
the matrix of mutants and the checks named for them.
"""
import concurrent.futures
import pathlib

import pytest

from grading.checks import analytic, invariance
from grading.checks.golden import check_golden
from labkit.harness import ROOT
from labkit.variants import build_variant

CHECKS = {
    "interior": analytic.check_sphere_interior,
    "millions": analytic.check_million_samples,
    "plane": analytic.check_lit_plane,
    "glass": analytic.check_glass_slab,
    "cornell": lambda b: check_golden(b, "cornell"),
    "showcase": lambda b: check_golden(b, "showcase"),
    "scale": invariance.check_scale_invariance,
    "moved": invariance.check_translation_invariance,
    "large": invariance.check_large_primitives,
}

# name: (file under common/core or the solution dir, original text, mutated text, checks that
# must catch it)
MUTANTS = {
    "no cosine in NEE": ("path_steps.h", "(cos_theta / (kPi * distance2))",
                         "(1.0f / (kPi * distance2))", ["plane", "cornell"]),
    "BRDF without 1/pi": ("path_steps.h", "(cos_theta / (kPi * distance2))",
                          "(cos_theta / distance2)", ["interior", "plane", "cornell"]),
    "light falls off as 1/d": ("path_steps.h", "(cos_theta / (kPi * distance2))",
                               "(cos_theta / (kPi * distance))", ["interior", "plane"]),
    "shadow rays ignore spheres": (
        "sphere.h", "return intersect_sphere<kConverged>(ray, s, t_max) < t_max;",
        "return false && intersect_sphere<kConverged>(ray, s, t_max) < t_max;", ["cornell"]),
    "shadow rays ignore triangles": (
        "triangle.h", "return intersect_triangle<kConverged>(ray, shear, tri, t_max) < t_max;",
        "return false && intersect_triangle<kConverged>(ray, shear, tri, t_max) < t_max;",
        ["showcase"]),
    "every rectangle hit names rectangle 0": (
        "path_steps.h", "hit = {t, primitive_kind<K>, i};",
        "hit = {t, primitive_kind<K>, has_kind<Kinds<AxisRect>, K> ? 0 : i};",
        ["cornell", "showcase"]),
    "rectangle: inside test of one axis reversed": (
        "axis_rect.h",
        "(from_edge(r.lo_u - o_u, d_u) >= 0.0f) & (from_edge(r.hi_u - o_u, d_u) <= 0.0f)",
        "(from_edge(r.lo_u - o_u, d_u) <= 0.0f) & (from_edge(r.hi_u - o_u, d_u) >= 0.0f)",
        ["cornell", "showcase"]),
    "no pixel jitter": ("path_steps.h",
                        "camera.ray_through(x + real(rng.at(kDimPixelX)), "
                        "y + real(rng.at(kDimPixelY)))",
                        "camera.ray_through(x + 0.5f, y + 0.5f)", ["cornell"]),
    "every sample reuses sample 0": ("path_steps.h", "SampleStream rng(settings.seed, pixel, s)",
                                     "SampleStream rng(settings.seed, pixel, 0)", ["cornell"]),
    "one bounce too few": ("path_steps.h", "path.alive = path.bounce < max_bounces;",
                           "path.alive = path.bounce + 1 < max_bounces;",
                           ["interior", "cornell"]),
    "throughput ignores albedo": ("path_steps.h",
                                  "path.throughput *= material.albedo;\n"
                                  "            path.ray = {above, sample_cosine",
                                  "path.ray = {above, sample_cosine",
                                  ["interior", "cornell"]),
    "NEE from the offset point": ("path_steps.h",
                                  "const Vec3 to_light = scene.light.position - position;",
                                  "const Vec3 to_light = scene.light.position - origin;",
                                  # A translated scene no longer shows it (the driver renders
                                  # scenes centred on their geometry); a floor of half-size
                                  # 1e5, whose offsets are large, does.
                                  ["large"]),
    "uniform sampling weighted as cosine": (
        "material.h", "const real r = sqrt_real(u1);", "const real r = sqrt_real(1.0f - u1 * u1);",
        ["cornell"]),
    "glass never reflects": ("material.h",
                             "if (rng.at(bounce_dimension(bounce, 0)) < reflectance)",
                             "if (reflectance < 0.0f)", ["glass"]),
    "sphere: far root only": ("sphere.h", "near_ok ? t_near : far_ok ? t_far : t_max;",
                              "near_ok && false ? t_near : far_ok ? t_far : t_max;",
                              ["cornell", "showcase"]),
    "fixed epsilon offset": ("ray.h", "return p + n * (scale * kRelativeOffset);",
                             "return p + n * (0.0f * scale + 1e-4f);", ["scale"]),
    "float running sum": ("sample_sum.h", "double r = 0.0, g = 0.0, b = 0.0;",
                          "float r = 0.0f, g = 0.0f, b = 0.0f;", ["millions"]),
    "no offset at all": ("ray.h", "return p + n * (scale * kRelativeOffset);",
                         "return p + n * (0.0f * scale);", ["cornell"]),
}
# Not a mutant any more: the offset without the primitive's extent. Since triangles take their
# hit distance from their plane (triangle.h), no kind's hit error grows with coordinates larger
# than the hit point's in the large-primitive scenes, and check_large_primitives passes it.


def build_mutant(name: str, workdir: pathlib.Path) -> pathlib.Path:
    file, old, new, _ = MUTANTS[name]
    original = (ROOT / "labs" / "01-serial" / "solution" / file
                if file == "render.cpp" else ROOT / "common" / "core" / file).read_text()
    assert original.count(old) >= 1, f"mutant '{name}': text to mutate not found in {file}"
    return build_variant("01-serial", workdir, {file: original.replace(old, new, 1)})


@pytest.fixture(scope="module")
def mutant_results(tmp_path_factory):
    # Each mutant meets the checks that must catch it (rendering it through every check would
    # only fill the table below, and took most of this file's time).
    def evaluate(name):
        binary = build_mutant(name, tmp_path_factory.mktemp("mutant"))
        return name, {check: CHECKS[check](binary) for check in MUTANTS[name][3]}

    with concurrent.futures.ThreadPoolExecutor(2) as pool:
        results = dict(pool.map(evaluate, MUTANTS))
    print("\nmutant".ljust(40) + "".join(c.rjust(10) for c in CHECKS))
    for name, by_check in results.items():
        print(name.ljust(39) + "".join(
            ("" if c not in by_check else "caught" if not by_check[c].passed else "MISSED")
            .rjust(10) for c in CHECKS))
    return results


@pytest.mark.parametrize("name", sorted(MUTANTS))
def test_mutant_is_caught(mutant_results, name):
    expected = MUTANTS[name][3]
    missed = [c for c in expected if mutant_results[name][c].passed]
    assert not missed, f"'{name}' slipped past: " + "; ".join(
        str(mutant_results[name][c]) for c in missed)
