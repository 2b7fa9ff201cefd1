"""Running the set-table scenario: the world from a seed, the plan in a thread of its own under
time limits, the faults alongside, then the judge.

`open_world` builds the simulated apartment with the objects of `start_scene` and the robot at
the start pose; `run_scenario` runs the plan (`plan.set_table`) once, with the faults of
`FAULTS`, within `SIM_TIME_LIMIT` [s of simulated time] and `WALL_TIME_LIMIT` [s of wall time],
and judges the outcome with the simulator's truth (`judge`); it never raises for a failure of
the plan. `run_set_table`, `run_set_table_on_open_surfaces` and `run_set_table_anywhere` are the
``set-table``, ``set-table-open`` and ``set-table-anywhere`` scenarios of `pycram experiment`
(headless, JSON-serialisable results): the ``narrow`` starts of `START_REGIONS` (with or without
`START_CONTAINERS`), or the ``anywhere`` starts of `anywhere_scene`.
"""

from __future__ import annotations

import logging
import random
import time
from functools import partial
from pathlib import Path
from typing import Any

from pycram.apps.run_options import check_until
from pycram.apps.scenarios.common.driver import ScenarioPlan, play, start_pictures
from pycram.apps.scenarios.set_table.data import (
    ANYWHERE_OBJECTS,
    FAULTS,
    MISS_PROBABILITY,
    OBJECTS,
    SIM_TIME_LIMIT,
    STARTS,
    WALL_TIME_LIMIT,
)
from pycram.apps.scenarios.set_table.faults import Faults, check_faults
from pycram.apps.scenarios.set_table.judge import SetTableResult, judge
from pycram.apps.scenarios.set_table.plan import PlaceSetting, PlanRecord, SettingOutcome
from pycram.apps.scenarios.set_table.scene import anywhere_scene, place_settings, start_scene
from pycram.core.runtime.lockstep import DEFAULT_STEPPING

__all__ = [
    "check_environment",
    "open_world",
    "record_replay_info",
    "run_scenario",
    "run_set_table",
    "run_set_table_on_open_surfaces",
    "run_set_table_anywhere",
    "scenario_name",
    "default_objects",
]

log = logging.getLogger("pycram.demo")


class _PlanThread(ScenarioPlan):
    """The set-table plan in a thread of its own (a task tree root), so the driver can watch time
    limits."""

    def __init__(self, robot: Any, settings: list[PlaceSetting]) -> None:
        self.settings = settings
        super().__init__(robot, self._set_table, "set_table", "pycram-set-table")

    def _set_table(self, record: PlanRecord) -> list[SettingOutcome]:
        from pycram.apps.scenarios.set_table.plan import set_table

        return set_table(self.settings, record)


def check_starts(starts: str) -> str:
    """`starts` checked: one of `STARTS` (ValueError naming them otherwise)."""
    if starts not in STARTS:
        raise ValueError(f"unknown start mode {starts!r}; valid start modes: {', '.join(STARTS)}")
    return starts


def default_objects(starts: str) -> tuple[str, ...]:
    """The object types brought by default with the start mode `starts`: `OBJECTS` (``narrow``)
    or all six breakfast types, `ANYWHERE_OBJECTS` (``anywhere``)."""
    return ANYWHERE_OBJECTS if check_starts(starts) == "anywhere" else OBJECTS


def scenario_name(in_containers: bool = True, starts: str = "narrow") -> str:
    """The scenario's name for these options: ``set-table``, ``set-table-open`` or
    ``set-table-anywhere`` (output folders, recorded runs, experiments)."""
    if check_starts(starts) == "anywhere":
        return "set-table-anywhere"
    return "set-table" if in_containers else "set-table-open"


def open_world(
    robot: str,
    seed: int,
    faults: frozenset[str] = frozenset(),
    objects: tuple[str, ...] | None = None,
    in_containers: bool = True,
    stepping: str = DEFAULT_STEPPING,
    offscreen_size: tuple[int, int] | None = None,
    starts: str = "narrow",
    environment: str = "apartment",
) -> tuple[Any, list[Any]]:
    """The environment named `environment` (`pycram.environments.load`: ``apartment``,
    ``procedural:SEED``, ``file:PATH``) with the scenario's objects (default: `default_objects`)
    at random spots from `seed` and `robot` at the start pose (perception misses detections with
    the ``missed`` fault), simulated with `stepping` ("free" or "lockstep", see
    `pycram.sim.World`; `offscreen_size` [px]: the largest picture it renders, None for the
    world's default). The spots: with `starts` ``narrow`` those of `start_scene` (some inside
    closed containers with `in_containers`; the apartment only: its start regions are drawn on
    its counter), with ``anywhere`` those of `anywhere_scene` for `robot` (any environment).
    Returns the world and the placements; `ValueError` for narrow starts outside the apartment."""
    from pycram.backends.sim import ItemSpec, World
    from pycram.backends.sim.perception import PerceptionFaults
    from pycram.environments import load as load_environment
    from pycram.world.objects import object_type

    objects = default_objects(starts) if objects is None else tuple(objects)
    check_environment(environment, starts)
    described = load_environment(environment)
    if starts == "anywhere":
        placements = anywhere_scene(described, seed, robot, objects)
    else:
        placements = start_scene(described, seed, objects, in_containers)
    items = [ItemSpec.of(object_type(p.type), p.name, p.position, p.yaw) for p in placements]
    perception = PerceptionFaults(miss_probability=MISS_PROBABILITY, seed=seed) if "missed" in faults else None
    size: dict[str, Any] = {"offscreen_size": offscreen_size} if offscreen_size is not None else {}
    world = World(robot, items, environment=environment, perception_faults=perception, stepping=stepping, **size)
    return world, placements


def check_environment(environment: str, starts: str = "narrow") -> str:
    """`environment` checked for the start mode `starts`: a name `pycram.environments.load`
    reads, and the apartment for the ``narrow`` starts (their regions are drawn on the
    apartment's counter); ValueError naming the problem and what to use otherwise."""
    from pycram.environments import check_name

    try:
        name = check_name(environment)
    except KeyError as error:  # an unknown or malformed name: a bad option like the others
        raise ValueError(str(error.args[0] if error.args else error)) from None
    if check_starts(starts) == "narrow" and name != "apartment":
        raise ValueError(
            f"set-table is written for the apartment only (its start regions are drawn on the apartment's "
            f"counter), not {name}; set-table-anywhere runs in any environment"
        )
    return name


def _check(robot: str, seed: int, faults: Any) -> frozenset[str]:
    from pycram.robots import ROBOT_NAMES

    if robot not in ROBOT_NAMES:
        raise ValueError(f"unknown robot {robot!r}; valid robots: {', '.join(ROBOT_NAMES)}")
    if not isinstance(seed, int) or seed < 0:
        raise ValueError(f"the seed must be an integer >= 0, not {seed!r}")
    return check_faults(faults)


def run_scenario(
    robot: str,
    seed: int,
    faults: Any = frozenset(),
    *,
    recorder: Any = None,
    output: Path | None = None,
    animation: bool = False,
    progress: Any = None,
    objects: tuple[str, ...] | None = None,
    in_containers: bool = True,
    stepping: str = DEFAULT_STEPPING,
    until: float | None = None,
    until_folder: Path | None = None,
    starts: str = "narrow",
    environment: str = "apartment",
) -> tuple[SetTableResult, Any]:
    """Run the set-table scenario once; never raises for failures of the plan (they are in the
    result). With `output`, start.png and end.png are written there (and run.gif with
    `animation`); `recorder` (a trace recorder) is told the robot; `progress(world, plan_thread,
    faults)` is called about 4 times a second of wall time while the plan runs; `in_containers`:
    objects may start inside closed containers (`start_scene`); `starts`: the start mode
    (`STARTS`: ``narrow`` or ``anywhere``, see `open_world`); `environment`: where (see
    `open_world`; other than the apartment with ``anywhere`` starts only); `objects`: the types to bring
    (default: `default_objects`); `stepping`: "lockstep" for a
    run that depends on the seed alone (see `pycram.sim.World`); `until` [s of simulated time]:
    stop the world there, write the scene and belief pictures and the task tree of that moment
    (`write_stop_pictures`) into a folder ``until-T.Ts`` below `until_folder` (default: `output`,
    else ``output/set-table-ROBOT-SEED``), then stop the plan (`result.stopped_at`). Returns the
    result and the plan's task (the root of its task tree, None if it never started)."""
    from pycram import robots as robot_packages
    from pycram.apps.terminal import STOP_PICTURE_SIZE

    kinds = _check(robot, seed, faults)
    check_until(until)
    check_environment(environment, starts)
    objects = default_objects(starts) if objects is None else tuple(objects)
    scenario = scenario_name(in_containers, starts)
    started_wall = time.monotonic()
    result = SetTableResult(robot, seed, kinds)
    size = STOP_PICTURE_SIZE if until is not None else None
    world, placements = open_world(robot, seed, kinds, objects, in_containers, stepping, size, starts, environment)
    result.started_in = {p.name: p.container for p in placements if p.container is not None}
    plan: _PlanThread | None = None
    injector: Faults | None = None
    robot_handle = None
    try:
        settings = place_settings(world.environment, objects=objects)
        robot_handle = robot_packages.load(robot, world)
        if recorder is not None:
            recorder.set_run_info(robot=robot)
        camera = "overview"
        start_pictures(world, output, camera, animation, partial(_caption, len(settings)))
        injector = Faults(world, kinds, random.Random(seed * 7919 + 17), settings, placements)
        plan = _PlanThread(robot_handle, settings)
        play(
            world,
            plan,
            injector,
            result,
            sim_limit=SIM_TIME_LIMIT,
            wall_limit=WALL_TIME_LIMIT,
            progress=progress,
            until=until,
            folder=lambda: until_folder or output or Path("output") / f"{scenario}-{robot}-{seed}",
            title=f"set table · {robot} · seed {seed}",
            belief=robot_handle.belief,
            judge=lambda outcomes: judge(world, settings, outcomes, result),
            output=output,
            camera=camera,
            animation=animation,
        )
    finally:
        if injector is not None:
            injector.stop()
        if robot_handle is not None:
            robot_handle.shutdown()
        world.close()
        result.wall_time = time.monotonic() - started_wall
    return result, plan.task if plan is not None else None


def record_replay_info(
    recorder: Any,
    result: SetTableResult | None,
    task: Any,
    *,
    in_containers: bool,
    stepping: str,
    pictures: bool,
    until: float | None = None,
    starts: str = "narrow",
    environment: str = "apartment",
) -> None:
    """Store in the recorded run's info what `pycram replay` needs to run it again and -- for a
    run that ended by itself (not stopped by `until`) -- its fingerprint
    (`pycram.trace.fingerprint.recording_info`). Nothing without a `result`."""
    from pycram.trace.fingerprint import recording_info

    if result is None:
        return
    options: dict[str, Any] = {"faults": sorted(result.faults), "pictures": pictures}
    if until is not None:
        options["until"] = until
    finished = result.stopped_at is None and task is not None
    info = recording_info(
        scenario_name(in_containers, starts),
        result.robot,
        environment,
        result.seed,
        stepping,
        options,
        fingerprint=(task, result.final_poses, result.trajectory) if finished else None,
    )
    recorder.set_run_info(**info)


def _caption(total: int) -> str:
    from pycram.apps.scenarios.set_table.plan import current_object, objects_done

    current = current_object.get_value()
    return f"set table: {objects_done.get_value()}/{total} done" + (f", bringing the {current}" if current else "")


def run_set_table(
    robot: str,
    seed: int,
    faults: frozenset[str] = frozenset(),
    db_url: str | None = None,
    pictures: bool = False,
    objects: tuple[str, ...] | None = None,
    in_containers: bool = True,
    stepping: str = DEFAULT_STEPPING,
    starts: str = "narrow",
) -> dict[str, Any]:
    """Run the set-table scenario once, headless and without animation, simulated with
    `stepping` (see `pycram.sim.World`), for `pycram experiment`.

    `faults`: names of `FAULTS`; `db_url`: record the run in that trace database (None: not
    recorded); `pictures`: write start/end pictures to ``output/set-table-ROBOT-SEED``
    (``output/set-table-open-ROBOT-SEED`` without `in_containers`); `objects`: the object types
    to bring (default: `default_objects`: `OBJECTS`, or with `starts` ``anywhere``
    `ANYWHERE_OBJECTS`; a subset, in that order); `in_containers`: objects may start inside
    closed containers (`start_scene`); `starts`: the start mode (`STARTS`; ``anywhere``: the
    ``set-table-anywhere`` scenario, `anywhere_scene`; in another environment than the
    apartment: `run_set_table_anywhere`). Returns a JSON-serialisable dict: ``success``,
    ``objects`` (per object: ``placed``, ``failure`` (a failure type's name or None),
    ``reason``), ``failure_causes``, ``sim_time`` [s], ``wall_time`` [s], ``robot``, ``seed``,
    ``faults``, ``faults_injected``, ``run_id``, ``started_in`` (object -> the closed container
    it started in), and ``concurrency``: what the plan's concurrency did (`PlanRecord.as_dict`:
    objects found while driving, searches ended by a sighting, objects carried together) and
    ``most_held_at_once`` (the simulator's truth: the object names held at the same time).
    Raises `ValueError` for an unknown robot or fault name.
    """
    return _run_set_table(robot, seed, faults, db_url, pictures, objects, in_containers, stepping, starts, "apartment")


def _run_set_table(
    robot: str,
    seed: int,
    faults: frozenset[str],
    db_url: str | None,
    pictures: bool,
    objects: tuple[str, ...] | None,
    in_containers: bool,
    stepping: str,
    starts: str,
    environment: str,
) -> dict[str, Any]:
    """`run_set_table` in `environment` (the result also says ``environment``)."""
    import os

    os.environ.setdefault("MUJOCO_GL", "egl")
    kinds = _check(robot, seed, faults)
    check_environment(environment, starts)
    objects = default_objects(starts) if objects is None else tuple(objects)
    recorder = None
    if db_url is not None:
        from pycram.trace import start_recording

        recorder = start_recording(url=db_url, plan=f"set table ({robot}, seed {seed})")
    scenario = scenario_name(in_containers, starts)
    output = Path("output") / f"{scenario}-{robot}-{seed}" if pictures else None
    result: SetTableResult | None = None
    task = None
    try:
        result, task = run_scenario(
            robot,
            seed,
            kinds,
            recorder=recorder,
            output=output,
            objects=tuple(objects),
            in_containers=in_containers,
            stepping=stepping,
            starts=starts,
            environment=environment,
        )
    finally:
        run_id = None
        if recorder is not None:
            if tuple(objects) == default_objects(starts):  # a replay brings every object
                record_replay_info(
                    recorder,
                    result,
                    task,
                    in_containers=in_containers,
                    stepping=stepping,
                    pictures=pictures,
                    starts=starts,
                    environment=environment,
                )
            ok = result is not None and result.success
            run_id = recorder.finish(
                "succeeded" if ok else "failed", None if ok else (result.summary() if result else "error")
            )
    out = result.as_dict()
    out["run_id"] = run_id
    out["stepping"] = stepping
    out["starts"] = starts
    out["environment"] = environment
    return out


def run_set_table_on_open_surfaces(
    robot: str,
    seed: int,
    faults: frozenset[str] = frozenset(),
    db_url: str | None = None,
    pictures: bool = False,
    stepping: str = DEFAULT_STEPPING,
) -> dict[str, Any]:
    """The ``set-table-open`` scenario of `pycram experiment`: `run_set_table` with every object
    starting on an open surface (the scenes of the same seeds without `START_CONTAINERS`)."""
    return run_set_table(robot, seed, faults, db_url, pictures, in_containers=False, stepping=stepping)


def run_set_table_anywhere(
    robot: str,
    seed: int,
    faults: frozenset[str] = frozenset(),
    db_url: str | None = None,
    pictures: bool = False,
    stepping: str = DEFAULT_STEPPING,
    environment: str = "apartment",
) -> dict[str, Any]:
    """The ``set-table-anywhere`` scenario of `pycram experiment`: `run_set_table` with the
    ``anywhere`` starts -- all six breakfast types anywhere on the worktops, in the drawers, on
    the fridge's shelves and in the cupboard, wherever some standing pose of `robot` reaches
    them (`anywhere_scene`) -- in `environment` (``apartment``, ``procedural:SEED``, ...)."""
    return _run_set_table(robot, seed, faults, db_url, pictures, None, True, stepping, "anywhere", environment)


# the fault names `pycram experiment --faults all` expands to (read by the scenario registry)
run_set_table.FAULTS = FAULTS  # type: ignore[attr-defined]
run_set_table_on_open_surfaces.FAULTS = FAULTS  # type: ignore[attr-defined]
run_set_table_anywhere.FAULTS = FAULTS  # type: ignore[attr-defined]
