"""Speed against accuracy (`make tradeoff`, `python3 -m tools.tradeoff`): run.py measures and
checks, the other modules are its parts (series, sweep, fit, bias, reference, scenes, record,
report)."""
