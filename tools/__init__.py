"""The commands behind make targets (`make help` lists them), run from the repository root as
`python3 -m tools.NAME`: bench/, tradeoff/, gpu/, make_golden, extremes_report."""
