"""Replaying a recorded run: what a run stores to run again, running it again, comparing.

A run recorded by `pycram demo` (thesis, set-table, set-table-open, set-table-anywhere) or by
`pycram experiment` keeps two objects in its ``info`` (`pycram.trace.fingerprint.recording_info`):

* ``replay``: what defines the run -- ``scenario``, ``robot``, ``environment``, ``seed``,
  ``stepping``, ``backend``, the scenario's ``options`` (e.g. ``item_at``, ``steal``,
  ``faults``, ``pictures``: whether start and end pictures were written; they cost no
  simulated time since stop 42 -- one control tick before, so runs recorded then replay with
  it) -- and the ``pycram`` and ``python`` versions that ran it;
* ``fingerprint``: the run's record (`pycram.trace.fingerprint.run_record`, packed): its task
  lines, final poses and the world's state every simulated second -- only for a run that ended
  by itself (not stopped by a signal or `--until`).

`replay_run(RUN)` runs the scenario again, headless and unrecorded, with the stored options
(in lock-step: the same run, if the code is the same) and compares the two records
(`compare_records`): None means identical. A run that cannot be replayed -- not recorded by a
scenario, recorded without replay information (older PyCRAM, `pycram run`), free-running or
over ROS, interrupted, stopped by `--until` -- raises `CannotReplay` saying why. A run recorded
by another PyCRAM version is replayed with a warning (a difference may be the code's).
"""

from __future__ import annotations

import logging
import platform
import tempfile
import time
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

__all__ = [
    "REPLAYABLE_SCENARIOS",
    "CannotReplay",
    "ReplayReport",
    "load_replay",
    "rerun",
    "replay_run",
]

log = logging.getLogger("pycram.replay")

#: The scenarios a recorded run can be replayed for (`pycram demo --scenario`).
REPLAYABLE_SCENARIOS = (
    "thesis",
    "set-table",
    "set-table-open",
    "set-table-anywhere",
    "clear-table",
    "put-away",
    "serve",
)
#: The household tasks of the suite among them, by name -> the module holding their `TASK`.
_TASKS = {
    "clear-table": "pycram.apps.scenarios.clear_table.driver",
    "put-away": "pycram.apps.scenarios.put_away.driver",
    "serve": "pycram.apps.scenarios.serve.driver",
}


class CannotReplay(ValueError):
    """A recorded run that cannot be run again; the message says why, in one line."""


def load_replay(run: str | int | None, url: str | None = None) -> tuple[Any, dict[str, Any], dict[str, Any]]:
    """The recorded run `run` (id, uuid or uuid prefix; None: the newest), its ``replay`` object
    and its unpacked record. Raises `pycram.trace.query.RunNotFound` for no such run and
    `CannotReplay` (saying why) for a run that cannot be replayed."""
    from pycram.trace.fingerprint import unpack_record
    from pycram.trace.query import find_run

    info = find_run(run, url)
    replay = info.info.get("replay")
    if not isinstance(replay, dict):
        how = f" (`{info.command}`)" if info.command else ""
        raise CannotReplay(
            f"run {info.id}{how} was recorded without what a replay needs: only runs of `pycram demo` and "
            "`pycram experiment` recorded by a PyCRAM with replay support can be replayed"
        )
    scenario = replay.get("scenario")
    if scenario not in REPLAYABLE_SCENARIOS:
        raise CannotReplay(f"run {info.id} is of scenario {scenario!r}; replayable: {', '.join(REPLAYABLE_SCENARIOS)}")
    if replay.get("backend", "sim") != "sim":
        raise CannotReplay(
            f"run {info.id} ran over ROS (--backend {replay.get('backend')}): its timing is not reproducible"
        )
    if replay.get("stepping") != "lockstep":
        raise CannotReplay(
            f"run {info.id} ran free-running (--stepping {replay.get('stepping')}): what the plan computed cost "
            "simulated time, so no replay can be the same run"
        )
    options = replay.get("options") or {}
    if options.get("until") is not None:
        raise CannotReplay(
            f"run {info.id} was stopped at t={options['until']} s by --until; replay the run it was made from"
        )
    if options.get("interactive"):
        raise CannotReplay(f"run {info.id} asked a person (--interactive): the answers were not recorded")
    packed = info.info.get("fingerprint")
    if not isinstance(packed, dict):
        raise CannotReplay(
            f"run {info.id} has no fingerprint: it did not end by itself ({info.state}"
            + (f": {info.error}" if info.error else "")
            + ")"
        )
    try:
        record = unpack_record(packed)
    except ValueError as error:
        raise CannotReplay(f"run {info.id}: its fingerprint cannot be read: {error}") from None
    return info, replay, record


@dataclass
class ReplayReport:
    """What `replay_run` found. `divergence` is None when the replay was identical (with
    `until`: identical in every trajectory sample up to `until`)."""

    run_id: int
    replay: dict[str, Any]
    divergence: Any = None  # a `pycram.trace.fingerprint.Divergence`, or None
    warnings: list[str] = field(default_factory=list)
    recorded_hash: str | None = None
    replayed_hash: str | None = None
    wall_time: float = 0.0  # of the replay [s]
    until: float | None = None
    stop_folder: Path | None = None  # with `until`: where the pictures of that moment went

    @property
    def identical(self) -> bool:
        return self.divergence is None


def _version_warnings(replay: Mapping[str, Any]) -> list[str]:
    from pycram._version import __version__

    warnings = []
    if replay.get("pycram") != __version__:
        warnings.append(
            f"the run was recorded by PyCRAM {replay.get('pycram')}, this is {__version__}: "
            "a difference may be the code's"
        )
    if replay.get("python") != platform.python_version():
        warnings.append(f"the run was recorded with Python {replay.get('python')}, this is {platform.python_version()}")
    return warnings


def rerun(
    replay: Mapping[str, Any], until: float | None = None, output: Path | None = None
) -> tuple[dict[str, Any], Path | None]:
    """Run the scenario `replay` describes again, headless, unrecorded, without animation;
    returns its `run_record` and, with `until`, the folder the pictures and the task tree of
    that moment went to (stopped at that simulated time: the record holds the trajectory up to
    then; the folder is below `output`, which `until` needs). Pictures the recorded run took are
    taken again (into `output`, else a temporary folder): each costs simulated time. Raises
    `CannotReplay` for options this PyCRAM does not know, ValueError for `until` without
    `output`."""
    from pycram.trace.fingerprint import run_record

    if until is not None and output is None:
        raise ValueError("a replay with `until` needs an output folder for its pictures")
    scenario, options = replay["scenario"], dict(replay.get("options") or {})
    stop_folder: Path | None = None
    with tempfile.TemporaryDirectory(prefix="pycram-replay-") as scratch:
        folder = output if output is not None else Path(scratch)
        try:
            if scenario == "thesis":
                from pycram.apps.demos.kitchen import DemoOptions, run_demo

                result = run_demo(
                    DemoOptions(
                        robot=replay["robot"],
                        seed=int(replay["seed"]),
                        item_at=int(options.get("item_at", 1)),
                        steal=int(options.get("steal", 0)),
                        pictures=bool(options.get("pictures", True)),
                        output=folder,
                        record=False,
                        quiet=True,
                        animation=False,
                        stepping=replay["stepping"],
                        until=until,
                    )
                )
                task, poses, trajectory = result.plan_task, result.final_poses, result.trajectory
                stop_folder = result.stop_folder
            elif scenario in _TASKS:
                import importlib

                from pycram.apps.scenarios.common.driver import run_task

                pictures = bool(options.get("pictures", True))
                objects = options.get("objects")
                done, task = run_task(
                    importlib.import_module(_TASKS[scenario]).TASK,
                    replay["robot"],
                    int(replay["seed"]),
                    frozenset(options.get("faults", ())),
                    environment=replay.get("environment"),
                    objects=tuple(objects) if objects is not None else None,
                    output=folder if pictures else None,
                    stepping=replay["stepping"],
                    until=until,
                    until_folder=folder,
                )
                poses, trajectory = done.final_poses, done.trajectory
                stop_folder = done.stop_folder
            else:
                from pycram.apps.scenarios.set_table.driver import run_scenario

                pictures = bool(options.get("pictures", True))
                outcome, task = run_scenario(
                    replay["robot"],
                    int(replay["seed"]),
                    frozenset(options.get("faults", ())),
                    output=folder if pictures else None,
                    in_containers=scenario != "set-table-open",
                    starts="anywhere" if scenario == "set-table-anywhere" else "narrow",
                    environment=replay.get("environment") or "apartment",
                    stepping=replay["stepping"],
                    until=until,
                    until_folder=folder,
                )
                poses, trajectory = outcome.final_poses, outcome.trajectory
                stop_folder = outcome.stop_folder
        except (KeyError, TypeError, ValueError) as error:
            raise CannotReplay(f"the recorded options cannot be run: {type(error).__name__}: {error}") from None
    return run_record(task, poses, trajectory), stop_folder


def replay_run(
    run: str | int | None, url: str | None = None, until: float | None = None, output: Path | None = None
) -> ReplayReport:
    """Replay the recorded run `run` (see `load_replay`) and compare it with its record.

    With `until` [s of simulated time]: stop the replay there, write the scene and belief
    pictures and the task tree of that moment into `output`, and compare only the trajectory
    samples up to then. Raises `RunNotFound` and `CannotReplay` as `load_replay` does."""
    from pycram.trace.fingerprint import compare_records

    info, replay, recorded = load_replay(run, url)
    report = ReplayReport(info.id, replay, warnings=_version_warnings(replay), until=until)
    started = time.monotonic()
    replayed, report.stop_folder = rerun(replay, until=until, output=output)
    report.wall_time = time.monotonic() - started
    report.recorded_hash, report.replayed_hash = recorded.get("hash"), replayed.get("hash")
    if until is not None:  # only the samples both runs have up to `until`
        cut = [s for s in recorded.get("trajectory", []) if s[0] <= until + 1e-9]
        recorded = {"trajectory": cut}
        replayed = {"trajectory": [s for s in replayed.get("trajectory", []) if s[0] <= until + 1e-9]}
    report.divergence = compare_records(recorded, replayed)
    return report
