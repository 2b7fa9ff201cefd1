"""`pycram demo --scenario NAME` in the terminal, for every scenario: a live progress line while
the run goes on, then the task tree, each object done or not and why, the faults injected and the
pictures written, and the exit code.

`live_line`, `finish_recording` and `report_run` are the pieces set-table's front end
(`pycram.apps.scenarios.set_table.display`) and the household tasks' share; `task_demo(task)`
makes the whole front end of one `TaskScenario`. Exit codes: 0 only when the task is done (or the
run was stopped at ``until`` and its pictures written); 2 for bad options; else 1.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from pycram.apps.run_options import check_stepping, check_until
from pycram.apps.scenarios.common.driver import TaskScenario, check_task_inputs, record_task_replay_info, run_task
from pycram.world.robot_registry import DEFAULT_ROBOT

__all__ = ["Marks", "begin", "live_line", "finish_recording", "report_run", "task_demo"]


@dataclass(frozen=True)
class Marks:
    """How `report_run` marks each object: `done` or `not_done`, and what a failure without a type
    is called (`unnamed`)."""

    done: str = "placed"
    not_done: str = "missing"
    unnamed: str = "not at its place"


def begin(
    console: Any, checks: Callable[[], Any], *, quiet: bool, record: bool, db: str | None, title: str
) -> tuple[Any, Any] | None:
    """Start a demo run: `checks()` (its value is returned; a `ValueError` it raises is printed
    as ``pycram demo: ...`` and None returned: exit code 2), the log on the terminal unless
    `quiet`, and with `record` a recording into the trace database `db` (None: the default)
    titled `title`. Returns (what `checks` returned, the recorder or None)."""
    from pycram.apps.terminal import log_to_terminal

    try:
        checked = checks()
    except ValueError as error:
        console.print(f"[bold red]pycram demo:[/bold red] {error}", highlight=False, soft_wrap=True)
        return None
    if not quiet:
        log_to_terminal()
    recorder = None
    if record:
        from pycram.trace import start_recording

        recorder = start_recording(url=db, plan=title)
    return checked, recorder


def live_line(quiet: bool, total: int) -> tuple[Any, Callable[[Any, Any, Any], None]]:
    """A live progress line (a `rich.live.Live` on stderr, not started; None when `quiet`) and the
    ``progress(world, plan, faults)`` function that updates it: objects done of `total`, the one
    being brought, the faults injected, the simulated time."""
    from rich.live import Live

    from pycram.apps.scenarios.set_table.plan import current_object, objects_done
    from pycram.apps.terminal import stderr_console

    live = None if quiet else Live("", console=stderr_console(), refresh_per_second=4, transient=False)

    def progress(world: Any, plan: Any, injector: Any) -> None:
        if live is None:
            return
        current = current_object.get_value()
        live.update(
            f"objects done: {objects_done.get_value()}/{total}  "
            f"{'bringing the ' + current if current else 'between objects':<22}  "
            f"faults: {len(injector.injected)}  sim {world.sim_time.get_value():6.1f} s"
        )

    return live, progress


def finish_recording(recorder: Any, result: Any) -> Any:
    """End the recorded run as succeeded, interrupted (stopped at ``until``) or failed (with the
    result's summary); returns its id."""
    ok = result is not None and result.success
    stopped = result is not None and result.stopped_at is not None
    return recorder.finish(
        "succeeded" if ok else "interrupted" if stopped else "failed",
        None if ok else (result.summary() if result else "error"),
    )


def report_run(
    console: Any,
    result: Any,
    task: Any,
    *,
    folder: Path,
    recorder: Any,
    run_id: Any,
    db: str | None,
    until: float | None,
    success_text: str,
    where: str | None = None,
    marks: Marks = Marks(),
) -> int:
    """After a run: the pictures of the recorded run into `folder`, the task tree, how long it took
    (in `where`, when given), each object marked with `marks`, the faults, the pictures and the
    run's id; then SUCCESS (`success_text`), STOPPED or FAILURE with a hint. Returns the exit code."""
    from rich.markup import escape

    from pycram.apps.terminal import failure_hint, failure_text, task_tree_display, write_run_pictures

    files = [folder / n for n in ("start.png", "end.png", "run.gif") if (folder / n).exists()]
    if recorder is not None:
        files += write_run_pictures(run_id, task, folder, recorder.url)
    console.print()
    console.print(task_tree_display(task, run_id, db))
    assert result is not None
    console.print(
        f"\nthe plan simulated {result.sim_time:.1f} s{' in ' + where if where else ''}; "
        f"the whole run took {result.wall_time:.1f} s of wall time"
    )
    for name, obj in result.objects.items():
        mark = (
            f"[green]{marks.done}[/green]"
            if obj.placed
            else f"[red]{marks.not_done}[/red] ({obj.failure or marks.unnamed}: {escape(failure_text(obj.reason))})"
        )
        console.print(f"  {name}: {mark}", highlight=False)
    if result.faults_injected:
        console.print("faults: " + "; ".join(result.faults_injected), highlight=False)
    console.print(f"pictures in {folder.resolve()}: " + ", ".join(p.name for p in files))
    if run_id is not None:
        console.print(f"recorded as run {run_id} (see `pycram show {run_id}`)")
    if result.stopped_at is not None:
        assert until is not None
        console.print(
            f"[bold yellow]STOPPED[/bold yellow] at t={result.stopped_at:.2f} s of simulated time (--until {until:g}): "
            f"the scene, the belief and the task tree of that moment are in {result.stop_folder}",
            highlight=False,
        )
        return 0
    if result.success:
        console.print(f"[bold green]SUCCESS[/bold green]: {success_text}")
        return 0
    console.print(f"[bold red]FAILURE[/bold red]: {escape(failure_text(result.summary()))}", highlight=False)
    failed = [o.failure for o in result.objects.values() if o.failure]
    first = result.error.split(":")[0] if result.error else (failed[0] if failed else None)
    if failure_hint(first):
        console.print(f"  try: {escape(failure_hint(first))}", highlight=False)
    return 1


def task_demo(task: TaskScenario) -> Callable[..., int]:
    """The terminal front end of `task` for `pycram demo --scenario NAME` (see the module
    docstring)."""

    def main(
        robot: str = DEFAULT_ROBOT,
        seed: int = 0,
        faults: str | frozenset[str] = "",
        output: str | None = None,
        db: str | None = None,
        record: bool = True,
        quiet: bool = False,
        animation: bool = True,
        stepping: str | None = None,
        until: float | None = None,
        environment: str | None = None,
        objects: tuple[str, ...] | None = None,
    ) -> int:
        import os

        from rich.console import Console

        os.environ.setdefault("MUJOCO_GL", "egl")
        console = Console()
        where = environment or task.environment

        def checks() -> str:
            check_task_inputs(task, robot, seed, faults, where)
            check_until(until)
            return check_stepping(stepping)

        title = f"{task.title} ({robot}, seed {seed}, {where})"
        started = begin(console, checks, quiet=quiet, record=record, db=db, title=title)
        if started is None:
            return 2
        stepping, recorder = started
        run_id = recorder.run_id if recorder is not None else None
        stem = f"{task.name}-{robot}-{seed}" + ("" if where == task.environment else f"-{where.replace(':', '')}")
        folder = Path(output) if output else Path("output") / f"{stem}-{run_id or time.strftime('%Y%m%d-%H%M%S')}"
        live, progress = live_line(quiet, len(objects) if objects else task.count)
        result = None
        plan_task = None
        try:
            if live is not None:
                live.start()
            result, plan_task = run_task(
                task,
                robot,
                seed,
                faults,
                environment=where,
                objects=objects,
                recorder=recorder,
                output=folder,
                animation=animation,
                progress=progress,
                stepping=stepping,
                until=until,
            )
        finally:
            if live is not None:
                live.stop()
            if recorder is not None:
                record_task_replay_info(
                    recorder, task, result, plan_task, objects=objects, stepping=stepping, pictures=True, until=until
                )
                run_id = finish_recording(recorder, result)
        return report_run(
            console,
            result,
            plan_task,
            folder=folder,
            recorder=recorder,
            run_id=run_id,
            db=db,
            until=until,
            success_text=result.done_text if result is not None else "",
            where=where,
            marks=Marks("done", "not done", "not where it belongs"),
        )

    main.__doc__ = (
        f"`pycram demo --scenario {task.name}`: {task.title}, with live progress; the task tree and what is "
        "not done and why; start/end pictures (run.gif with `animation`), the task-tree SVG and the timeline "
        "of the recorded run. Returns the exit code: 0 on success, 2 for bad options, else 1."
    )
    return main
