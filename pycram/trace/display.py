"""The task tree in the terminal: a rich `Tree` with statuses, durations and failures.

Used by `pycram show` (a recorded run) and `pycram demo` (the run that just ended). Runs of
identical successful siblings -- a `whenever` loop moving the head every 0.2 s -- are one line
"✔ head: pointing_head ×83" unless `expand` (see `pycram.trace.collapse`). A failure shows its
error where it was raised; the enclosing tasks it failed on its way up say "passed on from"
that task (see `TaskRecord.error_origin`).
"""

from __future__ import annotations

from collections.abc import Sequence

from rich.markup import escape
from rich.tree import Tree

__all__ = ["STATUS_STYLE", "STATUS_MARK", "format_duration", "task_tree", "clock_label"]

#: rich style per task or run status.
STATUS_STYLE = {
    "succeeded": "green",
    "failed": "bold red",
    "evaporated": "grey62",
    "running": "blue",
    "unfinished": "yellow",
    "interrupted": "yellow",
    "created": "grey50",
    "suspended": "magenta",
}
#: One-character mark per task status.
STATUS_MARK = {"succeeded": "✔", "failed": "✘", "evaporated": "~", "running": "▶", "created": "·", "suspended": "‖"}


def format_duration(seconds: float | None) -> str:
    """`seconds` [s] in a unit that suits it (µs, ms, s, min); "–" when unknown."""
    if seconds is None:
        return "–"
    if seconds < 1e-3:
        return f"{seconds * 1e6:.0f} µs"
    if seconds < 1:
        return f"{seconds * 1000:.1f} ms"
    if seconds < 120:
        return f"{seconds:.2f} s"
    return f"{seconds / 60:.1f} min"


_CLOCK_NAMES = {"wall-clock": "wall clock", "simulated": "simulated clock"}


def clock_label(clock: str | None) -> str:
    """What the task times of a run are, for a reader: "simulated", "wall-clock", ..."""
    if not clock:
        return "the plan's clock (simulated or wall-clock: not recorded for this run)"
    kinds = [_CLOCK_NAMES.get(kind, f"{kind} clock") for kind in clock.split("+")]
    if len(kinds) == 1:
        return kinds[0]
    return "mixed: " + " and ".join(kinds) + " (the active clock changed during the run)"


def _label(node, names: dict[int, str]) -> str:
    """One tree line for a display node (`pycram.trace.collapse.DisplayNode`); `names`: task
    names by id (for "passed on from")."""
    record = node.record
    if record.kind == "root":
        return f"[bold]{escape(record.name)}[/bold] [grey50](thread)[/grey50]"
    style = STATUS_STYLE.get(record.status, "white")
    times = f" ×{node.count}" if node.count > 1 else ""
    text = (
        f"[{style}]{STATUS_MARK.get(record.status, '?')}[/{style}] {escape(record.name)}{times} "
        f"[grey50]\\[{escape(record.kind or 'task')}][/grey50] [{style}]{record.status}[/{style}] "
    )
    if node.count > 1:
        low, high = node.duration_range or (None, None)
        text += f"{format_duration(node.total_duration)} in all ({format_duration(low)} – {format_duration(high)} each)"
    else:
        text += format_duration(record.duration)
    if record.error_type and record.status != "succeeded":
        if record.propagated:
            origin = names.get(record.error_origin, f"task {record.error_origin}")
            text += f" [red]— {escape(record.error_type)} passed on from {escape(origin)}[/red]"
        else:
            text += f" [red]— {escape(record.error or '')}[/red]"
    return text


def task_tree(title: str, records: Sequence, expand: bool = False, max_nodes: int = 2000) -> tuple[Tree, int]:
    """A rich tree of the task `records` (`pycram.trace.query.TaskRecord`) under `title`.

    Returns the tree and how many records it shows (fewer than `len(records)` once
    `max_nodes` lines were added). `title` is rich markup. Records may include process-module
    executions (`pycram.trace.query.execution_nodes`).
    """
    from pycram.trace.collapse import MIN_RUN, collapse
    from pycram.trace.query import build_tree

    tree = Tree(title)
    lines = tasks_shown = 0
    branches: dict[int, Tree] = {}
    names = {r.task_id: r.name for r in records}
    for root in collapse(build_tree(records), min_run=0 if expand else MIN_RUN):
        for node, _depth in root.walk():
            if lines >= max_nodes:
                break
            parent_id = node.record.parent_id
            parent = branches.get(parent_id) if parent_id is not None else None
            branch = (parent or tree).add(_label(node, names))
            for member in node.records:
                branches[member.task_id] = branch
            lines += 1
            tasks_shown += node.count
    return tree, tasks_shown
