"""The autograder (grading/README.md): at its top the rubrics (grade.py) and what its parts
share (results, compile, students_tree, shown...); the checks in checks/, a class at once in
classes/, what leaves the repository in releases/. What it shares with the tools and tests
(images, comparison, the sandbox, running a lab binary, mpirun) is the labkit package."""
