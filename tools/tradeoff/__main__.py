"""`python3 -m tools.tradeoff`: speed against accuracy (`make tradeoff`; run.py says how)."""
import sys

from tools.tradeoff.run import main

sys.exit(main())
