"""Make the fuzz helpers importable (``fuzz_cases``, ``fuzz_oracles``)."""

import sys
from pathlib import Path

_HERE = str(Path(__file__).resolve().parent)
if _HERE not in sys.path:
    sys.path.insert(0, _HERE)
