"""The grader's checks that every renderer of the course passes, by name: the lab tests run
them on each reference (parametrized by these ids), tools/gpu/report.py on each GPU build.
A rubric (grading/grade.py) weighs a subset of them; this is the whole list, kept once."""
from grading import checks

CHECKS = {
    "sphere-interior": checks.check_sphere_interior,
    "million-samples": checks.check_million_samples,
    "lit-plane": checks.check_lit_plane,
    "glass-pane": checks.check_glass_slab,
    "golden-cornell": lambda b: checks.check_golden(b, "cornell"),
    "golden-showcase": lambda b: checks.check_golden(b, "showcase"),
    "scale": checks.check_scale_invariance,
    "translation": checks.check_translation_invariance,
    "large-primitives": checks.check_large_primitives,
    "reproducible": checks.check_reproducible,
}
