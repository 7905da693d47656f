"""``python -m orbit_env.cli``: the ``orbit-env`` command without its console script."""

import sys

from orbit_env.cli import main

sys.exit(main())
