"""A run's fingerprint: what two runs must share to count as the same run.

`run_fingerprint(task, poses)` hashes the plan's task tree -- each task's path, kind, status and
simulated start and end times (rounded to 1 ms of the plan's clock) -- and the final poses of the
robot and the objects (rounded to 1e-6 m and 1e-6 of a quaternion component). Two runs with the
same fingerprint did the same things at the same simulated times and ended the world in the same
state. `fingerprint_lines` gives the same as text, for saying where two runs differ.

Siblings are taken in the order of their start time, then name, then end time (in lock-step,
plan threads take turns in task order, so siblings are also created in the same order in every
run; the canonical order keeps fingerprints of free-running runs comparable where they can be).

A recorded run keeps more than the hash, to say *where* a replay first differs (`run_record`,
stored packed in the run's ``info`` by `pack_record`): the task lines, the final poses and the
world's trajectory -- the robot's base and joints, every object's pose and the containers' joints
sampled every simulated second by the simulation (`pycram.sim.World.trajectory`), each as its
rounded numbers (or, for more than `SHOWN_NUMBERS` of them, a hash of those). `compare_records`
finds the first difference of two records: the first trajectory sample that differs (simulated
time, which body, recorded and replayed numbers, the tasks running then), else the first task
line (task path), else the final poses. `recording_info` builds what a recorded run keeps for
`pycram replay` (`pycram.apps.replay`): how to run it again, and its packed record.
"""

from __future__ import annotations

import base64
import hashlib
import json
import platform
import zlib
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

__all__ = [
    "RECORD_FORMAT",
    "SHOWN_NUMBERS",
    "Divergence",
    "compare_records",
    "fingerprint_lines",
    "pack_record",
    "recording_info",
    "run_fingerprint",
    "run_record",
    "state_text",
    "unpack_record",
]

#: Version of the layout of `run_record` (a record of another layout is not compared).
RECORD_FORMAT = 1
#: A sampled body with at most this many numbers is kept as its numbers (a pose: 7), one with
#: more (the robot's joints) as a 16-hex-digit hash of them.
SHOWN_NUMBERS = 8


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


def state_text(values: Sequence[float]) -> str:
    """One sampled body as text: its numbers rounded to 1e-6 (as `fingerprint_lines` rounds
    poses), or ``#`` and a hash of that text when there are more than `SHOWN_NUMBERS`."""
    text = " ".join(_number(float(v)) for v in values)
    return text if len(values) <= SHOWN_NUMBERS else "#" + hashlib.sha256(text.encode()).hexdigest()[:16]


def run_record(
    task: Any,
    poses: Mapping[str, Any] | None = None,
    trajectory: Iterable[tuple[float, Mapping[str, Sequence[float]]]] = (),
) -> dict[str, Any]:
    """What a run keeps to be compared with a replay (JSON-serialisable): ``format``
    (`RECORD_FORMAT`), ``hash`` (`run_fingerprint(task, poses)`), ``tasks`` (the task lines of
    `fingerprint_lines`), ``poses`` (name -> rounded numbers) and ``trajectory`` (a list of
    [simulated time [s] rounded to 1 ms, {body: `state_text`}] from `World.trajectory()`)."""
    pose_lines = fingerprint_lines(None, poses)
    return {
        "format": RECORD_FORMAT,
        "hash": run_fingerprint(task, poses),
        "tasks": fingerprint_lines(task),
        "poses": {line[5:].split(": ", 1)[0]: line.split(": ", 1)[1] for line in pose_lines},
        "trajectory": [
            [round(float(t), 3), {name: state_text(state[name]) for name in sorted(state)}] for t, state in trajectory
        ],
    }


def pack_record(record: Mapping[str, Any]) -> dict[str, Any]:
    """`record` as stored in a run's ``info``: ``{"format", "hash", "data"}`` with the whole
    record as zlib-compressed JSON in base64 (a few kB for a run of a few minutes)."""
    data = zlib.compress(json.dumps(record, separators=(",", ":"), sort_keys=True).encode(), 9)
    return {"format": record.get("format"), "hash": record.get("hash"), "data": base64.b64encode(data).decode()}


def unpack_record(packed: Mapping[str, Any]) -> dict[str, Any]:
    """The record `pack_record` packed. Raises ValueError for anything else."""
    try:
        record = json.loads(zlib.decompress(base64.b64decode(packed["data"])))
    except (KeyError, TypeError, ValueError, zlib.error) as error:
        raise ValueError(f"not a packed run record ({type(error).__name__}: {error})") from None
    if not isinstance(record, dict) or record.get("format") != RECORD_FORMAT:
        raise ValueError(
            f"a run record of format {record.get('format') if isinstance(record, dict) else '?'}, "
            f"this PyCRAM reads format {RECORD_FORMAT}"
        )
    return record


@dataclass(frozen=True)
class Divergence:
    """Where a replay first differs from the recorded run.

    `time` [s of simulated time]: the first trajectory sample (or task start/end) that differs;
    `since`: the sample before it, when both agreed (None if the runs differ from the start or
    the difference is in a task or final pose); `body`: which sampled body ("base", "joints",
    "containers" or an object's name) or final pose differs (None for a task); `task`: the
    path of the first differing task, or the tasks running at `time`; `recorded`, `replayed`:
    what each run has there ("-" for nothing)."""

    what: str  # "trajectory", "task", "length" or "pose"
    time: float | None
    since: float | None
    body: str | None
    task: str | None
    recorded: str
    replayed: str
    others: tuple[str, ...] = ()  # further bodies differing at the same sample

    def __str__(self) -> str:
        if self.what == "trajectory":
            window = f"between t={self.since:.1f} s and t={self.time:.1f} s" if self.since is not None else ""
            where = window or f"at t={self.time:.1f} s"
            others = f" (also: {', '.join(self.others)})" if self.others else ""
            text = f"diverged {where}: {_body_words(self.body)} differs{others} "
            text += f"(recorded {self.recorded}, replayed {self.replayed})"
            return text + (f"; running then: {self.task}" if self.task else "")
        if self.what == "task":
            return (
                f"diverged at t={self.time:.3f} s in task {self.task} (recorded {self.recorded!r}, replayed "
                f"{self.replayed!r})"
                if self.time is not None
                else f"diverged in task {self.task} (recorded {self.recorded!r}, replayed {self.replayed!r})"
            )
        if self.what == "length":
            return f"diverged after t={self.since:.1f} s: the recorded run {self.recorded}, the replay {self.replayed}"
        return (
            f"diverged at the end: {_body_words(self.body)} at the end differs "
            f"(recorded {self.recorded}, replayed {self.replayed})"
        )


def _body_words(body: str | None) -> str:
    if body == "joints":
        return "the robot's joint positions"
    if body == "base":
        return "the robot's base pose"
    if body == "containers":
        return "the containers' joint positions"
    return f"the pose of {body!r}"


_TaskRow = tuple[str, str, float | None, float | None]


def _task_table(lines: Sequence[str]) -> list[_TaskRow]:
    """(path, rest of the line, start, end) of each task line; path: names joined by "/"."""
    table: list[_TaskRow] = []
    stack: list[str] = []
    for line in lines:
        depth = (len(line) - len(line.lstrip(" "))) // 2
        name, _, rest = line.strip().partition(" [")
        del stack[depth:]
        stack.append(name)
        fields = rest.rsplit(" ", 2)
        times = [None if f == "-" else float(f) for f in fields[-2:]] if len(fields) == 3 else [None, None]
        table.append(("/".join(stack), "[" + rest, times[0], times[1]))
    return table


def _running_at(table: Sequence[_TaskRow], t: float) -> str:
    """The deepest tasks running at simulated time `t` (at most 3 paths, "; "-joined)."""
    running = [p for p, _, s, e in table if s is not None and s <= t and (e is None or e >= t)]
    leaves = [p for p in running if not any(q.startswith(p + "/") for q in running)]
    return "; ".join(leaves[:3]) + (f" (+{len(leaves) - 3} more)" if len(leaves) > 3 else "")


def _task_divergence(a: _TaskRow | None, b: _TaskRow | None) -> Divergence:
    """The divergence of two differing task rows (None: the run has no such line)."""
    path = a[0] if a is not None else b[0] if b is not None else "?"
    if a is not None and b is not None and a[0] != b[0]:
        path = f"{a[0]} (replayed: {b[0]})"
    when: float | None = None
    if a is not None and b is not None:  # the first of the times that differ (start, else end)
        differing = [x for pair in ((a[2], b[2]), (a[3], b[3])) if pair[0] != pair[1] for x in pair if x is not None]
        known = [x for x in (a[2], b[2]) if x is not None]
        when = min(differing) if differing else min(known) if known else None
    else:
        row = a or b
        when = row[2] if row is not None else None
    return Divergence("task", when, None, None, path, a[1] if a else "-", b[1] if b else "-")


def compare_records(recorded: Mapping[str, Any], replayed: Mapping[str, Any]) -> Divergence | None:
    """Where `replayed` first differs from `recorded` (both from `run_record`); None when they
    are the same (the same hash, task lines, final poses and trajectory).

    Looked at in this order: the trajectory samples both runs have (the first sample that
    differs, with every body that differs there), the task lines (the first line that differs:
    its task path and the simulated time its start or end differs), the number of samples (one
    run simulated longer), the final poses."""
    rec_traj, rep_traj = recorded.get("trajectory", []), replayed.get("trajectory", [])
    rec_tasks, rep_tasks = list(recorded.get("tasks", [])), list(replayed.get("tasks", []))
    table = _task_table(rec_tasks)
    since: float | None = None
    for (t_rec, rec), (t_rep, rep) in zip(rec_traj, rep_traj, strict=False):
        if t_rec != t_rep:
            return Divergence("trajectory", t_rec, since, "the sample time", None, f"t={t_rec}", f"t={t_rep}")
        bodies = sorted(set(rec) | set(rep), key=lambda b: (b not in ("base", "joints"), b))
        differing = [b for b in bodies if rec.get(b) != rep.get(b)]
        if differing:
            body = differing[0]
            return Divergence(
                "trajectory",
                float(t_rec),
                since,
                body,
                _running_at(table, since if since is not None else float(t_rec)) or None,
                rec.get(body, "-"),
                rep.get(body, "-"),
                tuple(differing[1:]),
            )
        since = float(t_rec)
    rep_table = _task_table(rep_tasks)
    for i in range(max(len(table), len(rep_table))):
        a = table[i] if i < len(table) else None
        b = rep_table[i] if i < len(rep_table) else None
        if a == b:
            continue
        return _task_divergence(a, b)
    if len(rec_traj) != len(rep_traj):

        def span(traj: Sequence[Any]) -> str:
            return f"ran until t={traj[-1][0]:.1f} s" if traj else "has no samples"

        return Divergence(
            "length", None, since if since is not None else 0.0, None, None, span(rec_traj), span(rep_traj)
        )
    rec_poses, rep_poses = recorded.get("poses", {}), replayed.get("poses", {})
    for name in sorted(set(rec_poses) | set(rep_poses)):
        if rec_poses.get(name) != rep_poses.get(name):
            return Divergence("pose", None, None, name, None, rec_poses.get(name, "-"), rep_poses.get(name, "-"))
    if recorded.get("hash") != replayed.get("hash"):  # e.g. a record edited by hand
        return Divergence(
            "pose", None, None, "fingerprint hash", None, str(recorded.get("hash")), str(replayed.get("hash"))
        )
    return None


def recording_info(
    scenario: str,
    robot: str,
    environment: str,
    seed: int,
    stepping: str,
    options: Mapping[str, Any],
    *,
    backend: str = "sim",
    fingerprint: tuple[Any, Mapping[str, Any], Iterable[Any]] | None = None,
) -> dict[str, Any]:
    """The ``info`` fields of a recorded run that `pycram replay` reads (for
    `Recorder.set_run_info(**...)`): ``replay`` -- what defines the run: `scenario` (a name of
    `pycram demo --scenario`), `robot`, `environment`, `seed`, `stepping`, `backend`, the
    scenario's `options` and the ``pycram`` and ``python`` versions -- and, with `fingerprint` =
    (the plan's task, the final poses, `World.trajectory()`), ``fingerprint`` (the packed
    `run_record`). See `pycram.apps.replay`."""
    from pycram._version import __version__

    info: dict[str, Any] = {
        "replay": {
            "scenario": scenario,
            "robot": robot,
            "environment": environment,
            "seed": seed,
            "stepping": stepping,
            "backend": backend,
            "options": dict(sorted(options.items())),
            "pycram": __version__,
            "python": platform.python_version(),
        }
    }
    if fingerprint is not None:
        task, poses, trajectory = fingerprint
        info["fingerprint"] = pack_record(run_record(task, poses, trajectory))
    return info
