"""The one place where the simulation imports the PyCRAM runtime (fluents and clocks).

Everything in `pycram.sim` gets `Fluent`, `ManualClock` and `use_clock` from here. If the
language core is not importable (during early development), small stand-ins with the same
contract are used and a warning is logged.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

_log = logging.getLogger(__name__)

try:  # pragma: no cover - exercised whichever way the repository is
    from pycram.core.fluent import Fluent
except ImportError:  # pragma: no cover
    _log.warning("pycram.fluent not available: pycram.sim uses a minimal stand-in Fluent")

    class Fluent:  # type: ignore[no-redef]  # the stand-in for the missing import
        """Minimal stand-in: a value with `get_value`, `set_value` and `wait_for`."""

        def __init__(self, value: Any = None, name: str | None = None) -> None:
            self._value = value
            self.name = name
            self._cond = threading.Condition()

        def get_value(self) -> Any:
            return self._value

        def set_value(self, value: Any) -> None:
            with self._cond:
                self._value = value
                self._cond.notify_all()

        def wait_for(self, timeout: float | None = None) -> bool:
            with self._cond:
                return self._cond.wait_for(lambda: self._value is not None, timeout)


try:  # pragma: no cover
    from pycram.core.runtime.clock import ManualClock, current_clock, set_clock, use_clock
except ImportError:  # pragma: no cover
    _log.warning("pycram.runtime not available: pycram.sim uses a minimal stand-in clock")

    _active: Any = None

    def current_clock() -> Any:  # type: ignore[misc]  # stand-in: the clock type is missing too
        return _active

    def set_clock(clock: Any) -> Any:  # type: ignore[misc]  # stand-in: the clock type is missing too
        global _active
        previous, _active = _active, clock
        return previous

    class ManualClock:  # type: ignore[no-redef]  # the stand-in for the missing import
        def __init__(self, start: float = 0.0) -> None:
            self._now = start

        def now(self) -> float:
            return self._now

        def advance_to(self, t: float) -> None:
            self._now = max(self._now, t)

    @contextmanager
    def use_clock(clock: Any) -> Iterator[Any]:
        yield clock


__all__ = ["Fluent", "ManualClock", "current_clock", "set_clock", "use_clock"]
