"""`python -m pycram FILE.py [ARGS...]` runs a plan script with the block syntax switched on.

Any other arguments (`python -m pycram run FILE.py`, `python -m pycram demo`, none) go to the
`pycram` command line (`pycram.apps.cli.main`).
"""

from __future__ import annotations

import os
import sys


def main(argv: list[str] | None = None) -> int:
    """Run `argv[0]` as a plan script if it names a Python file, else the pycram CLI."""
    args = sys.argv[1:] if argv is None else argv
    if args and (args[0].endswith(".py") or os.path.isfile(args[0])):
        from pycram.core.macros import format_script_error, run_script

        try:
            run_script(args[0], args[1:])
        except Exception as e:  # reported as `python FILE` would, from the script's first frame
            sys.stderr.write(format_script_error(e, args[0]))
            return 1
        return 0
    from pycram.apps.cli import main as cli_main

    result = cli_main()
    return result if isinstance(result, int) else 0


if __name__ == "__main__":
    sys.exit(main())
