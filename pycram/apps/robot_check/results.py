"""What a conformance run finds: one `CheckResult` per check, gathered in a `CheckReport`.

A check's `result` is one of `RESULTS`: ``PASS`` (it ran and met its criterion), ``FAIL`` (it
ran and did not, or could not run because the robot is broken: `detail` says why) or ``SKIP``
(it was not run: the short form leaves it out, or what it needs failed before; `detail` says
which). Times are the simulated time [s] the check took in its world (None when it simulated
nothing) and the wall time [s] it took on this machine.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

__all__ = ["PASS", "FAIL", "SKIP", "RESULTS", "CheckResult", "CheckReport", "CheckFailed", "CheckSkipped"]

#: The check ran and met its criterion.
PASS = "PASS"
#: The check ran and did not meet its criterion (or the robot could not run it).
FAIL = "FAIL"
#: The check was not run (short form, or what it needs failed before).
SKIP = "SKIP"
#: Every result a check can have.
RESULTS = (PASS, FAIL, SKIP)


class CheckFailed(Exception):
    """Raised by a check's body when the robot ran it but missed its criterion; the message is
    the row's detail (what was expected, what was measured). `data` goes into the JSON output."""

    def __init__(self, detail: str, data: dict[str, Any] | None = None) -> None:
        super().__init__(detail)
        self.detail = detail
        self.data = dict(data or {})


class CheckSkipped(Exception):
    """Raised by a check's body that cannot run (the robot has nothing to check there); the
    message is the row's detail."""


@dataclass
class CheckResult:
    """One row of the conformance table.

    `group` is the part of the run it belongs to (``description``, ``world``, ``motions``,
    ``reach``, ``camera``, ``actions``, ``set-table``), `check` its name within the run,
    `result` one of `RESULTS`, `detail` what was measured or why it failed or was skipped,
    `sim_time` the simulated time [s] it took (None: no simulation), `wall_time` the wall time
    [s], `data` machine-readable measurements (JSON-serialisable).
    """

    group: str
    check: str
    result: str
    detail: str = ""
    sim_time: float | None = None
    wall_time: float = 0.0
    data: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if self.result not in RESULTS:
            raise ValueError(f"a check's result is one of {', '.join(RESULTS)}, not {self.result!r}")

    @property
    def failed(self) -> bool:
        """Whether this check failed."""
        return self.result == FAIL

    def as_dict(self) -> dict[str, Any]:
        """The row as JSON-serialisable data."""
        return {
            "group": self.group,
            "check": self.check,
            "result": self.result,
            "detail": self.detail,
            "sim_time": self.sim_time,
            "wall_time": self.wall_time,
            "data": self.data,
        }


@dataclass
class CheckReport:
    """The conformance run of one robot: its rows in the order they ran.

    `form` is ``"full"`` or ``"short"``; `wall_time` [s] the whole run's wall time.
    """

    robot: str
    form: str
    results: list[CheckResult] = field(default_factory=list)
    wall_time: float = 0.0

    @property
    def passed(self) -> bool:
        """True when no check failed (skipped checks do not fail a run)."""
        return not any(r.failed for r in self.results)

    def count(self, result: str) -> int:
        """How many checks had `result` (one of `RESULTS`)."""
        return sum(1 for r in self.results if r.result == result)

    @property
    def sim_time(self) -> float:
        """The simulated time [s] of all checks together."""
        return sum(r.sim_time or 0.0 for r in self.results)

    def failures(self) -> list[CheckResult]:
        """The checks that failed, in run order."""
        return [r for r in self.results if r.failed]

    def summary(self) -> str:
        """One line: robot, form, counts, times."""
        return (
            f"{self.robot} ({self.form} form): {self.count(PASS)} passed, {self.count(FAIL)} failed, "
            f"{self.count(SKIP)} skipped; sim {self.sim_time:.1f} s, wall {self.wall_time:.1f} s"
        )

    def as_dict(self) -> dict[str, Any]:
        """The report as JSON-serialisable data (``passed``, counts, times and every row)."""
        return {
            "robot": self.robot,
            "form": self.form,
            "passed": self.passed,
            "counts": {r: self.count(r) for r in RESULTS},
            "sim_time": self.sim_time,
            "wall_time": self.wall_time,
            "checks": [r.as_dict() for r in self.results],
        }
