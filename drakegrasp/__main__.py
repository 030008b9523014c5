"""``python -m drakegrasp``: the same as the ``drakegrasp`` command."""

import sys

try:
    from drakegrasp.cli import run
except KeyboardInterrupt:  # Ctrl-C while Drake is still importing
    print("drakegrasp: interrupted", file=sys.stderr)
    sys.exit(130)

run()
