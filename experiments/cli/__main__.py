"""``python -m experiments.cli``: the ``tasker`` command."""

import sys

from experiments.cli import main

sys.exit(main())
