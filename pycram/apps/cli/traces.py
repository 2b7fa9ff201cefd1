"""Inspecting recorded runs: `pycram runs`, `show`, `graph`, `timeline`."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import typer
from rich.markup import escape

from pycram.apps.cli.app import (
    COLLAPSE,
    DbOption,
    RunArgument,
    app,
    console,
    err,
    local_time,
    reading,
    write_errors,
)


@app.command("runs")
def runs_command(
    limit: int = typer.Option(20, "--limit", "-n", help="Show at most this many runs (0: all)."),
    plan: str | None = typer.Option(None, "--plan", help="Only runs whose plan name contains this."),
    db: str | None = DbOption,
) -> None:
    """List recorded runs, newest first: id, start, plan, robot, outcome, wall-clock duration
    and why a run failed."""
    from rich.table import Table

    from pycram.trace import query
    from pycram.trace.display import STATUS_STYLE, format_duration

    found = reading(db, query.runs, db, limit or None, plan)
    if not found:
        err.print("no runs recorded yet (run `pycram run FILE.py` or `pycram demo`)")
        return
    table = Table(box=None, pad_edge=False, header_style="bold")
    for name in ("id", "started", "plan", "robot", "outcome"):
        table.add_column(name, no_wrap=name != "plan")
    table.add_column("took", no_wrap=True, justify="right")
    table.add_column("reason", overflow="fold")
    for run in found:
        state = run.state
        style = STATUS_STYLE.get(state, "white")
        table.add_row(
            str(run.id),
            local_time(run.started_at),
            escape(run.plan or "–"),
            escape(run.robot or "–"),
            f"[{style}]{state}[/{style}]",
            format_duration(run.elapsed),
            escape(_reason(run)),
        )
    console.print(table)


def _reason(run: Any) -> str:
    """Why the run did not succeed (its recorded error), "" for a successful run."""
    if run.error:
        return run.error
    if run.state == "unfinished":
        return "the process ended without finishing the record (killed?)"
    return ""


@app.command("show")
def show_command(
    run: int | None = RunArgument,
    max_nodes: int = typer.Option(2000, "--max-nodes", help="Stop printing after this many tree lines."),
    expand: bool = typer.Option(
        False,
        "--expand",
        help="One line per task: do not collapse runs of identical successful siblings into one line (×N).",
    ),
    db: str | None = DbOption,
) -> None:
    """Print a run's task tree with statuses, durations and failures.

    Every process-module execution is shown (a blocking one under the task that performed it).
    A failure shows its error where it was raised; enclosing tasks it failed say "passed on".
    Tree times are on the plan's clock (the header says: simulated or wall clock); the run's
    duration and start are wall-clock. Runs of 3 or more consecutive identical successful
    sibling tasks (e.g. a motion repeated by a `whenever` loop) are shown as one line with a
    count, unless --expand.
    """
    from pycram.trace import query
    from pycram.trace.display import STATUS_STYLE, clock_label, format_duration, task_tree

    info = reading(db, query.get_run, run, db)
    records, execution_records = reading(db, query.tree_records, info.id, db)
    executions = reading(db, query.executions, info.id, url=db)
    state = info.state
    style = STATUS_STYLE.get(state, "white")
    title = (
        f"run {info.id}: {escape(info.plan or '–')} · robot {escape(info.robot or '–')} · "
        f"[{style}]{state}[/{style}] · took {format_duration(info.elapsed)} (wall-clock) · "
        f"started {local_time(info.started_at)}\n[grey50]times in the tree: {escape(clock_label(info.clock))}[/grey50]"
    )
    shown_records = records + execution_records
    tree, shown = task_tree(title, shown_records, expand=expand, max_nodes=max_nodes)
    console.print(tree)
    failed = [r for r in records if r.status == "failed"]
    raised = sum(1 for r in failed if not r.propagated)
    summary = f"{len(records)} tasks, {len(failed)} failed"
    if raised < len(failed):
        summary += f" ({raised} where the error was raised, {len(failed) - raised} passing it on)"
    if executions:
        summary += f", {len(executions)} process-module executions"
    if shown < len(shown_records):
        summary += f" ({len(shown_records) - shown} not shown; raise --max-nodes)"
    console.print(summary)
    if info.error:
        console.print(f"[red]{escape(info.error)}[/red]")
    if info.lost_records:
        console.print(
            f"[yellow]{info.lost_records} trace records of this run could not be written: "
            "the tree may be incomplete[/yellow]"
        )


@app.command("graph")
def graph_command(
    run: int | None = RunArgument,
    output: Path = typer.Option(Path("task-tree.svg"), "--output", "-o", help="SVG file to write."),
    expand: bool = typer.Option(False, "--expand", help="One box per task (do not collapse identical siblings)."),
    db: str | None = DbOption,
) -> None:
    """Draw a run's task tree as an SVG picture (identical successful siblings: one box ×N)."""
    from pycram.trace.pictures import write_tree_svg

    path = reading(db, write_errors, write_tree_svg, run, output, db, 0 if expand else COLLAPSE)
    console.print(f"wrote {path}")


@app.command("timeline")
def timeline_command(
    run: int | None = RunArgument,
    output: Path = typer.Option(Path("timeline.png"), "--output", "-o", help="PNG file to write."),
    max_rows: int = typer.Option(200, "--max-rows", help="At most this many task rows (deeper tasks are left out)."),
    expand: bool = typer.Option(
        False, "--expand", help="One row per task (do not share rows between identical siblings)."
    ),
    db: str | None = DbOption,
) -> None:
    """Draw which branches ran when (a Gantt chart, one row per task; identical successful
    siblings share a row) as a PNG picture."""
    from pycram.trace.pictures import write_timeline_png

    path = reading(db, write_errors, write_timeline_png, run, output, db, max_rows, 0 if expand else COLLAPSE)
    console.print(f"wrote {path}")


# -- running plans --------------------------------------------------------------------------------
