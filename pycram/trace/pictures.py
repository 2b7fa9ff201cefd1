"""Pictures of runs: the task tree as SVG (pure Python) and a timeline (Gantt chart) as PNG.

- `tree_svg(records)` / `write_tree_svg(run_id, path)`: the task tree, left to right, one box per
  task colored by status, with duration and failure; hover a box for its path and error. No
  graphviz needed.
- `timeline_png(records, path)` / `write_timeline_png(run_id, path)`: one row per task, a bar
  from its start to its end colored by status (matplotlib, Agg backend, no display needed), so
  concurrent branches, retries and evaporations are visible at a glance.
- Pictures of a recorded run show every process-module execution, the blocking ones (which
  are no task of their own) as children of the task that performed them.
- Both draw a run of identical successful siblings (a `whenever` loop repeating a motion) as one
  box / one row "name ×N" (`pycram.trace.collapse`; pass `min_run=0` for one per task). The
  stored trace is never changed.
- `write_run_pictures(run_id, folder, url=None)`: both into `folder` (`task-tree.svg`,
  `timeline.png`); `write_task_pictures(task, folder)` does the same from an in-memory task.

Records come from `pycram.trace.query.tasks` or `records_from_task` (no database needed).
"""

from __future__ import annotations

import logging
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import Any
from xml.sax.saxutils import escape

from pycram.trace.collapse import MIN_RUN, DisplayNode, collapse
from pycram.trace.display import format_duration
from pycram.trace.query import TaskRecord, build_tree

log = logging.getLogger(__name__)

__all__ = [
    "STATUS_COLORS",
    "tree_svg",
    "write_tree_svg",
    "timeline_png",
    "write_timeline_png",
    "write_run_pictures",
    "write_task_pictures",
]

#: Fill colors per task status (also used by the CLI).
STATUS_COLORS = {
    "succeeded": "#4caf50",
    "failed": "#e53935",
    "evaporated": "#9e9e9e",
    "running": "#1e88e5",
    "created": "#cfd8dc",
    "suspended": "#8e24aa",
    "thread": "#607d8b",
}
_LIGHT = {
    "succeeded": "#e8f5e9",
    "failed": "#ffebee",
    "evaporated": "#f5f5f5",
    "running": "#e3f2fd",
    "created": "#fafafa",
    "suspended": "#f3e5f5",
    "thread": "#eceff1",
}


def _clip(text: str, limit: int) -> str:
    return text if len(text) <= limit else text[: limit - 1] + "…"


def _status_of(record: TaskRecord) -> str:
    """The status to show: a thread's root task never ends, it is shown as "thread"."""
    return "thread" if record.kind == "root" else record.status


# -- task tree (SVG) ------------------------------------------------------------------------------

_CHAR_W = 6.6  # approximate width of one character at font-size 11 [px]
_ROW_H = 38
_BOX_H = 30
_GAP_X = 28


def _group_detail(node: DisplayNode) -> str:
    r = node.record
    if r.kind == "root":
        return "thread"
    if node.count > 1:
        return f"{r.kind or 'task'} · {_status_of(r)} · {node.count} × ≈{format_duration(_mean(node))}"
    detail = f"{r.kind or 'task'} · {_status_of(r)} · {format_duration(r.duration)}"
    if r.error_type and r.status != "succeeded":
        detail += f" · {r.error_type}"
    return detail


def _mean(node: DisplayNode) -> float | None:
    total = node.total_duration
    known = sum(1 for r in node.records if r.duration is not None)
    return total / known if total is not None and known else None


def tree_svg(
    records: Iterable[TaskRecord], title: str | None = None, max_label: int = 48, min_run: int = MIN_RUN
) -> str:
    """An SVG document (string) drawing the task tree of `records`, left to right.

    Runs of at least `min_run` consecutive identical successful siblings are drawn as one
    stacked box labelled "name ×N" (see `pycram.trace.collapse`; `min_run=0`: one box per task).
    """
    roots = collapse(build_tree(records), min_run=min_run)
    lines1: dict[int, str] = {}
    lines2: dict[int, str] = {}
    depth_of: dict[int, int] = {}
    order: list[DisplayNode] = []
    for root in roots:
        for node, depth in root.walk():
            key = id(node)
            depth_of[key] = depth
            order.append(node)
            suffix = f" ×{node.count}" if node.count > 1 else ""
            lines1[key] = _clip(node.record.name, max_label - len(suffix)) + suffix
            lines2[key] = _clip(_group_detail(node), max_label + 10)
    if not order:
        return (
            '<svg xmlns="http://www.w3.org/2000/svg" width="300" height="60">'
            '<text x="10" y="35" font-family="sans-serif" font-size="13">no tasks recorded</text></svg>\n'
        )
    # column widths per depth
    widths: dict[int, float] = {}
    for node in order:
        key = id(node)
        w = max(len(lines1[key]) * (_CHAR_W + 0.6), len(lines2[key]) * (_CHAR_W - 0.8)) + 16
        widths[depth_of[key]] = max(widths.get(depth_of[key], 0.0), w)
    x_of_depth: dict[int, float] = {}
    x = 10.0
    for depth in range(max(widths) + 1):
        x_of_depth[depth] = x
        x += widths.get(depth, 0) + _GAP_X
    total_w = x + 10
    top = 40.0 if title else 10.0
    # y: leaves take consecutive rows, parents centre on their children (post-order, iterative)
    y_of: dict[int, float] = {}
    row = 0
    stack: list[tuple[DisplayNode, bool]] = [(root, False) for root in reversed(roots)]
    while stack:
        node, expanded = stack.pop()
        if not node.children:
            y_of[id(node)] = top + row * _ROW_H
            row += 1
        elif not expanded:
            stack.append((node, True))
            stack.extend((child, False) for child in reversed(node.children))
        else:
            y_of[id(node)] = (y_of[id(node.children[0])] + y_of[id(node.children[-1])]) / 2
    total_h = top + row * _ROW_H + 10
    out: list[str] = [
        f'<svg xmlns="http://www.w3.org/2000/svg" width="{total_w:.0f}" height="{total_h:.0f}" '
        f'viewBox="0 0 {total_w:.0f} {total_h:.0f}" font-family="DejaVu Sans, Helvetica, Arial, sans-serif">',
        '<rect width="100%" height="100%" fill="white"/>',
    ]
    if title:
        out.append(f'<text x="10" y="26" font-size="15" font-weight="bold">{escape(title)}</text>')
    out.append('<g fill="none" stroke="#90a4ae" stroke-width="1.2">')
    for node in order:
        if not node.children:
            continue
        depth = depth_of[id(node)]
        x0 = x_of_depth[depth] + widths[depth]
        y0 = y_of[id(node)] + _BOX_H / 2
        for child in node.children:
            x1 = x_of_depth[depth_of[id(child)]]
            y1 = y_of[id(child)] + _BOX_H / 2
            xm = x0 + _GAP_X / 2
            out.append(f'<path d="M{x0:.1f},{y0:.1f} H{xm:.1f} V{y1:.1f} H{x1:.1f}"/>')
    out.append("</g>")
    for node in order:
        r = node.record
        key = id(node)
        status = _status_of(r)
        depth = depth_of[key]
        bx, by = x_of_depth[depth], y_of[key]
        stroke = STATUS_COLORS.get(status, "#607d8b")
        fill = _LIGHT.get(status, "#ffffff")
        if node.count > 1:
            low, high = node.duration_range or (None, None)
            tip = (
                f"{r.path or r.name} (and {node.count - 1} identical siblings)\n{status}, "
                f"{node.count} tasks, {format_duration(node.total_duration)} in all, "
                f"{format_duration(low)} – {format_duration(high)} each"
            )
        else:
            tip = f"{r.path or r.name}\n{status}, {format_duration(r.duration)}"
            if r.error:
                tip += f"\n{r.error}"
        css = f"task {status}" + (" group" if node.count > 1 else "")
        out.append(f'<g class="{escape(css)}"><title>{escape(tip)}</title>')
        if node.count > 1:  # a stack of cards
            out.append(
                f'<rect x="{bx + 4:.1f}" y="{by + 4:.1f}" width="{widths[depth]:.1f}" height="{_BOX_H}" '
                f'rx="4" fill="{fill}" stroke="{stroke}" stroke-width="1"/>'
            )
        out.append(
            f'<rect x="{bx:.1f}" y="{by:.1f}" width="{widths[depth]:.1f}" height="{_BOX_H}" rx="4" '
            f'fill="{fill}" stroke="{stroke}" stroke-width="1.6"/>'
        )
        out.append(f'<rect x="{bx:.1f}" y="{by:.1f}" width="5" height="{_BOX_H}" rx="2" fill="{stroke}"/>')
        out.append(
            f'<text x="{bx + 10:.1f}" y="{by + 13:.1f}" font-size="11" fill="#212121">{escape(lines1[key])}</text>'
        )
        out.append(
            f'<text x="{bx + 10:.1f}" y="{by + 25:.1f}" font-size="9" fill="#546e7a">{escape(lines2[key])}</text>'
        )
        out.append("</g>")
    out.append("</svg>")
    return "\n".join(out) + "\n"


# -- timeline (PNG) -------------------------------------------------------------------------------


def _rows_for_timeline(
    records: Sequence[TaskRecord], max_rows: int, min_run: int = MIN_RUN
) -> tuple[list[tuple[DisplayNode, int]], int]:
    """Depth-first rows (without thread roots; identical successful siblings share a row), cut
    at the deepest level that fits `max_rows`. Returns the rows and the number of tasks left out."""
    rows: list[tuple[DisplayNode, int]] = []
    for root in collapse(build_tree(records), min_run=min_run):
        for node, depth in root.walk():
            if node.record.kind == "root":
                continue
            rows.append((node, depth))
    if len(rows) <= max_rows:
        return rows, 0
    depths = sorted({d for _, d in rows})
    chosen = [(n, d) for n, d in rows if d <= depths[0]][:max_rows]
    for limit in depths:
        candidate = [(n, d) for n, d in rows if d <= limit]
        if len(candidate) > max_rows:
            break
        chosen = candidate
    total = sum(n.count for n, _ in rows)
    return chosen, total - sum(n.count for n, _ in chosen)


def timeline_png(
    records: Sequence[TaskRecord],
    path: str | Path,
    title: str | None = None,
    max_rows: int = 200,
    end_time: float | None = None,
    min_run: int = MIN_RUN,
) -> Path:
    """Draw the Gantt chart of `records` into the PNG file `path`; returns the path.

    One row per task; a run of at least `min_run` identical successful siblings shares one row
    labelled "name ×N" with one bar per task (`min_run=0`: one row per task). Times are shown
    relative to the first task's start. Tasks without an end (a killed run) are drawn hatched up
    to `end_time` (default: the latest time recorded).
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg  # no pyplot, no display
    from matplotlib.figure import Figure
    from matplotlib.patches import Patch

    path = Path(path)
    rows, left_out = _rows_for_timeline(list(records), max_rows, min_run)
    times = [t for node, _ in rows for r in node.records for t in (r.start, r.end) if t is not None]
    origin = min(times) if times else 0.0
    last = max(times) if times else 1.0
    if end_time is not None:
        last = max(last, end_time)
    span = max(last - origin, 1e-6)
    height = min(2.0 + 0.22 * max(len(rows), 1), 60.0)
    fig = Figure(figsize=(12, height), dpi=100)
    FigureCanvasAgg(fig)
    ax = fig.add_subplot(1, 1, 1)
    labels = []
    unfinished = False
    for i, (node, depth) in enumerate(rows):
        by_style: dict[tuple[str, bool], list[tuple[float, float]]] = {}
        for r in node.records:
            start = (r.start if r.start is not None else origin) - origin
            end = (r.end if r.end is not None else last) - origin
            width = max(end - start, span * 0.002)  # very short tasks stay visible
            by_style.setdefault((r.status, r.end is None), []).append((start, width))
            if r.error_type and r.status == "failed" and node.count == 1:
                ax.text(start + width, i, f" {r.error_type}", va="center", fontsize=7, color="#b71c1c")
        for (status, open_ended), bars in by_style.items():
            color = STATUS_COLORS.get(status, "#607d8b")
            unfinished = unfinished or open_ended
            ax.broken_barh(
                bars,
                (i - 0.35, 0.7),
                facecolors=color,
                edgecolors="#37474f" if open_ended else color,
                hatch="//" if open_ended else None,
                linewidth=0.5,
            )
        r = node.record
        label = "  " * depth + (r.name if r.name == r.kind or not r.kind else f"{r.name} [{r.kind}]")
        suffix = f" ×{node.count}" if node.count > 1 else ""
        labels.append(_clip(label, 48 - len(suffix)) + suffix)
    ax.set_yticks(range(len(rows)))
    ax.set_yticklabels(labels, fontsize=7, family="monospace")
    width_chars = max((len(label) for label in labels), default=0)
    for tick in ax.get_yticklabels():  # left-aligned, so the indentation shows the tree
        tick.set_horizontalalignment("left")
    ax.yaxis.set_tick_params(pad=4 + width_chars * 7 * 0.6)
    ax.set_ylim(len(rows) - 0.5 if rows else 0.5, -0.5)
    ax.set_xlim(-span * 0.01, span * 1.08)
    ax.set_xlabel("time since the first task started [s]")
    ax.grid(axis="x", color="#eceff1", linewidth=0.8)
    ax.set_axisbelow(True)
    heading = title or "timeline"
    if left_out:
        heading += f"  ({left_out} deeper tasks not shown)"
    ax.set_title(heading, fontsize=10, loc="left")
    present = sorted({r.status for node, _ in rows for r in node.records}) or ["succeeded"]
    handles = [Patch(color=STATUS_COLORS.get(s, "#607d8b"), label=s) for s in present]
    if unfinished:
        handles.append(Patch(facecolor="white", edgecolor="#37474f", hatch="//", label="no end recorded"))
    ax.legend(
        handles=handles,
        loc="lower right",
        bbox_to_anchor=(1.0, 1.0),
        ncol=len(handles),
        fontsize=8,
        frameon=False,
        borderaxespad=0.2,
    )
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, format="png")
    return path


# -- from the database / from memory ------------------------------------------------------------


def _title(run: Any) -> str:
    parts = [f"run {run.id}"]
    if run.plan:
        parts.append(run.plan)
    if run.robot:
        parts.append(run.robot)
    parts.append(run.state)
    return " · ".join(parts)


def _run_records(run_id: int, url: str | None) -> list[TaskRecord]:
    """The tasks of a recorded run and its process-module executions that are not tasks."""
    from pycram.trace import query

    tasks, executions = query.tree_records(run_id, url)
    return tasks + executions


def write_tree_svg(run_id: int | None, path: str | Path, url: str | None = None, min_run: int = MIN_RUN) -> Path:
    """Write the task tree of run `run_id` (newest when None) as SVG to `path` (see `tree_svg`)."""
    from pycram.trace import query

    run = query.get_run(run_id, url)
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(tree_svg(_run_records(run.id, url), title=_title(run), min_run=min_run), encoding="utf-8")
    return path


def write_timeline_png(
    run_id: int | None, path: str | Path, url: str | None = None, max_rows: int = 200, min_run: int = MIN_RUN
) -> Path:
    """Write the timeline of run `run_id` (newest when None) as PNG to `path` (see `timeline_png`)."""
    from pycram.trace import query

    run = query.get_run(run_id, url)
    return timeline_png(_run_records(run.id, url), path, title=_title(run), max_rows=max_rows, min_run=min_run)


def write_run_pictures(run_id: int | None, folder: str | Path, url: str | None = None) -> list[Path]:
    """Write `task-tree.svg` and `timeline.png` of a recorded run into `folder`; returns the paths."""
    folder = Path(folder)
    return [
        write_tree_svg(run_id, folder / "task-tree.svg", url),
        write_timeline_png(run_id, folder / "timeline.png", url),
    ]


def write_task_pictures(task: Any, folder: str | Path, title: str | None = None) -> list[Path]:
    """Like `write_run_pictures` for an in-memory `pycram.runtime.Task` (no database needed)."""
    from pycram.trace.query import records_from_task

    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    records = records_from_task(task)
    svg = folder / "task-tree.svg"
    svg.write_text(tree_svg(records, title=title), encoding="utf-8")
    return [svg, timeline_png(records, folder / "timeline.png", title=title)]
