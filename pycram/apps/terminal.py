"""What the terminal front ends of the demo and the scenarios share (`pycram demo`): one rich
console on standard error for the live progress line and the log records, the plan's task tree
as `pycram show` draws it, the pictures of a recorded run, and how failures are told.

Failures are told short unless asked otherwise (`set_verbose`, the CLI's ``--verbose``): what
failed, why and what to try in at most two lines (`failure_text`, after
`pycram.failures.failure_summary`), and each failed task of the tree with the first line of
what really failed -- without the nested "Cannot resolve ..." layers. Verbose, the whole
message and every cause are shown; the trace database always keeps them whole.

Every function here is for people watching a run; none of them changes what a plan does.
"""

from __future__ import annotations

import dataclasses
import functools
import logging
from pathlib import Path
from typing import Any

from pycram.execution.failures import SUMMARY_LINE, failure_chain, failure_summary, innermost_clause

__all__ = [
    "STOP_PICTURE_SIZE",
    "stderr_console",
    "log_to_terminal",
    "task_tree_display",
    "write_run_pictures",
    "write_stop_pictures",
    "set_verbose",
    "is_verbose",
    "failure_text",
    "run_failure_text",
    "failure_hint",
]

#: Whether failures are told in full (`set_verbose`).
_VERBOSE = [False]

#: The offscreen size [px] a world needs for `write_stop_pictures` (the scene picture's views).
STOP_PICTURE_SIZE = (1200, 900)

log = logging.getLogger("pycram.demo")


@functools.cache
def stderr_console() -> Any:
    """The one rich console of the demo's terminal output (progress line and log records)."""
    from rich.console import Console

    return Console(stderr=True)


def log_to_terminal() -> None:
    """Show the demo's INFO records above the live progress line (rich keeps them apart)."""
    from rich.logging import RichHandler

    demo_log = logging.getLogger("pycram.demo")
    if not any(isinstance(h, RichHandler) for h in demo_log.handlers):
        demo_log.addHandler(RichHandler(console=stderr_console(), show_path=False, markup=False))
        demo_log.setLevel(logging.INFO)
        demo_log.propagate = False


def set_verbose(verbose: bool) -> None:
    """Tell failures in full (True: every message whole, every cause) or short (False, the
    default: `failure_text`)."""
    _VERBOSE[0] = bool(verbose)


def is_verbose() -> bool:
    """Whether failures are told in full (`set_verbose`)."""
    return _VERBOSE[0]


def failure_text(error: BaseException | str, verbose: bool | None = None) -> str:
    """How a terminal tells a failure: short (at most two lines of at most `SUMMARY_LINE`
    characters: what failed, why, what to try -- `pycram.failures.failure_summary`; a message
    given as text: its first line, cut) unless `verbose` (None: `is_verbose()`), then in full:
    the message, then every cause in the chain, one per line, innermost last."""
    verbose = is_verbose() if verbose is None else verbose
    if isinstance(error, str):
        if verbose:
            return error
        first = error.strip().split("\n", 1)[0]
        return first if len(first) <= SUMMARY_LINE else first[: SUMMARY_LINE - 1].rstrip() + "…"
    if not verbose:
        return failure_summary(error)
    lines = [f"{type(error).__name__}: {error}"]
    lines += [f"  caused by {type(e).__name__}: {e}" for e in list(failure_chain(error))[1:]]
    attempts = getattr(error, "attempts", None) or []
    lines += [f"  attempt {i}: {a}" for i, a in enumerate(attempts, 1)]
    return "\n".join(lines)


def run_failure_text(message: str, plan_task: Any = None) -> str:
    """The failure of a run for its last line: the exception of the plan's task told by
    `failure_text` when `message` ("Type: ...") is about it, else `message` told."""
    error = getattr(plan_task, "exception", None)
    if isinstance(error, BaseException) and message.startswith(f"{type(error).__name__}:"):
        return failure_text(error)
    return failure_text(message)


def failure_hint(type_name: str | None, reason: str | None = None) -> str:
    """What to try after a typed failure known by its class name (`pycram.failures`) and
    reason: its hint ("" for a name that is no typed failure)."""
    from pycram.execution import failures

    cls = getattr(failures, type_name or "", None)
    if not isinstance(cls, type) or not issubclass(cls, (failures.PlanFailure, failures.SimulationFault)):
        return ""
    if issubclass(cls, failures.PlanFailure):
        return cls.hints.get(reason or "", cls.default_hint)
    return cls.default_hint


def _short_errors(records: list) -> list:
    """`records` with each task's error cut to the first line of what really failed (no
    "Cannot resolve ..." layers, at most `SUMMARY_LINE` characters), unless verbose."""
    if is_verbose():
        return records
    out = []
    for r in records:
        message = getattr(r, "error_message", None)
        fields = {f.name for f in dataclasses.fields(r)} if dataclasses.is_dataclass(r) else set()
        if message and "error_message" in fields and not isinstance(r, type):
            short = innermost_clause(message)
            if len(short) > SUMMARY_LINE:
                short = short[: SUMMARY_LINE - 1].rstrip() + "…"
            r = dataclasses.replace(r, error_message=short)
        out.append(r)
    return out


def task_tree_display(plan_task: Any, run_id: Any, url: str | None, tree_text: str = "") -> Any:
    """The plan's task tree for the terminal: as `pycram show` draws it (repeated head motions
    on one line, with the blocking process-module executions when the run was recorded as
    `run_id`), or `tree_text` when the trace extra is not installed. Unless verbose
    (`set_verbose`), each failure shows the first line of what really failed (`pycram show`
    shows the whole message)."""
    if plan_task is None:
        return "(the plan did not start)"
    try:
        from pycram.trace.display import task_tree
        from pycram.trace.query import records_from_task
    except ImportError:
        return tree_text
    records = records_from_task(plan_task)
    if run_id is not None:
        records += _recorded_executions(run_id, url, records)
    tree, _ = task_tree("[bold]Task tree[/bold] [grey50](times: simulated clock)[/grey50]", _short_errors(records))
    return tree


def _recorded_executions(run_id: Any, url: str | None, records: list) -> list:
    """The recorded process-module executions below the plan's tasks (none if unreadable)."""
    from pycram.trace import query

    ids = {r.task_id for r in records}
    try:
        executions = [x for x in query.executions(run_id, url=url) if x.task_id in ids]
    except (query.TraceDatabaseError, query.RunNotFound) as error:
        log.warning("cannot read the process-module executions of run %s: %s", run_id, error)
        return []
    return query.execution_nodes(records, executions)


def write_run_pictures(run_id: Any, plan_task: Any, output: Path, url: str | None) -> list[Path]:
    """The task-tree SVG and timeline PNG of the recorded run `run_id`, into `output`; drawn from
    the plan's task in memory when the trace database cannot be read (a broken database never
    fails the demo)."""
    try:
        from pycram.trace.db import TraceDatabaseError
        from pycram.trace.pictures import write_run_pictures as write_pictures
        from pycram.trace.pictures import write_task_pictures
        from pycram.trace.query import RunNotFound
    except ImportError:
        return []
    try:
        return list(write_pictures(run_id, output, url=url))
    except (TraceDatabaseError, RunNotFound) as error:
        log.warning(
            "cannot read run %s back from the trace database (%s); drawing the pictures from memory",
            run_id,
            error,
        )
    if plan_task is None:
        return []
    return list(write_task_pictures(plan_task, output))


def write_stop_pictures(world: Any, belief: Any, plan_task: Any, folder: Path, title: str) -> list[Path]:
    """What a run looked like where it was stopped (`pycram demo --until T`), into `folder`:
    ``scene.png`` (the labelled scene: plan and overview, `write_scene_picture`), ``belief.png``
    (what the robot believed beside what was, `write_belief_picture`), ``task-tree.txt`` (the
    task tree so far as text: tasks still running have no end time), ``task-tree.svg`` and
    ``timeline.png``. `world` is a simulated world standing still (`World.hold_at`) built with an
    offscreen size of at least `STOP_PICTURE_SIZE`; `belief` the robot's belief (None: no
    belief picture). A picture that cannot be drawn is logged and left out; returns the paths
    written."""
    from pycram.apps.demos.belief_picture import write_belief_picture
    from pycram.apps.demos.scene_picture import write_scene_picture
    from pycram.core.runtime import format_task_tree

    folder.mkdir(parents=True, exist_ok=True)
    written: list[Path] = []
    if plan_task is not None:  # first: the tree as it stands, before anything else can change it
        tree = folder / "task-tree.txt"
        tree.write_text(format_task_tree(plan_task) + "\n", encoding="utf-8")
        written.append(tree)
    steps: list[tuple[str, Any]] = [("scene.png", lambda path: write_scene_picture(world, path, title=title))]
    if belief is not None:
        steps.append(("belief.png", lambda path: write_belief_picture(world, belief, path, title=f"{title}: belief")))
    for name, draw in steps:
        try:
            written.append(draw(folder / name))
        except Exception as error:  # noqa: BLE001 - a picture never fails the run
            log.warning("cannot draw %s: %s: %s", name, type(error).__name__, error)
    if plan_task is not None:
        try:
            from pycram.trace.pictures import write_task_pictures
        except ImportError:
            return written
        written.extend(write_task_pictures(plan_task, folder, title=title))
    return written
