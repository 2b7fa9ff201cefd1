"""`World`: a simulated kitchen with one robot, run by its own simulation thread.

The simulation thread is the only thread that touches MuJoCo. Other threads

- send commands (`drive_to`, `move_arm`, `reach`, `set_gripper`, `track_point`, ...), each of
  which returns a `CommandHandle` at once (its `result` fluent gets the `Outcome`), and
- read sensor fluents, updated at `sensor_rate` [Hz] of simulated time (at most once per
  control tick of `control_period` [s], and also right after a command ends): `base_pose`,
  `joint_states`, `gripper_openings[g]`, `gripper_states[g]`, `tool_poses`, `item_poses`,
  `container_states` (joint position of each drawer and door), `sim_time`, and `camera_image`
  (on request).

While it runs, the world's `ManualClock` is the active PyCRAM clock: `pycram.sleep` and fluent
time-outs follow simulated time. Headless it runs as fast as it can; `realtime=True` paces it to
`realtime_factor` x wall time: over any interval, simulated time advances by at most
`realtime_factor` x (wall time + `REALTIME_SLACK`); a machine that cannot keep up runs slower,
and never races afterwards to catch up.
"""

from __future__ import annotations

import atexit
import copy
import logging
import queue
import threading
import time
import weakref
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, cast

import numpy as np

from pycram.environments import DEFAULT_ENVIRONMENT
from pycram.environments import load as load_environment
from pycram.world.environment import Environment
from pycram.world.objects import object_type
from pycram.world.scenes import random_scene
from pycram.world.types import Outcome, Pose, Pose2D, Quat, Vec3, VisibleItem

from ._runtime import Fluent, ManualClock, current_clock, set_clock
from .camera import FollowView
from .controllers import BaseDrive, Controller, GiveItem, GripperCommand, HeadPointing, Instant, JointTrajectory, Reach
from .engine import Engine
from .environment_builder import OBSTACLE_PARKING
from .errors import UnknownNameError, WorldClosedError
from .furniture import ContainerPush
from .handle import CommandHandle
from .items import ItemSpec
from .path_drive import PlannedDrive
from .perception import MAX_RANGE, MIN_PIXELS, PerceptionFaults, measure_detections, view_of
from .recording import DEFAULT_MAX_PENDING, FrameRecorder, RecordedFrames, StateSnapshot
from .render import Renderers, write_animation, write_png
from .robot_model import HEAD_CAMERA
from .scene import build_scene

if TYPE_CHECKING:
    from .prospection import SimProspection

_log = logging.getLogger(__name__)

#: The thesis kitchen's start pose [m, m, rad] (on the free floor between the counters).
DEFAULT_BASE_POSE = (0.8, 0.6, 0.0)
#: Clocks of closed worlds -> the clock that was active before each (to skip them when restoring).
_CLOSED_CLOCKS: weakref.WeakKeyDictionary[ManualClock, Any] = weakref.WeakKeyDictionary()
_CLOCK_LOCK = threading.Lock()
#: In real-time mode, how far [s of wall time] the simulation may fall behind before it stops
#: trying to catch up (it then paces from where it is).
REALTIME_SLACK = 0.05
#: Worlds not closed yet: closed at interpreter exit, so that no simulation or recorder thread
#: is still inside MuJoCo (or the GL driver) while the interpreter and its libraries shut down.
_LIVE_WORLDS: weakref.WeakSet[World] = weakref.WeakSet()


@atexit.register
def _close_live_worlds() -> None:
    for world in list(_LIVE_WORLDS):
        try:
            world.close()
        except BaseException:  # noqa: BLE001 - exiting anyway; never mask the exit
            _log.debug("closing a world at exit failed", exc_info=True)


class World:
    """An environment (default: the thesis kitchen), a robot ("pr2" or "tiago") and items,
    simulated in a background thread. The robot starts at `base_pose` (default: the
    environment's place "start").

    Items are given as `ItemSpec`s (`items`; by default the thesis kitchen's `DEFAULT_ITEMS`
    there and none elsewhere) and/or as object type names (`objects`, e.g. ``["cup", "bowl",
    "cup"]``), which are placed at random, non-overlapping spots on the environment's surfaces
    and inside its containers (only on the surfaces named in `supports`, when given), the same
    for the same `seed` (see `pycram.world.scenes`); they are named after their type ("cup", "cup
    2") and `placements` says where each started.

    Construction builds the scene (< 1 s) and starts the thread. `close()` (or leaving the
    `with` block) stops it and joins it; every command still running ends with reason "closed".
    All public methods are thread-safe and never block unless documented (`snapshot`,
    `stop_recording`, `wait_*`).
    """

    def __init__(
        self,
        robot: str = "pr2",
        items: Sequence[ItemSpec] | None = None,
        *,
        environment: str | Environment = DEFAULT_ENVIRONMENT,
        objects: Sequence[str] | None = None,
        seed: int = 0,
        supports: Sequence[str] | None = None,
        base_pose: tuple[float, float, float] | None = None,
        realtime: bool = False,
        realtime_factor: float = 1.0,
        sensor_rate: float = 50.0,
        control_period: float = 0.01,
        offscreen_size: tuple[int, int] = (640, 480),
        activate_clock: bool = True,
        perception_faults: PerceptionFaults | None = None,
    ) -> None:
        env = load_environment(environment)
        #: Faults of `detect` (none by default); its random generator is seeded from them.
        self.perception_faults = perception_faults or PerceptionFaults()
        self._fault_rng = np.random.default_rng(self.perception_faults.seed)
        #: Where the `objects` started (a random scene from `seed`; empty without objects).
        #: `supports` (surface names) restricts where they may start.
        self.placements = random_scene(env, objects, seed, supports=supports) if objects else []
        if self.placements:
            items = list(items or []) + [
                ItemSpec.of(object_type(p.type), p.name, p.position, p.yaw) for p in self.placements
            ]
        self.scene = build_scene(robot, items, offscreen_size, env)
        self.description = self.scene.description
        #: The environment's description (data: surfaces, containers, places, free floor).
        self.environment = self.scene.environment
        if base_pose is None:
            base_pose = self.environment.start_pose
        self.robot = robot
        self.realtime, self.realtime_factor = realtime, realtime_factor
        self._steps_per_tick = max(1, round(control_period / self.scene.model.opt.timestep))
        self._sensor_period = 1.0 / sensor_rate
        self.clock = ManualClock(0.0)
        self._engine = Engine(self.scene, base_pose)  # touched only by the simulation thread from now on
        eng = self._engine
        # --- sensor fluents
        self.sim_time = Fluent(0.0, name="sim_time")
        self.base_pose = Fluent(eng.base_pose(), name="base_pose")
        self.joint_states = Fluent(eng.joint_states(), name="joint_states")
        self.gripper_openings = {
            g: Fluent(eng.gripper_state(g).opening, name=f"{g}_gripper_opening") for g in eng.grippers
        }
        self.gripper_states = {g: Fluent(eng.gripper_state(g), name=f"{g}_gripper_state") for g in eng.grippers}
        self.tool_poses = Fluent(self._tool_poses(), name="tool_poses")
        self.item_poses = Fluent(self._item_poses(), name="item_poses")
        #: Joint position of every container by name [m for drawers, rad for doors], 0 when closed.
        self.container_states = Fluent(eng.furniture.positions(eng.data), name="container_states")
        self.camera_image = Fluent(None, name="camera_image")
        #: the latest state copied by the simulation thread, for prospection (never its MjData)
        self._state = StateSnapshot.of(eng.data)
        self._prospection: SimProspection | None = None
        # --- command plumbing
        self._inbox: queue.SimpleQueue = queue.SimpleQueue()
        self._lock = threading.Lock()
        self._closed = False
        self._stop = threading.Event()
        self._active: dict[str, tuple[Controller, CommandHandle]] = {}
        self._finished: list[tuple[CommandHandle, Outcome]] = []
        self._recorder: FrameRecorder | None = None  # the running recording (simulation thread's)
        self._recorders: list[FrameRecorder] = []  # every recorder started, for close() to end
        self._renderers: Renderers | None = None
        self._perception_renderers: Renderers | None = None
        self.error: BaseException | None = None
        self._previous_clock = set_clock(self.clock) if activate_clock else None
        self._clock_active = activate_clock
        self._thread = threading.Thread(target=self._run, name=f"pycram-sim-{robot}", daemon=True)
        self._thread.start()
        _LIVE_WORLDS.add(self)

    # ------------------------------------------------------------------ lifecycle
    def __enter__(self) -> World:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    @property
    def running(self) -> bool:
        """True while the simulation thread runs."""
        return self._thread.is_alive()

    def close(self, timeout: float = 10.0) -> None:
        """Stop the simulation thread and wait for it [s of wall time]; idempotent.

        Commands still running end with reason "closed"; a recording still running is ended
        without writing anything (its recorder thread is joined too); the clock that was active
        before this world is re-activated if this world's clock is still the active one.

        Guarantee: on return no thread of this world (simulation, recorders) runs any more
        (unless one hangs in a driver for longer than `timeout`: logged). A `KeyboardInterrupt`
        arriving while it closes does not cut the closing short: it is re-raised afterwards.
        """
        interrupted: BaseException | None = None
        for step in (self._stop_simulation, self._close_recorders, self._deactivate_clock):
            while True:  # each step is idempotent: an interrupted one is simply run again
                try:
                    step(timeout)
                    break
                except KeyboardInterrupt as exc:
                    interrupted = exc
        _LIVE_WORLDS.discard(self)
        if interrupted is not None:
            raise interrupted

    def _stop_simulation(self, timeout: float) -> None:
        self._stop.set()
        if self._thread.is_alive() and threading.current_thread() is not self._thread:
            self._thread.join(timeout)
            if self._thread.is_alive():  # pragma: no cover
                _log.error("simulation thread did not stop within %.1f s", timeout)

    def _close_recorders(self, timeout: float) -> None:
        """End every recorder thread this world started; a recorder is forgotten only once its
        thread has ended (so an interrupted call leaves the rest for the next one)."""
        with self._lock:
            recorders = list(self._recorders)
        for recorder in recorders:
            recorder.close(timeout)
            self._forget_recorder(recorder, abort=False)

    def _deactivate_clock(self, timeout: float = 0.0) -> None:
        """Hand the active clock back (once). Worlds may be closed in any order: the clock of a
        world closed earlier is never re-activated; a later world's active clock stays active."""
        with _CLOCK_LOCK:
            if not self._clock_active:
                return
            self._clock_active = False
            previous = self._previous_clock
            while isinstance(previous, ManualClock) and previous in _CLOSED_CLOCKS:  # its keys
                previous = _CLOSED_CLOCKS[previous]
            _CLOSED_CLOCKS[self.clock] = previous
            if current_clock() is self.clock:
                set_clock(previous)

    # ------------------------------------------------------------------ the thread
    def _run(self) -> None:
        eng = self._engine
        next_sensor = eng.time + self._sensor_period  # the constructor published at eng.time
        wall0, sim0 = time.monotonic(), eng.time
        try:
            while not self._stop.is_set():
                self._drain_inbox()
                t = eng.time
                for channel, (ctrl, _handle) in list(self._active.items()):
                    out = ctrl.update(eng, t)
                    if out is not None:
                        self._end(channel, out, stop=not out.succeeded)
                eng.step(self._steps_per_tick)
                self.clock.advance_to(eng.time)
                due = eng.time >= next_sensor - 1e-9
                if due or self._finished:
                    if due:  # a fixed schedule: exactly `sensor_rate` publications per simulated second
                        next_sensor += self._sensor_period
                        if next_sensor <= eng.time:
                            next_sensor = eng.time + self._sensor_period
                    self._publish()
                    # outcomes are delivered after the sensors show the state they ended in
                    finished, self._finished = self._finished, []
                    for handle, outcome in finished:
                        handle._finish(outcome)
                recorder = self._recorder
                if recorder is not None and recorder.due(eng.time):
                    recorder.capture(eng.data)  # a copy of the state; rendered in the recorder's thread
                if self.realtime:
                    ahead = (eng.time - sim0) / self.realtime_factor - (time.monotonic() - wall0)
                    if ahead > 0:
                        self._stop.wait(ahead)
                    elif ahead < -REALTIME_SLACK:  # fell behind: carry on from here, do not race to catch up
                        wall0, sim0 = time.monotonic(), eng.time
        except BaseException as exc:  # noqa: BLE001 - reported through handles and `error`
            self.error = exc
            _log.exception("simulation thread failed")
        finally:
            self._shutdown()

    def _shutdown(self) -> None:
        reason = "error" if self.error else "closed"
        with self._lock:
            self._closed = True
        for channel in list(self._active):
            self._end(channel, Outcome(False, reason, "world closed"), stop=False)
        finished, self._finished = self._finished, []
        for handle, outcome in finished:
            handle._finish(outcome)
        while True:
            try:
                kind, a, b = self._inbox.get_nowait()
            except queue.Empty:
                break
            if kind == "start":
                b._finish(Outcome(False, reason, "world closed"))
        for renderers in (self._renderers, self._perception_renderers):
            if renderers is not None:
                renderers.close()
        if self._recorder is not None:
            self._recorder.abort()  # never blocks; close() joins the thread
        # wake anybody waiting on simulated time one last time
        self.clock.advance_to(self._engine.time + 1e9)

    def _drain_inbox(self) -> None:
        eng = self._engine
        while True:
            try:
                kind, ctrl, handle = self._inbox.get_nowait()
            except queue.Empty:
                return
            if kind == "cancel":
                for channel, (_ctrl, h) in list(self._active.items()):
                    if h is handle:
                        self._end(channel, Outcome(False, "cancelled", "cancelled"), stop=True)
                continue
            try:
                if ctrl.channel is not None and ctrl.channel in self._active:
                    self._end(ctrl.channel, Outcome(False, "preempted", f"preempted by {handle.name}"), stop=False)
                out = ctrl.start(eng)
            except Exception as exc:  # a bad command must not kill the world
                _log.exception("command %s failed to start", handle.name)
                out = Outcome(False, "error", f"{type(exc).__name__}: {exc}")
            if out is not None:
                if not out.succeeded:
                    ctrl.stop(eng)
                self._finished.append((handle, out))
            elif ctrl.channel is None:
                self._finished.append((handle, Outcome(True, "succeeded")))
            else:
                self._active[ctrl.channel] = (ctrl, handle)

    def _end(self, channel: str, outcome: Outcome, stop: bool) -> None:
        ctrl, handle = self._active.pop(channel)
        if stop or not outcome.succeeded:
            ctrl.stop(self._engine)
        self._finished.append((handle, outcome))

    def _tool_poses(self) -> dict[str, Pose]:
        eng = self._engine
        return {arm: eng.site_pose(s) for arm, s in eng.tool_sites.items()}

    def _item_poses(self) -> dict[str, Pose]:
        eng = self._engine
        return {name: eng.item_pose(name) for name in eng.item_bodies}

    def _publish(self) -> None:
        eng = self._engine
        self._state = StateSnapshot.of(eng.data)  # first: whoever a fluent wakes sees this state
        self.sim_time.set_value(eng.time)
        self.base_pose.set_value(eng.base_pose())
        self.joint_states.set_value(eng.joint_states())
        for g in eng.grippers:
            state = eng.gripper_state(g)
            self.gripper_states[g].set_value(state)
            self.gripper_openings[g].set_value(state.opening)
        self.tool_poses.set_value(self._tool_poses())
        self.item_poses.set_value(self._item_poses())
        if eng.furniture.containers:
            self.container_states.set_value(eng.furniture.positions(eng.data))

    # ------------------------------------------------------------------ submitting
    def submit(self, ctrl: Controller, name: str) -> CommandHandle:
        """Queue a controller for the simulation thread; returns its handle at once."""
        handle = CommandHandle(name, self._cancel)
        with self._lock:
            if self._closed or self._stop.is_set():
                raise WorldClosedError(f"world is closed; cannot run {name}")
            self._inbox.put(("start", ctrl, handle))
        return handle

    def _cancel(self, handle: CommandHandle) -> None:
        with self._lock:
            if not self._closed:
                self._inbox.put(("cancel", None, handle))

    def _call(self, name: str, fn: Callable[..., Any], *args: Any) -> CommandHandle:
        return self.submit(Instant(fn, *args), name)

    def _check_arm(self, arm: str) -> str:
        if arm not in self.description.ARMS:
            raise UnknownNameError("arm", arm, self.description.ARMS)
        return arm

    def _check_gripper(self, gripper: str) -> str:
        if gripper not in self.description.GRIPPERS:
            raise UnknownNameError("gripper", gripper, self.description.GRIPPERS)
        return gripper

    # ------------------------------------------------------------------ robot commands
    def drive_to(self, x: float, y: float, yaw: float, plan_path: bool = True) -> CommandHandle:
        """Drive the base to the map pose (x [m], y [m], yaw [rad]) with the base's limits.

        With `plan_path` the base follows a collision-free path around the environment and the
        obstacles (the straight line where that is free; see `pycram.backends.sim.path_drive`), stops and
        re-plans when the path gets blocked, and ends with "no_path" when there is none; without,
        it drives the straight line whatever is in the way. Ends with "collision"/"blocked"
        (stopped where it is) or "timeout"; value: final `Pose2D`.
        """
        goal = Pose2D(x, y, yaw)
        return self.submit(PlannedDrive(goal) if plan_path else BaseDrive(goal), "drive_to")

    def move_base(self, pose: Pose2D, plan_path: bool = True) -> CommandHandle:
        """`drive_to` with a `Pose2D`."""
        return self.drive_to(pose.x, pose.y, pose.yaw, plan_path)

    def prospection(self) -> SimProspection:
        """The robot's prospection (`pycram.world.prospection.Prospection`) in this world: "what
        if" questions answered on scratch copies of the latest published state (thread-safe;
        never disturbs the simulation). The same object on every call."""
        with self._lock:
            if self._prospection is None:
                from .prospection import SimProspection

                self._prospection = SimProspection(self.scene, lambda: self._state)
            return self._prospection

    def set_torso(self, height: float, duration: float | None = None) -> CommandHandle:
        """Move the torso lift joint to `height` [m]."""
        joint = self.description.TORSO["joint"]
        return self.submit(
            JointTrajectory("torso", [joint], [height], duration, max_velocity=0.1, tolerance=0.005), "set_torso"
        )

    def move_arm(self, arm: str, positions: Sequence[float], duration: float | None = None) -> CommandHandle:
        """Move the joints of `arm` (order: `description.ARMS[arm]["joints"]`) to `positions` [rad]."""
        joints = self.description.ARMS[self._check_arm(arm)]["joints"]
        if len(positions) != len(joints):
            raise ValueError(f"{arm} arm has {len(joints)} joints, got {len(positions)} positions")
        return self.submit(JointTrajectory(f"arm:{arm}", joints, positions, duration), f"move_arm:{arm}")

    def move_arm_to(self, arm: str, configuration: str, duration: float | None = None) -> CommandHandle:
        """Move `arm` to a named configuration of `description.ARM_CONFIGURATIONS[arm]`."""
        configs = self.description.ARM_CONFIGURATIONS[self._check_arm(arm)]
        if configuration not in configs:
            raise UnknownNameError("arm configuration", configuration, configs)
        return self.move_arm(arm, configs[configuration], duration)

    def reach(
        self,
        arm: str,
        position: Sequence[float],
        orientation: Sequence[float] | None = None,
        duration: float | None = None,
        tolerance: float = 0.01,
    ) -> CommandHandle:
        """Move the tool frame of `arm` to `position` [m] (and `orientation` (w, x, y, z) if given).

        Ends with "unreachable" when inverse kinematics finds no solution within the joint limits;
        value: the reached tool `Pose`.
        """
        self._check_arm(arm)
        goal = Pose(
            cast(Vec3, tuple(map(float, position))),
            cast(Quat, tuple(map(float, orientation))) if orientation is not None else (1.0, 0.0, 0.0, 0.0),
        )
        return self.submit(Reach(arm, goal, orientation is not None, duration, tolerance), f"reach:{arm}")

    def point_head(self, point: Sequence[float]) -> CommandHandle:
        """Turn the head camera to `point` [m, map frame]; succeeds when it looks at it (< ~1 deg)."""
        return self.submit(HeadPointing(point), "point_head")

    def track_point(self, point: Sequence[float]) -> CommandHandle:
        """Keep the head camera on `point` [m, map frame], also while driving, until cancelled."""
        return self.submit(HeadPointing(point, track=True), "track_point")

    def set_gripper(self, gripper: str, opening: float, effort: float | None = None) -> CommandHandle:
        """Open/close `gripper` to `opening` [m] with at most `effort` [N] at the finger tips
        (default: the description's `default_effort`); value: measured opening [m].

        The fingers never push harder than `effort` (the applied effort is published in
        `gripper_states[gripper].effort`). Closing on an item that is between the fingers (both
        touching it) grasps it with a weld; closing on nothing grasps nothing; opening wider
        releases a held item. A non-positive effort ends with reason "invalid".
        """
        return self.submit(GripperCommand(self._check_gripper(gripper), opening, effort), f"gripper:{gripper}")

    def cancel(self, part: str) -> CommandHandle:
        """Cancel whatever runs on `part` ("base", "torso", "head", "arm:<arm>", "gripper:<g>")."""

        def fn(eng: Engine) -> bool:
            if part in self._active:
                self._end(part, Outcome(False, "cancelled", "cancelled"), stop=True)
                return True
            return False

        return self._call(f"cancel:{part}", fn)

    # ------------------------------------------------------------------ cameras and perception
    def _get_renderers(self) -> Renderers:
        if self._renderers is None:
            self._renderers = Renderers(self.scene.model)
        return self._renderers

    def _get_perception_renderers(self) -> Renderers:
        """Renderers of object perception, on a copy of the model without multisampling (~2x
        cheaper with a software renderer; the geometry is the model's, the state `eng.data`)."""
        if self._perception_renderers is None:
            model = copy.copy(self.scene.model)  # mj_copyModel: nothing shared afterwards
            model.vis.quality.offsamples = 0
            self._perception_renderers = Renderers(model)
        return self._perception_renderers

    def request_image(
        self, camera: str | FollowView = HEAD_CAMERA, width: int = 320, height: int = 240, hide_objects: bool = False
    ) -> CommandHandle:
        """Render an RGB image (height x width x 3, uint8) from `camera` (a camera name or a
        `FollowView`); also set `camera_image`.

        `hide_objects` leaves the items out of the picture (e.g. a plan to draw a belief on).
        """
        self._check_camera(camera)

        def fn(eng: Engine) -> np.ndarray:
            geoms = [g for gs in eng.item_part_geoms.values() for g in gs] if hide_objects else []
            saved = eng.model.geom_rgba[geoms, 3].copy()
            eng.model.geom_rgba[geoms, 3] = 0.0  # fully transparent geoms are not drawn
            try:
                img = self._get_renderers().rgb(eng.data, camera, width, height)
            finally:
                eng.model.geom_rgba[geoms, 3] = saved
            self.camera_image.set_value(img)
            return img

        return self._call(f"image:{camera}", fn)

    def _check_camera(self, camera: str | FollowView) -> None:
        """Raise for a camera name the scene does not have, or a `FollowView` of unknown bodies."""
        if isinstance(camera, FollowView):
            camera.check(self.scene.model)
        else:
            self.scene.camera(camera)

    def snapshot(
        self,
        path: str | Path,
        camera: str | FollowView = "overview",
        width: int = 640,
        height: int = 480,
        timeout: float = 30.0,
    ) -> Path:
        """Render `camera` (a camera name or a `FollowView`) and write a PNG to `path` (blocks up
        to `timeout` [s of wall time])."""
        handle = self.request_image(camera, width, height)
        _wait_wall(handle, timeout)
        out = handle.outcome
        if out is None or not out.succeeded:
            raise WorldClosedError(f"snapshot failed: {out}")
        return write_png(path, out.value)

    def perceive(self, min_pixels: int = 20, width: int = 320, height: int = 240) -> CommandHandle:
        """Items visible to the head camera (segmentation render): value `list[VisibleItem]`,
        most visible first. An item hidden behind others or outside the view is not reported."""

        def fn(eng: Engine) -> list[VisibleItem]:
            ids = self._get_renderers().segmentation(eng.data, HEAD_CAMERA, width, height)
            seen = []
            for name, geoms in eng.item_part_geoms.items():
                rows, cols = np.nonzero(np.isin(ids, geoms))
                if len(rows) >= min_pixels:
                    seen.append(
                        VisibleItem(
                            name,
                            self.scene.item(name).type,
                            eng.item_pose(name),
                            len(rows),
                            (float(cols.mean()), float(rows.mean())),
                        )
                    )
            return sorted(seen, key=lambda v: -v.pixels)

        return self._call("perceive", fn)

    def detect(
        self, width: int = 320, height: int = 240, min_pixels: int = MIN_PIXELS, max_range: float = MAX_RANGE
    ) -> CommandHandle:
        """One look of the head camera's object perception: value a
        `pycram.world.belief.PerceptionReport` (detections measured from segmentation, depth and
        colour images of `width` x `height` [px], most visible first; the camera view with its
        depth image; the joint positions of the containers whose handle is in the image or that
        an object was seen inside),
        stamped with the simulated time.

        Objects with fewer than `min_pixels` visible pixels or farther than `max_range` [m] are
        not reported; `perception_faults` apply. No simulator names or poses are reported.
        """
        return self._call("detect", lambda eng: self._detect(eng, width, height, min_pixels, max_range))

    def _detect(self, eng: Engine, width: int, height: int, min_pixels: int, max_range: float) -> Any:
        """`detect`'s work, in the simulation thread: render, measure, report."""
        from pycram.world.belief import PerceptionReport

        renderers = self._get_perception_renderers()
        ids, depth = renderers.segmentation_and_depth(eng.data, HEAD_CAMERA, width, height)
        rgb = renderers.rgb(eng.data, HEAD_CAMERA, width, height, shadows=False)
        cam = eng.camera
        view = view_of(eng.data.cam_xpos[cam], eng.data.cam_xmat[cam], float(eng.model.cam_fovy[cam]), depth, max_range)
        objects = {it.name: (it.type, eng.item_part_geoms[it.name]) for it in self.scene.items}
        states = eng.furniture.positions(eng.data) if eng.furniture.containers else {}
        detections = measure_detections(
            ids,
            depth,
            rgb,
            view,
            objects,
            self.environment,
            states,
            self.perception_faults,
            self._fault_rng,
            min_pixels,
        )
        # the joint positions of the containers whose handle is in the image, and of those an
        # object was seen inside (their inside is in view): the belief moves objects in a drawer
        # with its measured opening, so an object's pose and its drawer's opening come together
        in_view = {
            name: q
            for name, q in states.items()
            if view.in_image(self.environment.container(name).handle_position(q))
            or any(d.container == name for d in detections)
        }
        return PerceptionReport(eng.time, tuple(detections), view, in_view)

    def request_segmentation(self, camera: str = HEAD_CAMERA, width: int = 320, height: int = 240) -> CommandHandle:
        """Render geom ids per pixel (height x width, -1: background) from `camera`."""
        self.scene.camera(camera)
        return self._call(
            f"segmentation:{camera}", lambda eng: self._get_renderers().segmentation(eng.data, camera, width, height)
        )

    def start_recording(
        self,
        camera: str | FollowView = "overview",
        fps: float = 10.0,
        width: int = 320,
        height: int = 240,
        *,
        max_pending: int = DEFAULT_MAX_PENDING,
        caption: Callable[[], str] | None = None,
    ) -> CommandHandle:
        """Start recording frames of `camera` (width x height [px]) every 1/`fps` s of simulated
        time, from the simulated time at which the command runs; a recording already running is
        discarded.

        The simulation thread only copies the state at each frame time (microseconds); a
        recorder thread of its own renders and GIF-encodes the frames (`FrameRecorder`), so the
        simulation never waits for rendering. If `max_pending` frames wait to be rendered, a new
        one is dropped (counted and logged when the recording stops). Frames are not limited by
        the world's `offscreen_size`, and are rendered without multisampling.

        `camera` is a camera name or a `FollowView` (a free camera that keeps bodies in view).
        With `caption` (called in the simulation thread at each frame time; it must be quick and
        never block, e.g. read a fluent), each frame carries a caption: its text and the
        simulated time.
        """
        self._check_camera(camera)
        recorder = FrameRecorder(
            self.scene.model,
            camera,
            fps,
            width,
            height,
            max_pending,
            name=f"pycram-recorder-{self.robot}",
            caption=caption,
        )
        with self._lock:
            self._recorders.append(recorder)

        def fn(eng: Engine) -> None:
            previous, self._recorder = self._recorder, recorder
            if previous is not None:
                _log.warning("start_recording: discarding the recording that was running")
                previous.abort()
            recorder.start_at(eng.time)

        try:
            return self._call("start_recording", fn)
        except WorldClosedError:
            self._forget_recorder(recorder, abort=True)
            raise

    def _forget_recorder(self, recorder: FrameRecorder, abort: bool) -> None:
        """Stop tracking `recorder` for `close()`; with `abort`, end its thread first. A recorder
        whose thread still runs is never forgotten (`close()` must end it)."""
        if abort:
            recorder.close()
        if recorder.running:
            return
        with self._lock:
            if recorder in self._recorders:
                self._recorders.remove(recorder)

    def stop_recording(self, path: str | Path | None = None, timeout: float = 30.0) -> list[np.ndarray]:
        """Stop recording; write the animation to `path` (GIF by suffix) if given; return the frames.
        The last frame shows the state at the simulated time the recording stopped.

        Waits for the recorder thread to render the frames still pending and ends it. Blocks up
        to `timeout` [s of wall time]; frames not rendered by then are dropped (logged). Returns
        a `RecordedFrames` (a list of RGB arrays, height x width x 3 uint8, which also carries
        the GIF encoding, so `write_animation` of these frames to a GIF is fast). Raises
        `WorldClosedError` if the world is closed and `SimulationError` if rendering failed;
        `ValueError` from writing when `path` is given but nothing was recorded.
        """
        deadline = time.monotonic() + timeout

        def fn(eng: Engine) -> FrameRecorder | None:
            recorder, self._recorder = self._recorder, None
            if recorder is not None:
                recorder.capture_last(eng.data)  # the animation ends with the state it stopped in
            return recorder

        handle = self._call("stop_recording", fn)
        _wait_wall(handle, timeout)
        out = handle.outcome
        if out is None or not out.succeeded:
            raise WorldClosedError(f"stop_recording failed: {out}")
        recorder: FrameRecorder | None = out.value
        if recorder is None:
            frames = RecordedFrames()
        else:
            try:
                frames = recorder.finish(max(0.0, deadline - time.monotonic()))
            finally:  # if `finish` was interrupted (Ctrl-C), its thread runs on until close()
                self._forget_recorder(recorder, abort=False)
        if path is not None:
            write_animation(path, frames, frames.fps)
        return frames

    # ------------------------------------------------------------------ fault injection
    def take_item(
        self, gripper: str | None = None, item: str | None = None, to: Sequence[float] | None = None
    ) -> CommandHandle:
        """Take an item away, as a person would: out of `gripper` (the item it holds) or `item` by name.

        The item goes to `to` [m] or aside onto the floor beyond the environment. The gripper keeps
        its command, so a closed gripper closes fully. Value: the item's name (None if nothing).
        """
        if gripper is not None:
            self._check_gripper(gripper)
        if item is not None:
            self.scene.item(item)

        def fn(eng: Engine) -> str | None:
            name = item
            if name is None and gripper is not None:
                name = eng.grippers[gripper].holding
            if name is None:
                return None
            eng.set_item_pose(name, cast(Vec3, tuple(to)) if to is not None else eng.aside_position(name))
            return name

        return self._call("take_item", fn)

    def give_item(self, item: str, gripper: str, close: bool = True, timeout: float = 5.0) -> CommandHandle:
        """Hand `item` into `gripper` (opened first if needed) and hold it there until it is grasped.

        With `close` the person closes the gripper on the item; without, the robot must close
        its gripper (e.g. a `setting_gripper` motion) within `timeout` [s of simulated time].
        The command succeeds once the gripper holds the item and fails with "timeout" otherwise.
        """
        self.scene.item(item)
        self._check_gripper(gripper)
        arm = next(a for a, s in self.description.ARMS.items() if s["gripper"] == gripper)
        return self.submit(GiveItem(item, gripper, arm, close, timeout), "give_item")

    def move_item(
        self, item: str, position: Sequence[float], orientation: Sequence[float] = (1.0, 0.0, 0.0, 0.0)
    ) -> CommandHandle:
        """Put `item` at `position` [m] / `orientation` (w, x, y, z), releasing any grasp."""
        self.scene.item(item)
        return self._call("move_item", lambda eng: eng.set_item_pose(item, tuple(position), tuple(orientation)))

    def place_obstacle(self, x: float, y: float) -> CommandHandle:
        """Put a 0.3 x 0.3 x 1 m box on the floor centred at (x, y) [m]; value: its name."""

        def fn(eng: Engine) -> str:
            free = [n for n in eng.obstacles if n not in eng.obstacles_used]
            if not free:
                raise RuntimeError(f"all {len(eng.obstacles)} obstacles are in use")
            name = free[0]
            eng.obstacles_used.add(name)
            eng.place_obstacle(name, x, y)
            return name

        return self._call("place_obstacle", fn)

    def remove_obstacle(self, name: str) -> CommandHandle:
        """Take the obstacle `name` away again."""

        def fn(eng: Engine) -> None:
            if name not in eng.obstacles:
                raise UnknownNameError("obstacle", name, eng.obstacles)
            eng.obstacles_used.discard(name)
            eng.remove_obstacle(name, OBSTACLE_PARKING)

        return self._call("remove_obstacle", fn)

    def set_container_stuck(self, container: str, stuck: bool = True) -> CommandHandle:
        """Fault: make the drawer or door `container` stuck where it is (or free it again).

        A stuck container does not move however hard it is pulled (it is held by a constraint).
        """
        self.environment.container(container)

        def fn(eng: Engine) -> None:
            eng.furniture.set_stuck(eng.data, container, stuck)

        return self._call("set_container_stuck", fn)

    def push_container(
        self, container: str, force: Sequence[float], duration: float, point: Sequence[float] | None = None
    ) -> CommandHandle:
        """A person's hand pushes or pulls `container` with `force` [N, map frame] for `duration`
        [s of simulated time], at its handle (default) or at `point` [m, map frame] on it.

        Value: the container's joint position at the end [m or rad]. The container moves only as
        far as the force overcomes its friction; it keeps moving briefly (damped) afterwards.
        """
        self.environment.container(container)
        return self.submit(ContainerPush(container, force, duration, point), f"push:{container}")

    # ------------------------------------------------------------------ conveniences
    def kitchen_base_pose(self, place: str) -> Pose2D:
        """The description's base pose in front of `place` ("cooker #1", "cooker #2")."""
        poses = self.description.KITCHEN_BASE_POSES
        if place not in poses:
            raise UnknownNameError("place", place, poses)
        return Pose2D(*poses[place])

    def __repr__(self) -> str:
        return f"<World {self.robot} t={self.sim_time.get_value():.2f}s {'running' if self.running else 'closed'}>"


def _wait_wall(handle: CommandHandle, timeout: float) -> None:
    """Wait for `handle` by wall time (for blocking conveniences that must not hang on sim time)."""
    deadline = time.monotonic() + timeout
    while not handle.done and time.monotonic() < deadline:
        handle.wait(0.05)  # wakes on completion or after 0.05 s of the active clock


__all__ = ["World", "DEFAULT_BASE_POSE", "REALTIME_SLACK"]
