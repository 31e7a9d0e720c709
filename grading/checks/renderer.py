"""The grader's checks that every renderer of the course passes, by name: the lab tests run
them on each reference (parametrized by these ids), tools/gpu/report.py on each GPU build.
A rubric (grading/grade.py) weighs a subset of them; this is the whole list, kept once."""
from grading.checks import analytic, invariance
from grading.checks.golden import check_golden

CHECKS = {
    "sphere-interior": analytic.check_sphere_interior,
    "million-samples": analytic.check_million_samples,
    "lit-plane": analytic.check_lit_plane,
    "glass-pane": analytic.check_glass_slab,
    "golden-cornell": lambda b: check_golden(b, "cornell"),
    "golden-showcase": lambda b: check_golden(b, "showcase"),
    "scale": invariance.check_scale_invariance,
    "translation": invariance.check_translation_invariance,
    "large-primitives": invariance.check_large_primitives,
    "reproducible": invariance.check_reproducible,
}
