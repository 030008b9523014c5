"""``python -m drakegrasp``: the same as the ``drakegrasp`` command."""

import sys

from drakegrasp.cli import main

sys.exit(main())
