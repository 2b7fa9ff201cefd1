"""The run options every front end checks the same way: `--stepping` and `--until`.

`pycram demo` (both scenarios), `pycram replay` and `pycram experiment` refuse a bad value
before anything is built, each with the same one-line message (a `ValueError`; the CLI turns it
into exit code 2).
"""

from __future__ import annotations

import math

from pycram.core.runtime.lockstep import DEFAULT_STEPPING, STEPPING_MODES

__all__ = ["check_stepping", "check_until"]


def check_stepping(stepping: str | None) -> str:
    """`stepping` if it is one of `STEPPING_MODES`, `DEFAULT_STEPPING` for None; raises
    `ValueError` naming the choices otherwise."""
    if stepping is None:
        return DEFAULT_STEPPING
    if stepping not in STEPPING_MODES:
        raise ValueError(f"--stepping must be {' or '.join(STEPPING_MODES)}, not {stepping!r}")
    return stepping


def check_until(until: float | None) -> float | None:
    """`until` [s of simulated time] if it is None or a finite time >= 0; raises `ValueError`
    otherwise."""
    if until is not None and (not math.isfinite(until) or until < 0):
        raise ValueError(f"--until must be a simulated time >= 0 [s], not {until}")
    return until
