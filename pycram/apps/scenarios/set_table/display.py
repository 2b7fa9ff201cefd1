"""`pycram demo --scenario set-table` in the terminal: the scenario run with a live progress
line, then the task tree, each object placed or missing and why, the faults injected and the
pictures written.

`main` returns the exit code: 0 only when every object is at its place setting and every drawer
closed; 2 for bad options; else 1.
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any

from pycram.apps.run_options import check_stepping, check_until
from pycram.apps.scenarios.set_table.driver import (
    _check,
    check_environment,
    check_starts,
    default_objects,
    record_replay_info,
    run_scenario,
    scenario_name,
)
from pycram.apps.scenarios.set_table.judge import SetTableResult
from pycram.world.robot_registry import DEFAULT_ROBOT

__all__ = ["main", "main_on_open_surfaces", "main_anywhere"]


def _output_folder(robot: str, seed: int, run_id: Any, scenario: str = "set-table") -> Path:
    stem = f"{scenario}-{robot}-{seed}"
    return Path("output") / (f"{stem}-{run_id}" if run_id is not None else f"{stem}-{time.strftime('%Y%m%d-%H%M%S')}")


def main(
    robot: str = DEFAULT_ROBOT,
    seed: int = 0,
    faults: str | frozenset[str] = "",
    output: str | None = None,
    db: str | None = None,
    record: bool = True,
    quiet: bool = False,
    animation: bool = True,
    in_containers: bool = True,
    stepping: str | None = None,
    until: float | None = None,
    starts: str = "narrow",
    environment: str = "apartment",
) -> int:
    """`pycram demo --scenario set-table`: run the scenario with live progress, print the task
    tree and what is missing and why; write start/end pictures (and run.gif with `animation`),
    the task-tree SVG and the timeline of the recorded run. With `until` [s of simulated time]:
    stop there and write the scene and belief pictures and the task tree of that moment. Returns
    the exit code: 0 only when every object is at its place setting and every drawer closed, or
    when the run was stopped at `until` and its pictures written; 2 for bad options; else 1."""
    import os

    from rich.console import Console

    from pycram.apps.scenarios.common.display import begin, finish_recording, live_line, report_run

    os.environ.setdefault("MUJOCO_GL", "egl")
    console = Console()

    def checks() -> tuple[frozenset[str], str]:
        kinds = _check(robot, seed, faults)
        check_environment(environment, check_starts(starts))
        checked_stepping = check_stepping(stepping)
        check_until(until)
        return kinds, checked_stepping

    started = begin(console, checks, quiet=quiet, record=record, db=db, title=f"set table ({robot}, seed {seed})")
    if started is None:
        return 2
    (kinds, stepping), recorder = started
    run_id = recorder.run_id if recorder is not None else None
    folder = Path(output) if output else _output_folder(robot, seed, run_id, scenario_name(in_containers, starts))
    live, progress = live_line(quiet, len(default_objects(starts)))
    result: SetTableResult | None = None
    task = None
    try:
        if live is not None:
            live.start()
        result, task = run_scenario(
            robot,
            seed,
            kinds,
            recorder=recorder,
            output=folder,
            animation=animation,
            progress=progress,
            in_containers=in_containers,
            stepping=stepping,
            until=until,
            starts=starts,
            environment=environment,
        )
    finally:
        if live is not None:
            live.stop()
        if recorder is not None:
            record_replay_info(
                recorder,
                result,
                task,
                in_containers=in_containers,
                stepping=stepping,
                pictures=True,
                until=until,
                starts=starts,
                environment=environment,
            )
            run_id = finish_recording(recorder, result)
    return report_run(
        console,
        result,
        task,
        folder=folder,
        recorder=recorder,
        run_id=run_id,
        db=db,
        until=until,
        success_text="the table is set, every drawer closed",
    )


def main_on_open_surfaces(**options: Any) -> int:
    """`pycram demo --scenario set-table-open`: :func:`main` with every object starting on an open
    surface (none in a closed container)."""
    return main(in_containers=False, **options)


def main_anywhere(environment: str = "apartment", **options: Any) -> int:
    """`pycram demo --scenario set-table-anywhere`: :func:`main` with the ``anywhere`` starts --
    all six breakfast types anywhere on the worktops and inside the containers, wherever some
    standing pose of the robot reaches them -- in `environment` (``--env procedural:SEED``)."""
    return main(starts="anywhere", environment=environment, **options)
