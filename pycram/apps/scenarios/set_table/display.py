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
from pycram.apps.scenarios.set_table.data import OBJECTS
from pycram.apps.scenarios.set_table.driver import _check, record_replay_info, run_scenario
from pycram.apps.scenarios.set_table.judge import SetTableResult
from pycram.world.robot_registry import DEFAULT_ROBOT

__all__ = ["main", "main_on_open_surfaces"]


def _output_folder(robot: str, seed: int, run_id: Any) -> Path:
    stem = f"set-table-{robot}-{seed}"
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
) -> int:
    """`pycram demo --scenario set-table`: run the scenario with live progress, print the task
    tree and what is missing and why; write start/end pictures (and run.gif with `animation`),
    the task-tree SVG and the timeline of the recorded run. With `until` [s of simulated time]:
    stop there and write the scene and belief pictures and the task tree of that moment. Returns
    the exit code: 0 only when every object is at its place setting and every drawer closed, or
    when the run was stopped at `until` and its pictures written; 2 for bad options; else 1."""
    import os

    from rich.console import Console
    from rich.live import Live
    from rich.markup import escape

    from pycram.apps.scenarios.set_table.plan import current_object, objects_done
    from pycram.apps.terminal import (
        failure_hint,
        failure_text,
        log_to_terminal,
        stderr_console,
        task_tree_display,
        write_run_pictures,
    )

    os.environ.setdefault("MUJOCO_GL", "egl")
    console = Console()
    try:
        kinds = _check(robot, seed, faults)
        stepping = check_stepping(stepping)
        check_until(until)
    except ValueError as error:
        console.print(f"[bold red]pycram demo:[/bold red] {error}", highlight=False, soft_wrap=True)
        return 2
    if not quiet:
        log_to_terminal()
    recorder = None
    if record:
        from pycram.trace import start_recording

        recorder = start_recording(url=db, plan=f"set table ({robot}, seed {seed})")
    run_id = recorder.run_id if recorder is not None else None
    folder = Path(output) if output else _output_folder(robot, seed, run_id)
    live = None if quiet else Live("", console=stderr_console(), refresh_per_second=4, transient=False)

    def progress(world: Any, plan: Any, injector: Any) -> None:
        if live is None:
            return
        current = current_object.get_value()
        live.update(
            f"objects done: {objects_done.get_value()}/{len(OBJECTS)}  "
            f"{'bringing the ' + current if current else 'between objects':<22}  "
            f"faults: {len(injector.injected)}  sim {world.sim_time.get_value():6.1f} s"
        )

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
        )
    finally:
        if live is not None:
            live.stop()
        if recorder is not None:
            record_replay_info(
                recorder, result, task, in_containers=in_containers, stepping=stepping, pictures=True, until=until
            )
            ok = result is not None and result.success
            stopped = result is not None and result.stopped_at is not None
            run_id = recorder.finish(
                "succeeded" if ok else "interrupted" if stopped else "failed",
                None if ok else (result.summary() if result else "error"),
            )
    files = [folder / n for n in ("start.png", "end.png", "run.gif") if (folder / n).exists()]
    if recorder is not None:
        files += write_run_pictures(run_id, task, folder, recorder.url)
    console.print()
    console.print(task_tree_display(task, run_id, db))
    assert result is not None
    console.print(
        f"\nthe plan simulated {result.sim_time:.1f} s; the whole run took {result.wall_time:.1f} s of wall time"
    )
    for name, obj in result.objects.items():
        mark = (
            "[green]placed[/green]"
            if obj.placed
            else f"[red]missing[/red] ({obj.failure or 'not at its place'}: {escape(failure_text(obj.reason))})"
        )
        console.print(f"  {name}: {mark}", highlight=False)
    if result.faults_injected:
        console.print("faults: " + "; ".join(result.faults_injected), highlight=False)
    console.print(f"pictures in {folder.resolve()}: " + ", ".join(p.name for p in files))
    if run_id is not None:
        console.print(f"recorded as run {run_id} (see `pycram show {run_id}`)")
    if result.stopped_at is not None:
        console.print(
            f"[bold yellow]STOPPED[/bold yellow] at t={result.stopped_at:.2f} s of simulated time (--until {until:g}): "
            f"the scene, the belief and the task tree of that moment are in {result.stop_folder}",
            highlight=False,
        )
        return 0
    if result.success:
        console.print("[bold green]SUCCESS[/bold green]: the table is set, every drawer closed")
        return 0
    console.print(f"[bold red]FAILURE[/bold red]: {escape(failure_text(result.summary()))}", highlight=False)
    failed = [o.failure for o in result.objects.values() if o.failure]
    first = result.error.split(":")[0] if result.error else (failed[0] if failed else None)
    if failure_hint(first):
        console.print(f"  try: {escape(failure_hint(first))}", highlight=False)
    return 1


def main_on_open_surfaces(**options: Any) -> int:
    """`pycram demo --scenario set-table-open`: :func:`main` with every object starting on an open
    surface (none in a closed container)."""
    return main(in_containers=False, **options)
