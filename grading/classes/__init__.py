"""A class graded at once: batch (a grader process per student, grades.csv, report.html), slurm
(the same through Slurm), class_page (the class's report.html) and verdicts (a grade's verdict
in a few words). They import grading.grade and the checks, never the releases package."""
