"""Showing a conformance run: a rich table for people, a JSON file for machines.

`report_table` renders a :class:`~pycram.apps.robot_check.results.CheckReport` as a
:class:`rich.table.Table` -- one row per check: its name, PASS / FAIL / SKIP, the detail
(what was measured, or why it failed or was skipped), the simulated and the wall time [s] --
with the run's summary as its caption. `write_json` writes the report's data
(:meth:`CheckReport.as_dict`) to a file.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from pycram.apps.robot_check.results import FAIL, PASS, SKIP, CheckReport

__all__ = ["report_table", "write_json", "STYLES"]

#: The rich style of each result.
STYLES = {PASS: "green", FAIL: "bold red", SKIP: "yellow"}


def _seconds(value: float | None) -> str:
    return "–" if value is None else f"{value:.1f}"


def report_table(report: CheckReport) -> Any:
    """The report as a :class:`rich.table.Table` (see the module docstring)."""
    from rich.table import Table
    from rich.text import Text

    table = Table(
        title=f"pycram robot check {report.robot} ({report.form} form)",
        caption=report.summary(),
        show_lines=False,
    )
    table.add_column("check", no_wrap=True)
    table.add_column("result", no_wrap=True)
    table.add_column("detail", overflow="fold")
    table.add_column(Text("sim [s]"), justify="right", no_wrap=True)
    table.add_column(Text("wall [s]"), justify="right", no_wrap=True)
    for row in report.results:
        table.add_row(
            Text(row.check),
            Text(row.result, style=STYLES[row.result]),
            Text(row.detail),
            _seconds(row.sim_time),
            _seconds(row.wall_time),
        )
    return table


def write_json(reports: list[CheckReport], path: str | Path) -> Path:
    """Write `reports` (one per robot checked) as JSON to `path`: ``{"passed": bool, "robots":
    [report, ...]}``. Returns the path; raises ``OSError`` when it cannot be written."""
    path = Path(path)
    data = {"passed": all(r.passed for r in reports), "robots": [r.as_dict() for r in reports]}
    path.write_text(json.dumps(data, indent=2, default=str) + "\n", encoding="utf-8")
    return path
