"""Test doubles for designators and process modules (like py_trees' scripted behaviours).

Nothing here touches hardware. These classes exist for tests and examples; they are named as
doubles so that nobody mistakes them for real robot code.

- :class:`ScriptedProcessModule` records every designator it executes, plays a script of
  outcomes, can hold each execution until the test releases it, tracks concurrency, and records
  cancel-hook calls.
- :class:`CountingGenerator` is a resolver solution that counts how far it was advanced (to
  prove lazy resolution).
- :func:`scenario_double` is an experiment scenario (`pycram experiment --scenario
  pycram.testing:scenario_double`) that runs no simulation: a scripted result per seed in a few
  milliseconds, for testing experiment machinery.
"""

from __future__ import annotations

import threading
from collections import deque
from collections.abc import Callable, Iterable, Iterator
from typing import Any

from pycram.core.runtime import wait_until
from pycram.core.runtime.evaporation import runtime_code
from pycram.core.runtime.lockstep import Condition
from pycram.execution.process_module import ProcessModule
from pycram.world.robot_registry import robot_names

__all__ = ["ScriptedProcessModule", "CountingGenerator", "scenario_double", "SCENARIO_DOUBLE_FAULTS"]


class ScriptedProcessModule(ProcessModule):
    """A process module double.

    - ``script``: outcomes consumed one per execution; an exception (instance) is raised, a
      callable is called with the designator and its result returned, any other value is
      returned. When the script is empty ``default(designator)`` is returned (by default the
      designator's resolved solution if it resolves, else ``None``).
    - ``hold=True``: each execution blocks (evaporably) in ``_execute`` until it can take one
      of the releases granted by :meth:`release` (an evaporated execution takes none).
    - ``log``: list of ``(event, designator)`` with events ``'start'``, ``'end'``, ``'cancel'``,
      in the order they happened. ``executed``: the designators whose execution started.
    - ``max_concurrency``: the largest number of simultaneous ``_execute`` calls observed.
    """

    def __init__(
        self,
        name: str | None = None,
        script: Iterable[Any] = (),
        hold: bool = False,
        default: Callable[[Any], Any] | None = None,
    ) -> None:
        super().__init__(name)
        self.script: deque[Any] = deque(script)
        self.hold = hold
        self.default = default
        self.log: list[tuple[str, Any]] = []
        self.executed: list[Any] = []
        self.cancelled: list[Any] = []
        self.max_concurrency = 0
        self._active = 0
        self._releases = 0
        self._consumed = 0
        self._started = 0
        self._double_cv = Condition(threading.Lock())

    # -- test control -------------------------------------------------------------------------

    @runtime_code
    def release(self, n: int = 1) -> None:
        """Let ``n`` more held executions finish."""
        with self._double_cv:
            self._releases += n
            self._double_cv.notify_all()

    def wait_started(self, n: int, timeout: float = 5.0) -> bool:
        """Block until ``n`` executions have started in total; ``False`` on timeout."""
        return wait_until(self._double_cv, lambda: self._started >= n, timeout)

    def wait_logged(self, n: int, timeout: float = 5.0) -> bool:
        """Block until the log has ``n`` entries; ``False`` on timeout."""
        return wait_until(self._double_cv, lambda: len(self.log) >= n, timeout)

    # -- process module -----------------------------------------------------------------------

    # The double's own bookkeeping is runtime code: an evaporation landing inside
    # `Condition.__enter__` would otherwise leave its lock held.

    @runtime_code
    def _record(self, event: str, designator: Any) -> None:
        with self._double_cv:
            self.log.append((event, designator))
            self._double_cv.notify_all()

    @runtime_code
    def _record_start(self, designator: Any) -> None:
        with self._double_cv:
            self._active += 1
            self.max_concurrency = max(self.max_concurrency, self._active)
            self._started += 1
            self.executed.append(designator)
            self.log.append(("start", designator))
            self._double_cv.notify_all()

    @runtime_code
    def _record_inactive(self) -> None:
        with self._double_cv:
            self._active -= 1

    def _execute(self, designator: Any) -> Any:
        self._record_start(designator)
        try:
            if self.hold:
                wait_until(self._double_cv, self._take_release)
            outcome = self.script.popleft() if self.script else _DEFAULT
            if outcome is _DEFAULT:
                result = self.default(designator) if self.default else _solution(designator)
            elif isinstance(outcome, BaseException):
                raise outcome
            elif callable(outcome):
                result = outcome(designator)
            else:
                result = outcome
            self._record("end", designator)
            return result
        finally:
            self._record_inactive()

    def _take_release(self) -> bool:  # predicate under _double_cv: consume one release
        if self._releases > self._consumed:
            self._consumed += 1
            return True
        return False

    def _cancel(self, designator: Any) -> None:
        self.cancelled.append(designator)
        self._record("cancel", designator)


_DEFAULT = object()


def _solution(designator: Any) -> Any:
    from pycram.designators.core import DesignatorError

    try:
        return designator.reference()
    except (DesignatorError, AttributeError):
        return None


class CountingGenerator:
    """An iterator over ``items`` that counts how many items were taken (``advanced``).

    Use it as a resolver solution: ``resolvers.append(lambda d: [CountingGenerator(...)])``
    is not a generator, so wrap it with :meth:`generator`, which returns a real generator.
    """

    def __init__(self, items: Iterable[Any]) -> None:
        self._items = iter(items)
        self.advanced = 0

    def generator(self) -> Iterator[Any]:
        """A generator over the items that counts each advance."""
        for item in self._items:
            self.advanced += 1
            yield item


#: The faults `scenario_double` knows.
SCENARIO_DOUBLE_FAULTS = ("drop", "slow")


def scenario_double(
    robot: str,
    seed: int,
    faults: frozenset[str] = frozenset(),
    db_url: str | None = None,
    pictures: bool = False,
    stepping: str = "lockstep",
) -> dict[str, Any]:
    """A scripted experiment scenario (no simulation): the result of a `pycram experiment` run
    (`stepping` is only passed back in the result).

    Succeeds unless `"drop"` is among `faults` and the seed is divisible by 3 (then the cause is
    `ObjectSlipped`); `sim_time` is 10 + seed % 7 [s] (twice that with `"slow"`). Knows the
    registered robots (:func:`pycram.world.robot_registry.robot_names`) and the faults in
    `SCENARIO_DOUBLE_FAULTS` (`ValueError` otherwise).
    For tests across processes it reads two environment variables: with
    `$PYCRAM_SCENARIO_DOUBLE_LOG` set it appends "robot seed variant" to that file for every run;
    when `$PYCRAM_SCENARIO_DOUBLE_INTERRUPT` is the seed, it sends SIGINT to its parent process
    when that is a `pycram` process (the experiment's driver, for a local worker; never a Ray
    worker's parent) before returning: a deterministic Ctrl-C.
    """
    import os
    import signal
    import time

    started = time.monotonic()
    if robot not in robot_names():
        raise ValueError(f"unknown robot {robot!r}; available robots: {', '.join(robot_names())}")
    unknown = sorted(set(faults) - set(SCENARIO_DOUBLE_FAULTS))
    if unknown:
        raise ValueError(f"unknown fault(s) {', '.join(unknown)}; known: {', '.join(SCENARIO_DOUBLE_FAULTS)}")
    variant = ",".join(sorted(faults))
    log_file = os.environ.get("PYCRAM_SCENARIO_DOUBLE_LOG")
    if log_file:
        with open(log_file, "a", encoding="utf-8") as f:
            f.write(f"{robot} {seed} {variant or '-'}\n")
    failed = "drop" in faults and seed % 3 == 0
    sim_time = (10.0 + seed % 7) * (2.0 if "slow" in faults else 1.0)
    time.sleep(0.02)
    if os.environ.get("PYCRAM_SCENARIO_DOUBLE_INTERRUPT") == str(seed):
        parent = os.getppid()
        try:
            with open(f"/proc/{parent}/cmdline", "rb") as f:
                is_driver = b"pycram" in f.read()
        except OSError:
            is_driver = False
        if is_driver:  # a local worker's parent is the experiment's driver; a Ray worker's is not
            os.kill(parent, signal.SIGINT)
    return {
        "robot": robot,
        "seed": seed,
        "faults": sorted(faults),
        "stepping": stepping,
        "success": not failed,
        "objects": {"cup": {"placed": not failed, "failure": "ObjectSlipped" if failed else None, "reason": None}},
        "failure_causes": ["ObjectSlipped"] if failed else [],
        "sim_time": sim_time,
        "wall_time": time.monotonic() - started,
    }


scenario_double.FAULTS = SCENARIO_DOUBLE_FAULTS  # type: ignore[attr-defined]  # read by the experiment runner
