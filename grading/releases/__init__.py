"""What leaves the course repository: release (a student repository), reference_bins (its
prebuilt references), leaks (what must never ship), handin (a student's hand-in), gradescope
(the Gradescope bundle; gradescope_image/ its Docker test) and handout_tables (the rubric tables
in the handouts). They import grading.grade and the checks, never the classes package."""
