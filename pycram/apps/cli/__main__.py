"""`python -m pycram.apps.cli ...`: the `pycram` command line (as `python -m pycram ...`)."""

import sys

from pycram.apps.cli import main

sys.exit(main())
