"""`pycram demo`: the thesis demo in the simulated kitchen, headless, with pictures.

Builds the kitchen with the chosen robot and the item at the chosen position, activates the
robot and the kitchen's location resolvers, runs `kitchen_plan.fetch_and_place` while showing
live progress, then prints the task tree, writes snapshots, an animation (each frame captioned
with the plan's phase and the simulated time), the task-tree SVG and the timeline PNG to the
run's own output folder, and returns 0 only when the item rests on cooker #1.

SIGINT (Ctrl-C) and SIGTERM stop the plan (the robot stops), the pictures of what happened are
still written, the run is recorded as "interrupted" with the reason, and the exit code is 130 /
143; a second signal while stopping exits at once (`pycram.core.interrupts.StopSignals`).

A recorded run stores what it needs to run again and its fingerprint (`pycram.apps.replay`:
`pycram replay RUN`). With `until` (`pycram demo --until T`), the world stops at simulated time
T, the scene and belief pictures and the task tree so far are written (`write_stop_pictures`),
and the plan is stopped there.
"""

from __future__ import annotations

import contextlib
import logging
import math
import os
import random
import signal
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from pycram.apps.run_options import check_stepping, check_until
from pycram.apps.terminal import (
    STOP_PICTURE_SIZE,
    log_to_terminal,
    run_failure_text,
    stderr_console,
    task_tree_display,
    write_run_pictures,
    write_stop_pictures,
)
from pycram.core.runtime.lockstep import DEFAULT_STEPPING, LockstepClock, PlanThread
from pycram.world.robot_registry import DEFAULT_ROBOT, robot_choices, robot_names

if TYPE_CHECKING:  # imported where used: the ROS backend is optional
    from pycram.apps.demos.ros_kitchen_world import RosSimEnvironment

log = logging.getLogger("pycram.demo")

#: A plan that has not ended after this much simulated time is evaporated and reported as
#: failed [s]. The default run needs about 20 s, three failed grasps about 40 s.
SIM_TIME_LIMIT = 300.0
#: Backstop for a simulation that stops advancing (e.g. a crashed simulator thread) [s of wall
#: time]. Neither limit applies with `--interactive`, where a person may take their time.
WALL_TIME_LIMIT = 600.0
#: The animation: frames per second of simulated time, and how much faster it plays.
ANIMATION_FPS = 8.0
ANIMATION_SPEED_UP = 2.0
#: How long [s of wall time] the animation's recorder may take to render the frames still
#: pending when the plan ended (a few seconds normally; much more on a heavily loaded machine).
RENDER_CATCH_UP = 300.0
#: Size of the animation's frames [px]; snapshots are 640 x 480.
ANIMATION_SIZE = (480, 360)
#: Where the pictures' camera frames bodies [m]: the kitchen (x_min, y_min, x_max, y_max); an
#: item put aside out of the kitchen is not followed.
KITCHEN_REGION = (-1.3, -1.8, 3.2, 3.6)
#: The camera looks at the robot and the item from the side facing this point [m] (the open
#: corner of the room, away from the walls).
ROOM_MIDDLE = (2.0, 2.0)


@dataclass
class DemoOptions:
    robot: str = DEFAULT_ROBOT
    output: Path | None = None
    item_at: int = 1
    steal: int = 0
    seed: int = 0
    realtime: bool = False
    interactive: bool = False
    db: str | None = None
    record: bool = True
    quiet: bool = False
    animation: bool = True  # record run.gif (False: no animation, a faster run)
    pictures: bool = True  # write start/end snapshots and the run's pictures (False: none, no folder)
    backend: str = "sim"  # "sim": process modules call the simulator; "ros": over ROS 1 (pycram.ros)
    # sim only: "lockstep" (default) stands the simulation still while plan code runs; "free" does not
    stepping: str | None = None
    # sim only: stop the run at this simulated time [s], writing the pictures and the task tree so far
    until: float | None = None


@dataclass
class DemoResult:
    """What a demo run produced: exit code, message, counts and where the pictures are."""

    exit_code: int
    message: str
    output: Path
    run_id: Any = None
    sim_time: float = 0.0  # simulated time the plan ran [s]
    wall_time: float = 0.0  # wall time of the whole run: world, plan, pictures [s]
    plan_wall_time: float = 0.0  # wall time the plan ran [s]
    failed_grasps: int = 0
    recoveries: int = 0
    item_on_cooker_1: bool = False
    interrupted: bool = False  # stopped by SIGINT/SIGTERM (exit code 130/143)
    files: list[Path] = field(default_factory=list)
    captions: list[tuple[float, str]] = field(default_factory=list)  # the animation's (sim time [s], caption)
    tree_text: str = ""  # the plan's task tree as plain text, one line per task
    plan_task: Any = None  # the plan's task (`pycram.runtime.Task`), root of its task tree
    trace_loss: str | None = None  # "N trace records could not be written: why", if any were lost
    final_poses: dict[str, Any] = field(default_factory=dict)  # the robot's base and the items at the end
    #: The world's state every simulated second (`pycram.sim.World.trajectory`; empty over ROS).
    trajectory: list[Any] = field(default_factory=list)
    #: With `DemoOptions.until`: the simulated time [s] the run was stopped at (None: it was not),
    #: and the folder the pictures and the task tree of that moment went to.
    stopped_at: float | None = None
    stop_folder: Path | None = None

    @property
    def speed_factor(self) -> float:
        """Simulated time per wall time while the plan ran (> 1: faster than real time)."""
        return self.sim_time / self.plan_wall_time if self.plan_wall_time > 0 else 0.0


def default_output(robot: str, run_id: Any = None) -> Path:
    """The run's own folder: `output/demo-ROBOT-RUNID` for a recorded run, else
    `output/demo-ROBOT-YYYYmmdd-HHMMSS` (with a suffix if that folder exists already)."""
    if run_id is not None:
        return Path("output") / f"demo-{robot}-{run_id}"
    stem = Path("output") / f"demo-{robot}-{time.strftime('%Y%m%d-%H%M%S')}"
    folder, n = stem, 1
    while folder.exists():
        n += 1
        folder = stem.with_name(f"{stem.name}-{n}")
    return folder


class PlanRun:
    """The plan, run as task `fetch_and_place` in a thread of its own, so the driver can watch it.

    `task` is the plan's task (its whole tree, the reset included); `error` is what made the
    plan fail (e.g. `NoItemGrasped`), its evaporation on a time limit or Ctrl-C, or a bug.
    """

    def __init__(self, plan: Any, robot: Any, facts: Any) -> None:
        self.plan, self.robot, self.facts = plan, robot, facts
        self.task: Any = None
        self.error: BaseException | None = None
        self._thread = PlanThread(target=self._run, name="pycram-demo-plan", daemon=True, hand_over=True)
        self._started_wall = self._ended_wall = 0.0
        self._started_sim = 0.0

    def start(self, sim_now: float) -> None:
        self._started_sim = sim_now
        self._started_wall = time.monotonic()
        self._thread.start()

    def _run(self) -> None:
        from pycram.core.runtime import current_task, end_thread_root, run_subtask

        def whole_plan() -> Any:
            self.task = current_task()
            with self.robot, self.facts:
                return self.plan.fetch_and_place()

        try:
            run_subtask("fetch_and_place", whole_plan, kind="plan")
        except BaseException as error:  # the plan failed, or was evaporated
            self.error = error
        finally:
            end_thread_root(self.error)  # the thread's root task ends with the thread, as the plan did
            self._ended_wall = time.monotonic()

    def join(self, timeout: float) -> bool:
        """Wait at most `timeout` [s of wall time] for the plan's thread; True once it ended."""
        self._thread.join(timeout)
        return not self._thread.is_alive()

    def stop(self, timeout: float = 10.0) -> None:
        """Evaporate the plan and wait (at most `timeout` [s]) for its thread to end."""
        if self.task is not None:
            self.task.evaporate()
        self._thread.join(timeout)

    @property
    def wall_time(self) -> float:
        """Wall time [s] from the start to the end of the plan (or to now while it runs)."""
        end = self._ended_wall or time.monotonic()
        return end - self._started_wall

    def sim_time(self, sim_now: float) -> float:
        """Simulated time [s] the plan ran; `sim_now` is the simulation's current time."""
        if self.task is not None and self.task.end_time is not None and self.task.start_time is not None:
            return self.task.end_time - self.task.start_time
        return sim_now - self._started_sim


def run_demo(options: DemoOptions, stop: Any = None) -> DemoResult:
    """Run the demo once; never raises for plan failures (they are in the result).

    `stop` (a `pycram.core.interrupts.StopSignals`, e.g. the one `main` installs): once it is
    requested, the plan is stopped, the pictures are written, and the run ends "interrupted"
    with the signal's exit code (130 / 143). A `KeyboardInterrupt` while the plan runs counts as
    SIGINT. The output folder is `options.output`, else the run's own (`default_output`).
    """
    from pycram.core.interrupts import StopSignals

    if options.item_at not in (0, 1, 2, 3):
        raise ValueError(f"--item-at must be 0 (no item) or a position 1, 2 or 3, not {options.item_at}")
    if options.backend not in ("sim", "ros"):
        raise ValueError(f"--backend must be 'sim' or 'ros', not {options.backend!r}")
    if options.robot not in robot_names():
        raise ValueError(f"--robot must be {robot_choices()}, not {options.robot!r}")
    if options.stepping is not None:
        check_stepping(options.stepping)
        if options.backend != "sim":
            raise ValueError("--stepping applies to --backend sim only (over ROS the bridge keeps the time)")
    check_until(options.until)
    if options.until is not None and options.backend != "sim":
        raise ValueError("--until applies to --backend sim only")
    stop = stop if stop is not None else StopSignals()  # never signalled unless entered
    started_wall = time.monotonic()
    recorder = _start_recorder(options, plan_name="kitchen demo (fetch and place)")
    run_id = recorder.run_id if recorder is not None else None
    output = Path(options.output) if options.output else default_output(options.robot, run_id)
    result = DemoResult(exit_code=1, message="", output=output, run_id=run_id)
    error: BaseException | None = None
    try:
        if options.pictures:
            output.mkdir(parents=True, exist_ok=True)
        _run_in_world(options, result, recorder, stop)
    except BaseException as exc:
        error = exc
        raise
    finally:
        result.wall_time = time.monotonic() - started_wall
        if isinstance(error, KeyboardInterrupt):
            stop.request(signal.SIGINT)
        if stop.requested:
            _mark_interrupted(result, stop)
        if recorder is not None:
            outcome = "succeeded" if result.exit_code == 0 else "interrupted" if result.interrupted else "failed"
            reason = result.message if result.exit_code != 0 else None
            if result.stopped_at is not None:
                outcome, reason = "interrupted", result.message
            if error is not None and not isinstance(error, KeyboardInterrupt):
                reason = f"{type(error).__name__}: {error}"
            if error is None:
                _record_replay_info(recorder, options, result)
            result.run_id = recorder.finish(outcome, reason)
            result.trace_loss = recorder.loss_report()
    if recorder is not None and options.pictures:
        result.files.extend(write_run_pictures(result.run_id, result.plan_task, result.output, recorder.url))
    return result


def _record_replay_info(recorder: Any, options: DemoOptions, result: DemoResult) -> None:
    """Store in the run's info what `pycram replay` needs to run it again, and -- for a run that
    ended by itself, not stopped by a signal or `until` -- its fingerprint."""
    from pycram.trace.fingerprint import recording_info

    replay_options: dict[str, Any] = {"item_at": options.item_at, "steal": options.steal, "pictures": options.pictures}
    if options.interactive:
        replay_options["interactive"] = True
    if options.until is not None:
        replay_options["until"] = options.until
    finished = not result.interrupted and result.stopped_at is None and result.plan_task is not None
    info = recording_info(
        "thesis",
        options.robot,
        "thesis-kitchen",
        options.seed,
        options.stepping or DEFAULT_STEPPING,
        replay_options,
        backend=options.backend,
        fingerprint=(result.plan_task, result.final_poses, result.trajectory) if finished else None,
    )
    recorder.set_run_info(**info)


def _mark_interrupted(result: DemoResult, stop: Any) -> None:
    """Make `result` say that a signal ended the run (exit code 130/143), and what had happened."""
    result.interrupted = True
    result.exit_code = stop.exit_code
    if result.item_on_cooker_1:
        result.message = f"{stop.reason} after the plan had placed the item on cooker #1"
    elif result.plan_task is None:
        result.message = f"{stop.reason} before the plan started"
    else:
        result.message = (
            f"{stop.reason} after {result.sim_time:.1f} s of simulated time; the plan and the robot were stopped"
        )


def _run_in_world(options: DemoOptions, result: DemoResult, recorder: Any, stop: Any) -> None:
    """Build the kitchen, run the plan in it, fill in `result`, write the pictures."""
    from pycram import robots as robot_packages
    from pycram.apps.demos import kitchen_plan as plan
    from pycram.apps.demos.kitchen_world import (
        ITEM_NAME,
        START_POSE,
        Helper,
        KitchenFacts,
        Operator,
        Thief,
        demo_items,
        operator_resolver,
    )
    from pycram.backends.sim import FollowView, Pose2D, World
    from pycram.backends.sim.render import write_animation
    from pycram.core.runtime import add_task_listener, format_task_tree, remove_task_listener
    from pycram.environments import load as load_environment

    output = result.output
    rng = random.Random(options.seed)
    items = demo_items(options.item_at)
    mug = demo_items(1)[0]  # the mug's size, also when it is not in the kitchen
    camera: Any = "overview"
    world: World | RosSimEnvironment
    if options.backend == "ros":  # plan -> ROS process modules -> roscore -> sim-ros-bridge -> MuJoCo
        from pycram.apps.demos.ros_kitchen_world import open_ros_world

        world, robot = open_ros_world(options.robot, options.item_at, realtime=options.realtime)
        counter_height = load_environment("thesis-kitchen").surface("cooker #1").height
    else:
        world = World(
            options.robot,
            items,
            base_pose=START_POSE,
            realtime=options.realtime,
            stepping=options.stepping or DEFAULT_STEPPING,
            **_picture_size(options),
        )
        robot = None
        counter_height = world.environment.surface("cooker #1").height
        camera = FollowView(
            (world.description.ROOT_LINK, *(item.name for item in items)),
            region=KITCHEN_REGION,
            side_of=ROOM_MIDDLE,
            elevation=-50.0,
            min_distance=2.8,
            margin=2.2,
        )
    thief = None
    story = None
    frames: list = []
    try:
        robot = robot or robot_packages.load(options.robot, world)
        helper = Helper(world, interactive=options.interactive)
        gripper_of = _gripper_mapper(world)
        operator = Operator(helper, gripper_of)
        robot.add_process_module("operator", operator)
        robot.process_module_resolvers.append(operator_resolver(operator))
        facts = KitchenFacts(mug.half_height, counter_height, Pose2D(*START_POSE))
        thief = Thief(world, helper, plan.phase, plan.goal, gripper_of(plan.GRIPPER), options.steal, rng)
        if recorder is not None:
            recorder.set_run_info(robot=options.robot)
            for fluent in (plan.phase, world.base_pose):
                recorder.watch(fluent, fluent.name, max_rate_hz=5.0)
        if options.pictures:
            world.snapshot(output / "start.png", camera=camera)
            result.files.append(output / "start.png")
        plan.forget_state()
        story = _Story(plan, thief, stop)
        add_task_listener(story)
        if options.animation and options.pictures:
            world.start_recording(
                camera, fps=ANIMATION_FPS, width=ANIMATION_SIZE[0], height=ANIMATION_SIZE[1], caption=story.caption
            )
        run = PlanRun(plan, robot, facts)
        if isinstance(world, World):
            from pycram.trace.view.session import attach_views

            attach_views(world, robot.belief, robot)  # a view's start-up is paid before the plan runs
        if options.until is not None and isinstance(world, World):  # (--until is refused over ROS)
            world.hold_at(options.until)
        thief.start()
        run.start(world.sim_time.get_value())
        if isinstance(world.clock, LockstepClock):
            world.clock.leave()  # this thread only watches (by wall time): the plan runs on
        result.message = _watch(run, world, plan, helper, thief, options, stop)
        if result.message == _HELD:  # --until: the world stands at T; look, then stop the plan there
            result.stopped_at = world.sim_time.get_value()
            result.stop_folder = output / f"until-{result.stopped_at:.1f}s"
            title = f"thesis demo · {options.robot} · seed {options.seed} · t={result.stopped_at:.2f} s"
            result.files.extend(write_stop_pictures(world, robot.belief, run.task, result.stop_folder, title))
            result.message = (
                f"stopped at t={result.stopped_at:.2f} s of simulated time (--until {options.until:g}); "
                f"the scene, the belief and the task tree of that moment are in {result.stop_folder}"
            )
            run.stop()  # evaporated while the world stands still: no task ends after T
        if isinstance(world.clock, LockstepClock):
            world.clock.adopt()  # the plan ended (or was stopped): the world stands as it left it
        thief.stop()
        result.plan_wall_time = run.wall_time
        result.sim_time = run.sim_time(world.sim_time.get_value())
        result.plan_task = run.task
        result.tree_text = format_task_tree(run.task) if run.task is not None else ""
        result.failed_grasps = failed_grasps(run.task)
        result.recoveries = recoveries(run.task)
        result.item_on_cooker_1 = _item_on_cooker_1(world, ITEM_NAME, counter_height) if items else False
        result.final_poses = {"base": world.base_pose.get_value(), **world.item_poses.get_value()}
        result.trajectory = world.trajectory() if hasattr(world, "trajectory") else []
        if options.pictures:
            world.snapshot(output / "end.png", camera=camera)
            result.files.append(output / "end.png")
        # the recorder may lag behind on a busy machine: let it finish rather than lose the end
        frames = world.stop_recording(timeout=RENDER_CATCH_UP) if options.animation and options.pictures else []
        if result.stopped_at is not None:
            result.exit_code = 0  # stopped where asked: the pictures of that moment are written
        elif result.item_on_cooker_1:
            result.exit_code, result.message = 0, "the item rests on cooker #1"
        elif not result.message:
            result.message = _failure_message(run)
    finally:
        if story is not None:
            remove_task_listener(story)
        if thief is not None:
            thief.stop()
        world.close()
    result.captions = list(getattr(frames, "captions", []))
    if frames:  # encoded after the simulation stopped, so the two do not compete for the CPU
        result.files.append(write_animation(output / "run.gif", frames, ANIMATION_SPEED_UP * ANIMATION_FPS))


def _picture_size(options: DemoOptions) -> dict[str, Any]:
    """The world's offscreen size: large enough for the pictures of `--until`, else the default."""
    return {"offscreen_size": STOP_PICTURE_SIZE} if options.until is not None else {}


def _gripper_mapper(world: Any):
    grippers = list(world.gripper_openings)

    def gripper_of(name: str) -> str:
        if name in grippers:
            return name
        if len(grippers) == 1:  # a one-armed robot serves requests for either gripper
            return grippers[0]
        return {"0": "left", "1": "right"}.get(str(name), name)

    return gripper_of


def _item_on_cooker_1(world: Any, item: str, counter_height: float) -> bool:
    """True when `item` stands upright on cooker #1 and no gripper holds it."""
    from pycram.apps.demos.kitchen_world import PLACE_XY

    pose = world.item_poses.get_value().get(item)
    if pose is None:
        return False
    x, y, z = pose.position
    held = any(state.get_value().holding == item for state in world.gripper_states.values())
    on_top = counter_height < z < counter_height + 0.15
    near = math.hypot(x - PLACE_XY[0], y - PLACE_XY[1]) < 0.15
    tilt = _tilt(pose.orientation)
    log.info(
        "the %s ends at (%.2f, %.2f, %.2f), tilted %.0f deg%s",
        item,
        x,
        y,
        z,
        math.degrees(tilt),
        ", held" if held else "",
    )
    return not held and on_top and near and tilt < math.radians(20)


def _tilt(quaternion: tuple[float, float, float, float]) -> float:
    """Angle [rad] between an item's own z axis and the vertical, from its (w, x, y, z) orientation."""
    w, x, y, z = quaternion
    up_z = 1.0 - 2.0 * (x * x + y * y)  # z component of the item's z axis in the map frame
    return math.acos(max(-1.0, min(1.0, up_z)))


def _failed(task: Any) -> bool:
    return task.status.get_value().value == "failed"


def _error(task: Any) -> str:
    return type(task.exception).__name__ if task.exception is not None else ""


def _count(task: Any, predicate) -> int:
    return 0 if task is None else sum(1 for t in task.walk() if predicate(t))


def failed_grasps(plan_task: Any) -> int:
    """How many grasp attempts in the plan's task tree failed with `GraspFailed`."""
    return _count(plan_task, lambda t: t.kind == "step" and _failed(t) and _error(t) == "GraspFailed")


def recoveries(plan_task: Any) -> int:
    """How many transport attempts ended in `retry()` (one per recovered theft)."""
    return _count(plan_task, lambda t: t.kind == "attempt" and _error(t) == "RetryRequested")


def _failure_message(run: PlanRun) -> str:
    """Why the item is not on cooker #1: what stopped the plan, if anything did."""
    if run.error is not None:
        return f"{type(run.error).__name__}: {run.error}"
    return "the plan ended, but the item is not on cooker #1"


def _start_recorder(options: DemoOptions, plan_name: str) -> Any:
    if not options.record:
        return None
    try:
        from pycram.trace import start_recording
    except ImportError:
        log.info("recording unavailable (pycram.trace not installed)")
        return None
    return start_recording(url=options.db, plan=plan_name)


def _watch(run: PlanRun, world: Any, plan: Any, helper: Any, thief: Any, options: DemoOptions, stop: Any) -> str:
    """Show live progress until the plan ends; stop it on a time limit, a stop signal or Ctrl-C.

    Returns "" when the plan ended by itself, otherwise why it was stopped. Without
    `--interactive` the plan is stopped after `SIM_TIME_LIMIT` of simulated time or
    `WALL_TIME_LIMIT` of wall time, whichever comes first: the demo never hangs.
    """
    limited = not options.interactive
    held = getattr(world, "held", None)  # with --until: set once the world stands at that time
    sim_deadline = world.sim_time.get_value() + SIM_TIME_LIMIT
    wall_deadline = time.monotonic() + WALL_TIME_LIMIT
    progress = None if options.quiet else _ProgressLine(run, world, plan, thief)
    if progress is not None:
        helper.prompt = progress.ask  # --interactive: pause the live line while asking
    reason = ""
    with progress or contextlib.nullcontext():
        try:
            # Wake on the end of the plan, and 4 times a second of wall time to refresh the
            # progress line and check the limits (a display refresh, not the plan's logic).
            while not run.join(0.25):
                if progress is not None:
                    progress.refresh()
                if held is not None and held.is_set():
                    return _HELD  # the plan is left as it is, for pictures of this moment
                if stop.requested:
                    reason = stop.reason
                elif limited and world.sim_time.get_value() > sim_deadline:
                    reason = f"the plan did not end within {SIM_TIME_LIMIT:.0f} s of simulated time"
                elif limited and time.monotonic() > wall_deadline:
                    reason = f"the plan did not end within {WALL_TIME_LIMIT:.0f} s of wall time"
                if reason:
                    break
        except KeyboardInterrupt:  # no StopSignals installed (library use): Ctrl-C raised here
            stop.request(signal.SIGINT)
            reason = stop.reason
        if not reason and stop.requested:  # the signal came as the plan ended
            reason = stop.reason
        if reason:
            log.warning("stopping the plan: %s", reason)
            run.stop()
    return reason


#: What `_watch` returns when the world holds at `DemoOptions.until`.
_HELD = "held at --until"


class _Story:
    """What the animation's captions say: the plan's phase in words, with the failed grasps
    (counted as `grab_item` tasks fail: a task listener, O(1) per task end), the thefts and the
    recovery (read from the simulated gripper: this is for people watching, not for the plan).
    `caption` is called by the simulation thread at each frame time: it only reads."""

    GRASP_POSITIONS = 3

    def __init__(self, plan: Any, thief: Any, stop: Any) -> None:
        self.plan, self.thief, self.stop = plan, thief, stop
        self.failed_grasps = 0

    def task_started(self, task: Any) -> None:
        pass

    def task_ended(self, task: Any) -> None:
        if task.name == "grab_item" and _failed(task):
            self.failed_grasps += 1

    def caption(self) -> str:
        if self.stop.requested:
            return f"{self.stop.reason}: stopping"
        phase = self.plan.phase.get_value()
        failed, stolen = self.failed_grasps, self.thief.stolen
        if phase == "fetching":
            if failed:
                return f"fetching: grasp {failed} of {self.GRASP_POSITIONS} failed, trying position {failed + 1}"
            return f"fetching: grasp 1 of {self.GRASP_POSITIONS}"
        if phase == "transporting":
            if stolen and self.thief.world.gripper_states[self.thief.gripper].get_value().holding is None:
                return f"item taken ({stolen}x): recovering"  # until the gripper holds it again
            return f"transporting (recovered {stolen}x)" if stolen else "transporting"
        if phase == "failed" and failed >= self.GRASP_POSITIONS:
            return f"failed: all {self.GRASP_POSITIONS} grasps failed"
        return {"initialising": "getting ready", "resetting": "resetting the robot"}.get(phase, phase)


class _ProgressLine:
    """One live terminal line: step, failed grasps, recoveries, thefts, simulated and wall time."""

    def __init__(self, run: PlanRun, world: Any, plan: Any, thief: Any) -> None:
        from rich.live import Live

        self.run, self.world, self.plan, self.thief = run, world, plan, thief
        self._started = time.monotonic()
        self._live = Live(self._text(), console=stderr_console(), refresh_per_second=4, transient=False)

    def _text(self) -> str:
        task = self.run.task
        return (
            f"step: {self.plan.phase.get_value():<13} failed grasps: {failed_grasps(task)}  "
            f"recoveries: {recoveries(task)}  "
            f"thefts: {self.thief.stolen}  sim {self.world.sim_time.get_value():6.1f} s  "
            f"wall {time.monotonic() - self._started:5.1f} s"
        )

    def __enter__(self) -> _ProgressLine:
        self._live.__enter__()
        return self

    def refresh(self) -> None:
        self._live.update(self._text())

    def ask(self, question: str) -> str:
        """Ask the user at the terminal, with the live line paused so it does not hide the question."""
        self._live.stop()
        try:
            return input(question)
        finally:
            self._live.start()

    def __exit__(self, *exc: Any) -> None:
        self.refresh()
        self._live.__exit__(*exc)


def main(
    robot: str = DEFAULT_ROBOT,
    output: str | None = None,
    item_at: int = 1,
    steal: int = 0,
    seed: int = 0,
    realtime: bool = False,
    interactive: bool = False,
    db: str | None = None,
    record: bool = True,
    quiet: bool = False,
    animation: bool = True,
    backend: str = "sim",
    stepping: str | None = None,
    until: float | None = None,
) -> int:
    """Run the demo, print the task tree and a summary; return the process exit code (0: the item
    rests on cooker #1, or the run was stopped at `until` and its pictures written; 130 / 143:
    stopped by SIGINT / SIGTERM; 2: bad options; 1: failed)."""
    from rich.console import Console
    from rich.markup import escape as markup_escape

    from pycram.core.interrupts import StopSignals

    if not quiet:
        log_to_terminal()
    os.environ.setdefault("MUJOCO_GL", "egl")
    console = Console()
    options = DemoOptions(
        robot=robot,
        output=Path(output) if output else None,
        item_at=item_at,
        steal=steal,
        seed=seed,
        realtime=realtime,
        interactive=interactive,
        db=db,
        record=record,
        quiet=quiet,
        animation=animation,
        backend=backend,
        stepping=stepping,
        until=until,
    )
    try:
        with StopSignals(on_second=lambda: stderr_console().show_cursor(True)) as stop:
            result = run_demo(options, stop)
    except ValueError as error:  # an option out of range: say which, no traceback
        console.print(f"[bold red]pycram demo:[/bold red] {error}", highlight=False)
        return 2
    console.print()
    console.print(task_tree_display(result.plan_task, result.run_id, options.db, result.tree_text))
    console.print(
        f"\nthe plan simulated {result.sim_time:.1f} s in {result.plan_wall_time:.2f} s of wall time "
        f"({result.speed_factor:.1f}x real time); the whole run took {result.wall_time:.1f} s"
    )
    console.print(f"failed grasps: {result.failed_grasps}, recoveries: {result.recoveries}")
    console.print(f"pictures in {result.output.resolve()}: " + ", ".join(p.name for p in result.files))
    if result.run_id is not None:
        console.print(f"recorded as run {result.run_id} (see `pycram show {result.run_id}`)")
    if result.trace_loss:
        console.print(f"[yellow]trace of run {result.run_id} incomplete: {result.trace_loss}[/yellow]", highlight=False)
    if result.stopped_at is not None:
        console.print(f"[bold yellow]STOPPED[/bold yellow]: {result.message}", highlight=False)
        return result.exit_code
    colour = "green" if result.exit_code == 0 else "yellow" if result.interrupted else "red"
    verdict = "SUCCESS" if result.exit_code == 0 else "INTERRUPTED" if result.interrupted else "FAILURE"
    told = result.message if result.exit_code == 0 else run_failure_text(result.message, result.plan_task)
    console.print(f"[bold {colour}]{verdict}[/bold {colour}]: {markup_escape(told)}", soft_wrap=True)
    return result.exit_code
