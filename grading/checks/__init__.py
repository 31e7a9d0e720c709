"""The checks a rubric weighs, each module one concern with the false-failure rates of its
checks: check_result (what a check returns), golden (the golden images), analytic (the closed
forms), invariance (scale, moves, size, reproducibility), speed (timed renders and their
credit), identity (lab 01's bits), mpi (lab 04's distributions and hybrid threads), layout (lab
07's pool), lanes (lab 02's lanes), races (lab 03 under ThreadSanitizer), hidden (the hidden
scene), part_a (lab 02's Part A); graded_scenes (the scenes they render, drawn for this grade),
draws (what is drawn from the grading secret), symptoms (a failure's likely cause),
golden_sums (the stored golden data's sums) and renderer (the checks every renderer passes, by
name). Import a name from the module that defines it; this package names none of them.

A renderer whose float roundings differ (SIMD, GPU) is another random draw of the same
estimator, so the rates apply to it too. Which bugs each check catches is shown by
tests/labs/test_lab01_mutants.py. The checks import the grader's shared modules below them
(compile, students_tree, shown...), never grading.grade or the classes and releases packages."""
