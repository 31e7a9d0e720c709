"""The autograder (grading/README.md): rubrics, checks, building hand-ins, results and class
pages, releases. What it shares with the tools and tests (images, comparison, the sandbox,
running a lab binary) is the labkit package."""
