"""A run's fingerprint: what two runs must share to count as the same run.

`run_fingerprint(task, poses)` hashes the plan's task tree -- each task's path, kind, status and
simulated start and end times (rounded to 1 ms of the plan's clock) -- and the final poses of the
robot and the objects (rounded to 1e-6 m and 1e-6 of a quaternion component). Two runs with the
same fingerprint did the same things at the same simulated times and ended the world in the same
state. `fingerprint_lines` gives the same as text, for saying where two runs differ.

Siblings are taken in the order of their start time, then name, then end time: tasks started at
one simulated instant by concurrent branches are created, and served by a process module, in
whichever order their threads ran (the runtime does not yet run simultaneous branches in a fixed
order), so two same-named siblings may swap which of them ended first.
"""

from __future__ import annotations

import hashlib
from collections.abc import Iterable, Mapping
from typing import Any

__all__ = ["fingerprint_lines", "run_fingerprint"]


def _time(value: float | None) -> str:
    return "-" if value is None else f"{value:.3f}"


def _number(value: float) -> str:
    text = f"{value:.6f}"
    return "0.000000" if text == "-0.000000" else text


def _pose_text(pose: Any) -> str:
    if hasattr(pose, "position"):
        values: Iterable[float] = (*pose.position, *pose.orientation)
    elif hasattr(pose, "yaw"):
        values = (pose.x, pose.y, pose.yaw)
    else:
        values = pose
    return " ".join(_number(float(v)) for v in values)


def _sibling_order(task: Any) -> tuple[float, str, float]:
    inf = float("inf")
    start = task.start_time if task.start_time is not None else inf
    return (start, task.name, task.end_time if task.end_time is not None else inf)


def fingerprint_lines(task: Any, poses: Mapping[str, Any] | None = None) -> list[str]:
    """The fingerprint as text: one line per task (indented by depth: name, kind, status, start
    and end [s]) and one per pose (name, then the rounded numbers), in a canonical order."""
    lines: list[str] = []

    def visit(node: Any, depth: int) -> None:
        status = getattr(node.status.get_value(), "name", str(node.status.get_value()))
        lines.append(
            f"{'  ' * depth}{node.name} [{node.kind}] {status} {_time(node.start_time)} {_time(node.end_time)}"
        )
        children = sorted(node.children, key=_sibling_order)
        for child in children:
            visit(child, depth + 1)

    if task is not None:
        visit(task, 0)
    for name in sorted(poses or {}):
        lines.append(f"pose {name}: {_pose_text(poses[name])}")  # type: ignore[index]
    return lines


def run_fingerprint(task: Any, poses: Mapping[str, Any] | None = None) -> str:
    """The SHA-256 (hex) of `fingerprint_lines(task, poses)`."""
    return hashlib.sha256("\n".join(fingerprint_lines(task, poses)).encode()).hexdigest()
