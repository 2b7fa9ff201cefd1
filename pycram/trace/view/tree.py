"""The task tree in a view: each task's status over time, its failures, the current action.

`TreeLog` keeps the tasks it was told about (`change`) and logs, on the recording's current
times:

- ``tree/status``: one text-log row per status change (running, succeeded, failed, evaporated;
  level INFO, DEBUG, ERROR, WARN), so the viewer's text log lists -- and filters -- them
  (noted by `change`, logged in columns by `flush`);
- ``tree/failures``: each failure once, in the task it was raised in, with its typed reason;
- ``tree/graph``: the task tree as a graph (nodes coloured by status), at most every
  `graph_period` [s of the sim timeline] and at the end;
- ``plan/current``: the running tasks as an indented tree, the current action (the innermost
  running plan or action task), motion (a running process module) and object.

The live view (`pycram.trace.view.session`) and the view rebuilt from the trace database
(`pycram.trace.view.from_db`) both use it, so both show the same thing.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from . import paths

__all__ = ["TreeLog", "TaskState", "STATUS_COLORS", "STATUS_LEVELS"]

#: RGB of each status in the graph and the text log.
STATUS_COLORS = {
    "created": (150, 150, 150),
    "running": (66, 133, 244),
    "suspended": (171, 71, 188),
    "succeeded": (67, 160, 71),
    "failed": (229, 57, 53),
    "evaporated": (251, 140, 0),
}
#: The text-log level of each status change.
STATUS_LEVELS = {
    "created": "TRACE",
    "running": "INFO",
    "suspended": "INFO",
    "succeeded": "DEBUG",
    "failed": "ERROR",
    "evaporated": "WARN",
}
#: Task kinds that are actions of a plan (the current action is the innermost running one).
ACTION_KINDS = frozenset({"plan", "action"})
#: Most nodes the graph shows (the first tasks of a run, in the order they started).
GRAPH_LIMIT = 600


@dataclass
class TaskState:
    """What the view knows of one task."""

    task_id: int
    parent_id: int | None
    name: str
    kind: str | None
    path: str | None
    status: str = "created"
    error: str | None = None


class TreeLog:
    """Logs a task tree into `recording` (a `rerun.RecordingStream`); see the module docstring.
    `objects()` returns the names of the objects the robot believes in (to name the current
    object); `graph_period` [s]: the graph is logged at most this often."""

    def __init__(self, recording: Any, objects: Any = None, graph_period: float = 1.0) -> None:
        self.rec = recording
        self.tasks: dict[int, TaskState] = {}
        self.children: dict[int | None, list[int]] = {}
        self.running: dict[int, None] = {}  # ordered set
        self.changes = 0
        self.objects = objects or (lambda: ())
        self.graph_period = graph_period
        self._graph_logged_at = -1e18
        self._graph_dirty = False
        self._current_text = ""
        self._current_dirty = True
        self._rows: list[tuple[float, float, str, str]] = []  # status changes not logged yet

    def change(
        self,
        time: float,
        wall: float,
        task_id: int,
        parent_id: int | None,
        name: str,
        kind: str | None,
        path: str | None,
        status: str,
        error: str | None = None,
        origin: bool = False,
    ) -> None:
        """Note that task `task_id` has `status` since `time` [s of the sim timeline] (`wall`: the
        wall-clock time [s since the epoch]): one row in ``tree/status`` (logged by `flush`, in
        columns); a failure `error` ("Type: message") raised in this very task (`origin`) also
        one in ``tree/failures`` (at once: the recording's times must be set)."""
        import rerun as rr

        state = self.tasks.get(task_id)
        if state is None:
            state = self.tasks[task_id] = TaskState(task_id, parent_id, name, kind, path)
            self.children.setdefault(parent_id, []).append(task_id)
        state.status = status
        state.error = error
        if status == "running":
            self.running[task_id] = None
        else:
            self.running.pop(task_id, None)
        self.changes += 1
        shown = path or name
        text = f"{status:<10} {shown}" + (f" -- {error}" if error else "")
        self._rows.append((float(time), float(wall), text, status))
        if error and origin and status == "failed":
            self.rec.log(paths.TREE_FAILURES, rr.TextLog(f"{error}  (in {shown})", level="ERROR"))
        self._graph_dirty = True
        self._current_dirty = True

    def flush(self) -> int:
        """Log the status changes noted since the last flush into ``tree/status`` (one Rerun call);
        returns how many rows that was."""
        import rerun as rr

        rows, self._rows = self._rows, []
        if rows:
            grey = (150, 150, 150)
            self.rec.send_columns(
                paths.TREE_STATUS,
                indexes=[
                    rr.TimeColumn(paths.SIM_TIMELINE, duration=[r[0] for r in rows]),
                    rr.TimeColumn(paths.WALL_TIMELINE, timestamp=[r[1] for r in rows]),
                ],
                columns=rr.TextLog.columns(
                    text=[r[2] for r in rows],
                    level=[STATUS_LEVELS.get(r[3], "INFO") for r in rows],
                    color=[STATUS_COLORS.get(r[3], grey) for r in rows],
                ),
            )
        return len(rows)

    # -- summaries (logged at the caller's pace) ---------------------------------------------------

    def log_current(self) -> None:
        """Log ``plan/current`` if it changed (a task's status changed since the last call, and
        the text with it): the current action, motion and object, and the running tasks as an
        indented tree."""
        import rerun as rr

        if not self._current_dirty:
            return
        self._current_dirty = False
        running = [self.tasks[i] for i in self.running]
        action = next((t for t in reversed(running) if t.kind in ACTION_KINDS), None)
        motion = next((t for t in reversed(running) if t.kind == "process-module"), None)
        names = [n for n in self.objects() if n]
        text_of_tasks = " ".join(t.name for t in running)
        obj = next((n for n in names if n in text_of_tasks), None)
        lines = [
            f"**action:** {action.name if action else '-'}  ",
            f"**motion:** {motion.name if motion else '-'}  ",
            f"**object:** {obj or '-'}",
            "",
            "running tasks:",
            "",
        ]
        depth: dict[int | None, int] = {}
        for task in running:
            level = depth.get(task.parent_id, -1) + 1
            depth[task.task_id] = level
            lines.append(f"{'    ' * level}- {task.name} ({task.kind or 'task'})")
        text = "\n".join(lines)
        if text != self._current_text:
            self._current_text = text
            self.rec.log(paths.CURRENT, rr.TextDocument(text, media_type="text/markdown"))

    def log_graph(self, now: float, force: bool = False) -> None:
        """Log ``tree/graph`` when the tree changed and `graph_period` passed since the last time
        (or with `force`): nodes (task name, coloured by status) and parent -> child edges."""
        import rerun as rr

        if not self._graph_dirty or (not force and now - self._graph_logged_at < self.graph_period):
            return
        self._graph_dirty = False
        self._graph_logged_at = now
        shown = list(self.tasks.values())[:GRAPH_LIMIT]
        ids = {t.task_id for t in shown}
        self.rec.log(
            paths.TREE_GRAPH,
            rr.GraphNodes(
                [str(t.task_id) for t in shown],
                labels=[t.name for t in shown],
                colors=[STATUS_COLORS.get(t.status, (150, 150, 150)) for t in shown],
            ),
            rr.GraphEdges(
                [(str(t.parent_id), str(t.task_id)) for t in shown if t.parent_id in ids],
                graph_type="directed",
            ),
        )
