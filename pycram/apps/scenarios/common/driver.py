"""Running a scenario's plan: the plan in a thread of its own, watched under time limits -- and a
whole household task (world, faults, plan, judge) from its description as data (`TaskScenario`).

`ScenarioPlan` runs a plan as the root of a task tree in a `PlanThread`; `watch_plan` waits for
it under a budget of simulated and of wall time, calling a progress function and stopping the
world at ``until`` for pictures (set-table's driver uses both). `run_task` runs one household task
of the suite (`pycram.apps.scenarios.clear_table`, ``put_away``, ``serve``) once in an environment
named like `pycram.environments.load` names them (``apartment``, ``procedural:SEED``, ...) and
judges it with the simulator's truth; `run_task_for_experiment` is the same for `pycram
experiment` (headless, a JSON-serialisable dict, recorded into a trace database).
"""

from __future__ import annotations

import logging
import os
import random
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from pycram.apps.run_options import check_until
from pycram.apps.scenarios.common.scene import Goal, TaskScene, reachability
from pycram.core.runtime.lockstep import DEFAULT_STEPPING, LockstepClock, PlanThread

if TYPE_CHECKING:  # set-table's driver imports this module: set-table's modules are imported when used
    from pycram.apps.scenarios.common.faults import TaskFaults
    from pycram.apps.scenarios.common.judge import TaskResult

__all__ = [
    "ScenarioPlan",
    "watch_plan",
    "start_pictures",
    "play",
    "TaskScenario",
    "check_task_inputs",
    "open_task_world",
    "run_task",
    "record_task_replay_info",
    "run_task_for_experiment",
    "task_experiment",
]

log = logging.getLogger("pycram.demo")


class ScenarioPlan:
    """A scenario's plan in a thread of its own (the root of a task tree named `name`), so the
    driver can watch time limits: `body(record)` runs with `robot` active and returns the plan's
    outcomes; `record` is the plan's `PlanRecord`."""

    def __init__(self, robot: Any, body: Callable[[Any], Any], name: str, thread_name: str) -> None:
        from pycram.apps.scenarios.set_table.plan import PlanRecord

        self.robot, self.body, self.name = robot, body, name
        self.record = PlanRecord()
        self.task: Any = None
        self.error: BaseException | None = None
        self.outcomes: Any = None
        self._thread = PlanThread(target=self._run, name=thread_name, daemon=True, hand_over=True)

    def _run(self) -> None:
        from pycram.core.runtime import current_task, end_thread_root, run_subtask

        def whole_plan() -> Any:
            self.task = current_task()
            with self.robot:
                self.outcomes = self.body(self.record)

        try:
            run_subtask(self.name, whole_plan, kind="plan")
        except BaseException as error:  # evaporated (time limit) or a bug
            self.error = error
        finally:
            end_thread_root(self.error)

    def start(self) -> None:
        self._thread.start()

    def join(self, timeout: float) -> bool:
        self._thread.join(timeout)
        return not self._thread.is_alive()

    def stop(self, timeout: float = 30.0) -> None:
        if self.task is not None:
            self.task.evaporate()
        self._thread.join(timeout)


def watch_plan(
    world: Any,
    plan: ScenarioPlan,
    result: Any,
    *,
    sim_start: float,
    sim_limit: float,
    wall_limit: float,
    progress: Callable[[Any, Any, Any], None] | None,
    injector: Any,
    until: float | None,
    folder: Callable[[], Path],
    title: str,
    belief: Any,
) -> None:
    """Wait for the started `plan` (about 4 times a second of wall time calling `progress(world,
    plan, injector)`), stopping it when it runs past `sim_limit` [s] of simulated time from
    `sim_start` or `wall_limit` [s] of wall time (`result.error` says which). With `until` [s of
    simulated time] (the world held there by `World.hold_at`): once the world stands there,
    write the scene and belief pictures and the task tree into ``until-T.Ts`` below `folder()`
    (`result.stop_folder`, `result.stopped_at`), then stop the plan."""
    from pycram.apps.terminal import write_stop_pictures

    if isinstance(world.clock, LockstepClock):
        world.clock.leave()  # this thread only watches (by wall time): the plan runs on
    sim_deadline, wall_deadline = sim_start + sim_limit, time.monotonic() + wall_limit
    while not plan.join(0.25):
        if progress is not None:
            progress(world, plan, injector)
        if until is not None and world.held.is_set():  # the world stands at `until`: look, then stop
            result.stopped_at = world.sim_time.get_value()
            result.stop_folder = folder() / f"until-{result.stopped_at:.1f}s"
            write_stop_pictures(world, belief, plan.task, result.stop_folder, f"{title} · t={result.stopped_at:.2f} s")
            result.error = f"stopped at t={result.stopped_at:.2f} s of simulated time (--until {until:g})"
            plan.stop()  # evaporated while the world stands still: no task ends after `until`
            break
        if world.sim_time.get_value() > sim_deadline:
            result.error = f"TimeoutError: the plan did not end within {sim_limit:.0f} s of simulated time"
        elif time.monotonic() > wall_deadline:
            result.error = f"TimeoutError: the plan did not end within {wall_limit:.0f} s of wall time"
        if result.error:
            log.warning("stopping the plan: %s", result.error)
            plan.stop()
            break
    if isinstance(world.clock, LockstepClock):
        world.clock.adopt()  # the plan ended (or was stopped): the world stands as it left it


def start_pictures(world: Any, output: Path | None, camera: str, animation: bool, caption: Callable[[], str]) -> None:
    """With `output`: write the world's start.png there from `camera` and, with `animation`,
    start recording the frames of run.gif (captioned by `caption()`)."""
    if output is None:
        return
    output.mkdir(parents=True, exist_ok=True)
    world.snapshot(output / "start.png", camera=camera)
    if animation:
        world.start_recording(camera, fps=4.0, width=480, height=360, caption=caption)


def play(
    world: Any,
    plan: ScenarioPlan,
    injector: Any,
    result: Any,
    *,
    sim_limit: float,
    wall_limit: float,
    progress: Callable[[Any, Any, Any], None] | None,
    until: float | None,
    folder: Callable[[], Path],
    title: str,
    belief: Any,
    judge: Callable[[Any], None],
    output: Path | None,
    camera: str,
    animation: bool,
) -> None:
    """Run a scenario's `plan` in `world` with its faults (`injector`) and fill `result`: start
    both (holding the world at `until`), `watch_plan` within `sim_limit` and `wall_limit` [s],
    then note what the concurrency did (`PlanRecord.as_dict`, and from the simulator's truth the
    most objects held at once), the simulated time, the plan's error, the faults injected,
    `judge(outcomes)`'s verdict, the final poses and the trajectory; with `output`, end.png (and
    run.gif with `animation`)."""
    from pycram.apps.scenarios.set_table.judge import _HeldAtOnce

    held_at_once = _HeldAtOnce(world)
    sim_start = world.sim_time.get_value()
    if until is not None:
        world.hold_at(until)
    injector.start()
    plan.start()
    watch_plan(
        world,
        plan,
        result,
        sim_start=sim_start,
        sim_limit=sim_limit,
        wall_limit=wall_limit,
        progress=progress,
        injector=injector,
        until=until,
        folder=folder,
        title=title,
        belief=belief,
    )
    injector.stop()
    held_at_once.stop()
    result.concurrency = {**plan.record.as_dict(), "most_held_at_once": held_at_once.most}
    result.sim_time = world.sim_time.get_value() - sim_start
    if plan.error is not None and result.error is None:
        result.error = f"{type(plan.error).__name__}: {plan.error}"
    result.faults_injected = list(injector.injected)
    judge(plan.outcomes)
    result.final_poses = {"base": world.base_pose.get_value(), **world.item_poses.get_value()}
    result.trajectory = world.trajectory()
    if output is not None:
        world.snapshot(output / "end.png", camera=camera)
        if animation:
            from pycram.backends.sim.render import write_animation

            frames = world.stop_recording(timeout=300.0)
            if frames:
                write_animation(output / "run.gif", frames, 8.0)


@dataclass(frozen=True)
class TaskScenario:
    """A household task as data and functions: its `name` (``clear-table``), a `title` for
    pictures, the `faults` it knows, its budgets of simulated and wall time [s], `scene(environment,
    seed, robot, objects) -> TaskScene` (deterministic per seed), `plan(goals, record) -> outcomes`
    (the robot-agnostic plan), `judge(world, goals, outcomes, result)` (the simulator's truth),
    `done_text` (what success means, one line), `count` (how many objects its scene holds by
    default) and the `environment` it runs in by default."""

    name: str
    title: str
    faults: tuple[str, ...]
    sim_time_limit: float
    wall_time_limit: float
    scene: Callable[..., TaskScene]
    plan: Callable[[list[Goal], Any], Any]
    judge: Callable[[Any, list[Goal], Any, TaskResult], None]
    done_text: str
    count: int
    environment: str = "apartment"


def check_task_inputs(task: TaskScenario, robot: str, seed: Any, faults: Any, environment: str) -> frozenset[str]:
    """Check a run's inputs: raises `ValueError` naming the valid choices for an unknown robot,
    fault or environment name, or a seed that is not an integer >= 0. Returns the fault names."""
    from pycram.apps.scenarios.common.faults import check_task_faults
    from pycram.environments import check_name
    from pycram.robots import ROBOT_NAMES

    if robot not in ROBOT_NAMES:
        raise ValueError(f"unknown robot {robot!r}; valid robots: {', '.join(ROBOT_NAMES)}")
    if not isinstance(seed, int) or isinstance(seed, bool) or seed < 0:
        raise ValueError(f"the seed must be an integer >= 0, not {seed!r}")
    try:
        check_name(environment)
    except KeyError as error:
        raise ValueError(str(error).strip("\"'")) from None
    return check_task_faults(faults, task.faults, task.name)


def open_task_world(
    task: TaskScenario,
    robot: str,
    seed: int,
    kinds: frozenset[str] = frozenset(),
    environment: str = "apartment",
    objects: tuple[str, ...] | None = None,
    stepping: str = DEFAULT_STEPPING,
    offscreen_size: tuple[int, int] | None = None,
) -> tuple[Any, TaskScene]:
    """The environment with the task's objects where its scene for `seed` puts them and `robot`
    at the start pose (perception misses detections with the ``missed`` fault). Returns the world
    and the scene."""
    from pycram.apps.scenarios.set_table.data import MISS_PROBABILITY
    from pycram.backends.sim import ItemSpec, World
    from pycram.backends.sim.perception import PerceptionFaults
    from pycram.environments import load as load_environment
    from pycram.world.objects import object_type

    scene = task.scene(load_environment(environment), seed, robot, objects)
    items = [ItemSpec.of(object_type(p.type), p.name, p.position, p.yaw) for p in scene.placements]
    perception = PerceptionFaults(miss_probability=MISS_PROBABILITY, seed=seed) if "missed" in kinds else None
    size: dict[str, Any] = {"offscreen_size": offscreen_size} if offscreen_size is not None else {}
    world = World(robot, items, environment=environment, perception_faults=perception, stepping=stepping, **size)
    return world, scene


def run_task(
    task: TaskScenario,
    robot: str,
    seed: int,
    faults: Any = frozenset(),
    *,
    environment: str | None = None,
    objects: tuple[str, ...] | None = None,
    recorder: Any = None,
    output: Path | None = None,
    animation: bool = False,
    progress: Callable[[Any, Any, Any], None] | None = None,
    stepping: str = DEFAULT_STEPPING,
    until: float | None = None,
    until_folder: Path | None = None,
) -> tuple[TaskResult, Any]:
    """Run `task` once (see the module docstring); never raises for failures of the plan (they are
    in the result). `environment`: its name (None: the task's own); `objects`: what the scene
    holds (None: the task's default; see each task); with `output`, start.png and end.png are
    written there (and run.gif with `animation`); `recorder` (a trace recorder) is told the
    robot; `progress(world, plan, faults)` is called about 4 times a second; `stepping`:
    "lockstep" for a run that depends on the seed alone; `until` [s of simulated time]: stop
    there and write the pictures of that moment below `until_folder` (default `output`, else
    ``output/NAME-ROBOT-SEED``). Raises `ValueError` for bad inputs (unknown robot, fault,
    environment, object) before anything runs. Returns the result and the plan's task."""
    from pycram import robots as robot_packages
    from pycram.apps.scenarios.common.faults import TaskFaults
    from pycram.apps.scenarios.common.judge import TaskResult
    from pycram.apps.terminal import STOP_PICTURE_SIZE

    environment = environment or task.environment
    kinds = check_task_inputs(task, robot, seed, faults, environment)
    check_until(until)
    started_wall = time.monotonic()
    result = TaskResult(robot, seed, kinds, scenario=task.name, environment=environment, done_text=task.done_text)
    size = STOP_PICTURE_SIZE if until is not None else None
    world, scene = open_task_world(task, robot, seed, kinds, environment, objects, stepping, offscreen_size=size)
    plan: ScenarioPlan | None = None
    injector: TaskFaults | None = None
    robot_handle = None
    try:
        robot_handle = robot_packages.load(robot, world)
        if recorder is not None:
            recorder.set_run_info(robot=robot)
        camera = world.environment.camera.name
        start_pictures(world, output, camera, animation, _caption(task, scene))
        reach = reachability(robot, environment) if kinds & {"moved", "taken"} else None
        rng = random.Random(seed * 7919 + 17)
        injector = TaskFaults(world, kinds, rng, scene.goals, scene.placements, reach)
        goals = scene.goals
        plan = ScenarioPlan(
            robot_handle, lambda record: task.plan(goals, record), task.name.replace("-", "_"), f"pycram-{task.name}"
        )
        play(
            world,
            plan,
            injector,
            result,
            sim_limit=task.sim_time_limit,
            wall_limit=task.wall_time_limit,
            progress=progress,
            until=until,
            folder=lambda: until_folder or output or Path("output") / f"{task.name}-{robot}-{seed}",
            title=f"{task.title} · {robot} · seed {seed}",
            belief=robot_handle.belief,
            judge=lambda outcomes: task.judge(world, goals, outcomes, result),
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


def _caption(task: TaskScenario, scene: TaskScene) -> Callable[[], str]:
    def caption() -> str:
        from pycram.apps.scenarios.set_table.plan import current_object, objects_done

        current = current_object.get_value()
        return f"{task.title}: {objects_done.get_value()}/{len(scene.goals)} done" + (
            f", bringing the {current}" if current else ""
        )

    return caption


def record_task_replay_info(
    recorder: Any,
    task: TaskScenario,
    result: TaskResult | None,
    plan_task: Any,
    *,
    objects: tuple[str, ...] | None,
    stepping: str,
    pictures: bool,
    until: float | None = None,
) -> None:
    """Store in the recorded run's info what `pycram replay` needs to run it again (the scenario,
    robot, environment, seed, faults, objects) and -- for a run that ended by itself -- its
    fingerprint (`pycram.trace.fingerprint.recording_info`). Nothing without a `result`."""
    from pycram.trace.fingerprint import recording_info

    if result is None:
        return
    options: dict[str, Any] = {"faults": sorted(result.faults), "pictures": pictures}
    if objects is not None:
        options["objects"] = list(objects)
    if until is not None:
        options["until"] = until
    finished = result.stopped_at is None and plan_task is not None
    info = recording_info(
        task.name,
        result.robot,
        result.environment,
        result.seed,
        stepping,
        options,
        fingerprint=(plan_task, result.final_poses, result.trajectory) if finished else None,
    )
    recorder.set_run_info(**info)


def run_task_for_experiment(
    task: TaskScenario,
    robot: str,
    seed: int,
    faults: Any = frozenset(),
    db_url: str | None = None,
    pictures: bool = False,
    stepping: str = DEFAULT_STEPPING,
    environment: str | None = None,
    objects: tuple[str, ...] | None = None,
) -> dict[str, Any]:
    """Run `task` once, headless and without animation, for `pycram experiment`: `db_url` records
    the run in that trace database (None: not recorded); `pictures` writes start/end pictures to
    ``output/NAME-ROBOT-SEED`` (with ``-ENVIRONMENT`` for another environment than the task's
    own). Returns a JSON-serialisable dict (`TaskResult.as_dict`, with ``run_id`` and
    ``stepping``); raises `ValueError` for bad inputs."""
    os.environ.setdefault("MUJOCO_GL", "egl")
    environment = environment or task.environment
    check_task_inputs(task, robot, seed, faults, environment)
    recorder = None
    if db_url is not None:
        from pycram.trace import start_recording

        recorder = start_recording(url=db_url, plan=f"{task.title} ({robot}, seed {seed}, {environment})")
    stem = f"{task.name}-{robot}-{seed}" + ("" if environment == task.environment else f"-{environment}")
    output = Path("output") / stem.replace(":", "") if pictures else None
    result: TaskResult | None = None
    plan_task = None
    try:
        result, plan_task = run_task(
            task,
            robot,
            seed,
            faults,
            environment=environment,
            objects=objects,
            recorder=recorder,
            output=output,
            stepping=stepping,
        )
    finally:
        run_id = None
        if recorder is not None:
            record_task_replay_info(
                recorder, task, result, plan_task, objects=objects, stepping=stepping, pictures=pictures
            )
            ok = result is not None and result.success
            run_id = recorder.finish(
                "succeeded" if ok else "failed", None if ok else (result.summary() if result else "error")
            )
    assert result is not None
    out = result.as_dict()
    out["run_id"] = run_id
    out["stepping"] = stepping
    return out


def task_experiment(task: TaskScenario) -> Callable[..., dict[str, Any]]:
    """The scenario function of `task` for `pycram experiment` (see
    `pycram.apps.experiments.scenarios`): ``run(robot, seed, faults, db_url, pictures, stepping,
    environment, objects) -> dict``, `run_task_for_experiment` with `task`; its ``FAULTS`` are
    the task's."""

    def run(
        robot: str,
        seed: int,
        faults: frozenset[str] = frozenset(),
        db_url: str | None = None,
        pictures: bool = False,
        stepping: str = DEFAULT_STEPPING,
        environment: str = task.environment,
        objects: tuple[str, ...] | None = None,
    ) -> dict[str, Any]:
        return run_task_for_experiment(task, robot, seed, faults, db_url, pictures, stepping, environment, objects)

    run.__doc__ = (
        f"The ``{task.name}`` scenario of `pycram experiment`: one run of {task.title!r} in `environment` "
        "(``apartment``, ``procedural:SEED``, ...), judged with the simulator's truth; see "
        "`run_task_for_experiment` for the arguments and the result. Raises `ValueError` for bad inputs."
    )
    run.FAULTS = task.faults  # type: ignore[attr-defined]
    return run
