"""`World`: a simulated kitchen with one robot, run by its own simulation thread.

The simulation thread is the only thread that touches MuJoCo. Other threads

- send commands (`drive_to`, `move_arm`, `reach`, `set_gripper`, `track_point`, ...), each of
  which returns a `CommandHandle` at once (its `result` fluent gets the `Outcome`), and
- read sensor fluents, updated at `sensor_rate` [Hz] of simulated time (at most once per
  control tick of `control_period` [s], and also right after a command ends): `base_pose`,
  `joint_states`, `gripper_openings[g]`, `gripper_states[g]`, `tool_poses`, `item_poses`,
  `container_states` (joint position of each drawer and door), `sim_time`, and `camera_image`
  (on request). `joint_states`, `tool_poses`, `item_poses` and `container_states` are built
  when first read, from the state copied when they were published (`engine.Deferred`): what
  a reader gets is the same, and a value nobody reads costs the simulation a few array copies.

While it runs, the world's `ManualClock` is the active PyCRAM clock: `pycram.sleep` and fluent
time-outs follow simulated time. Headless it runs as fast as it can; `realtime=True` paces it to
`realtime_factor` x wall time: over any interval, simulated time advances by at most
`realtime_factor` x (wall time + `REALTIME_SLACK`); a machine that cannot keep up runs slower,
and never races afterwards to catch up.

The simulation thread also samples the world's state every `TRAJECTORY_PERIOD` of simulated time
(`trajectory()`: the robot's base and joints, every item's pose, the containers' joints), for a
run's fingerprint (`pycram.trace.fingerprint`), and `hold_at(t)` stops it from stepping past a
simulated time while it still serves commands (pictures of the world as it stood at `t`).

This module holds `World` itself: construction, lifecycle (`close`), the simulation thread's loop
and the sensor fluents it publishes. Its commands are grouped by concept in the classes it
inherits: `commands.CommandQueue` (submitting, starting, cancelling and ending commands),
`motion_commands.MotionCommands`, `sensing.Sensing` (cameras and perception),
`recording_commands.RecordingCommands` and `interventions.Interventions` (items, obstacles and
containers moved by a person, fault injection or a test).
"""

from __future__ import annotations

import atexit
import logging
import queue
import threading
import time
import weakref
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from pycram.core.fluent import Fluent
from pycram.core.runtime.clock import ManualClock, current_clock, set_clock
from pycram.core.runtime.lockstep import DEFAULT_STEPPING, STEPPING_MODES, LockstepClock
from pycram.environments import DEFAULT_ENVIRONMENT
from pycram.environments import load as load_environment
from pycram.world.environment import Environment
from pycram.world.objects import object_type
from pycram.world.robot_registry import DEFAULT_ROBOT
from pycram.world.scenes import random_scene
from pycram.world.types import Outcome, Pose, Pose2D

from .controllers import Controller
from .engine import Deferred, Engine
from .errors import UnknownNameError
from .handle import CommandHandle
from .interventions import Interventions
from .items import ItemSpec
from .motion_commands import MotionCommands
from .perception import PerceptionFaults
from .physics_faults import PhysicsWatchdog
from .recording import FrameRecorder, StateSnapshot
from .recording_commands import RecordingCommands
from .render import Renderers
from .scene import build_scene
from .sensing import Sensing

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
#: Simulated time between two samples of `World.trajectory()` [s].
TRAJECTORY_PERIOD = 1.0
#: The parts of the simulation thread's loop that `World.time_spent()` accounts for.
TIME_SPENT_PARTS = ("physics", "controllers", "commands", "sensors", "recording", "plan")
#: Worlds not closed yet: closed at interpreter exit, so that no simulation or recorder thread
#: is still inside MuJoCo (or the GL driver) while the interpreter and its libraries shut down.
_LIVE_WORLDS: weakref.WeakSet[World] = weakref.WeakSet()


def _joint_positions(addresses: dict[str, int], qpos: np.ndarray) -> dict[str, float]:
    """Name -> qpos[address] (a container's joint position [m or rad])."""
    return {n: float(qpos[a]) for n, a in addresses.items()}


@atexit.register
def _close_live_worlds() -> None:
    for world in list(_LIVE_WORLDS):
        try:
            world.close()
        except BaseException:  # noqa: BLE001 - exiting anyway; never mask the exit
            _log.debug("closing a world at exit failed", exc_info=True)


class World(MotionCommands, Sensing, RecordingCommands, Interventions):
    """An environment (default: the thesis kitchen), a robot (a name of `pycram.world.robot_registry`) and items,
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
        robot: str = DEFAULT_ROBOT,
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
        stepping: str = DEFAULT_STEPPING,
    ) -> None:
        if stepping not in STEPPING_MODES:
            raise ValueError(f"stepping must be one of {', '.join(STEPPING_MODES)}, not {stepping!r}")
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
        #: "free" or "lockstep" (see `STEPPING_MODES`).
        self.stepping = stepping
        self.clock = LockstepClock(0.0) if stepping == "lockstep" else ManualClock(0.0)
        if isinstance(self.clock, LockstepClock):
            self.clock.enter()  # the creating thread runs the plan (or waits in PyCRAM for one)
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
        #: The `SimulationFault` that broke the physics, None while it is sound (`physics_faults`).
        self.physics_fault = Fluent(None, name="physics_fault")
        self._watchdog = PhysicsWatchdog(eng, self.environment)
        #: the latest state copied by the simulation thread, for prospection (never its MjData)
        self._state = StateSnapshot.of(eng.data)
        self._prospection: SimProspection | None = None
        self._believed_prospections: list[tuple[Any, SimProspection]] = []  # (belief, its prospection)
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
        # --- trajectory samples (appended by the simulation thread only) and hold_at
        self._trajectory: list[tuple[float, dict[str, tuple[float, ...]]]] = [self._sample_state()]
        self._next_sample = eng.time + TRAJECTORY_PERIOD
        self._hold_cv = threading.Condition(threading.Lock())
        self._hold_at: float | None = None
        #: Set once the simulation stands still at the time given to `hold_at`.
        self.held = threading.Event()
        # wall time [s] the simulation thread spent on each part of its loop (see `time_spent`)
        self._spent = dict.fromkeys(TIME_SPENT_PARTS, 0.0)
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
        if isinstance(self.clock, LockstepClock):
            self.clock.poke()
        with self._hold_cv:
            self._hold_cv.notify_all()
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
        lockstep = self.clock if isinstance(self.clock, LockstepClock) else None
        if lockstep is not None:
            lockstep.steps_here()  # the threads its steps wake run once each step is over
        tick = self._steps_per_tick * float(self.scene.model.opt.timestep)
        spent = self._spent
        clock = time.perf_counter
        try:
            while not self._stop.is_set():
                if lockstep is not None and not lockstep.quiet():
                    # plan code runs: the world stands still (commands wait for the next step)
                    t0 = clock()
                    lockstep.wait_until_quiet(self._stop.is_set)
                    spent["plan"] += clock() - t0
                    continue
                hold = self._hold_at
                if hold is not None and eng.time + tick > hold + 1e-9:
                    self._serve_held()  # the next step would pass `hold`: stand still, serve commands
                    continue
                t0 = clock()
                if not self._inbox.empty():  # (most ticks: nothing was sent)
                    self._drain_inbox()
                self._watchdog.apply(self)
                t1 = clock()
                t = eng.time
                for channel, (ctrl, _handle) in list(self._active.items()):
                    out = ctrl.update(eng, t)
                    if out is not None:
                        self._end(channel, out, stop=not out.succeeded)
                t2 = clock()
                eng.step(self._steps_per_tick)
                t3 = clock()
                spent["commands"] += t1 - t0
                spent["controllers"] += t2 - t1
                spent["physics"] += t3 - t2
                self.clock.advance_to(eng.time)
                if eng.time >= self._next_sample - 1e-9:  # a fixed schedule in simulated time
                    self._trajectory.append(self._sample_state())
                    self._next_sample += TRAJECTORY_PERIOD
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
                t4 = clock()
                recorder = self._recorder
                if recorder is not None and recorder.due(eng.time):
                    recorder.capture(eng.data)  # a copy of the state; rendered in the recorder's thread
                t5 = clock()
                spent["sensors"] += t4 - t3
                spent["recording"] += t5 - t4
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

    def _sample_state(self) -> tuple[float, dict[str, tuple[float, ...]]]:
        """The world's state now, for `trajectory()` (simulation thread; a few microseconds)."""
        eng = self._engine
        data = eng.data
        state: dict[str, tuple[float, ...]] = {
            "base": tuple(float(data.qpos[i]) for i in eng.base_qpos),
            "joints": tuple(float(data.qpos[a]) for _, a, _ in eng.robot_joints),
        }
        for name in eng.item_bodies:
            pose = eng.item_pose(name)
            state[name] = (*pose.position, *pose.orientation)
        if eng.furniture.containers:
            positions = eng.furniture.positions(data)
            state["containers"] = tuple(positions[n] for n in sorted(positions))
        return float(eng.time), state

    def trajectory(self) -> list[tuple[float, dict[str, tuple[float, ...]]]]:
        """The world's state sampled by the simulation thread at its start and then every
        `TRAJECTORY_PERIOD` [s] of simulated time (at the first control tick at or after each
        whole period): a list of (simulated time [s], state), oldest first. Each state maps
        "base" to the base's planar joints (x [m], y [m], yaw [rad], unwrapped), "joints" to the
        robot's joint positions (in the description's order), each item's name to its position
        [m] and orientation (w, x, y, z), and "containers" (if any) to the containers' joint
        positions [m or rad] sorted by name. In lock-step the samples depend on the seed and
        the options alone. Thread-safe; a copy."""
        return list(self._trajectory)

    def time_spent(self) -> dict[str, float]:
        """Wall time [s] the simulation thread has spent so far on each part of its loop:
        "physics" (`mj_step`), "controllers" (each command's control law, every tick),
        "commands" (starting commands: IK, path planning, perception's rendering, pictures),
        "sensors" (publishing the sensor fluents and waking the plan threads waiting on them,
        the trajectory samples), "recording" (copying frames for a recording), and "plan" (in
        lock-step: standing still while plan code ran -- thinking, belief updates, location
        reasoning). What is left of the wall time was spent outside the loop (construction,
        closing, a held world). Approximate while the simulation runs; a copy."""
        return dict(self._spent)

    def hold_at(self, sim_time: float) -> None:
        """Stop stepping before simulated time would pass `sim_time` [s]: the world then stands
        still at the last control tick at or before it (at once if that has passed), publishes
        its sensors once, sets `held`, and from then on only serves commands that need no step
        (pictures, instant commands; motions start but do not move) until `release()` or
        `close()`. Plan code waiting on simulated time waits until then. Thread-safe."""
        if sim_time < 0:
            raise ValueError(f"hold_at needs a simulated time >= 0 [s], not {sim_time!r}")
        with self._hold_cv:
            self._hold_at = float(sim_time)
            self._hold_cv.notify_all()
        if isinstance(self.clock, LockstepClock):
            self.clock.poke()

    def release(self) -> None:
        """Undo `hold_at`: the world steps on (as it did before)."""
        with self._hold_cv:
            self._hold_at = None
            self._hold_cv.notify_all()
        if isinstance(self.clock, LockstepClock):
            self.clock.poke()

    def submit(self, ctrl: Controller, name: str) -> CommandHandle:
        """`CommandQueue.submit`; a held world (`hold_at`) is woken to serve the command."""
        handle = super().submit(ctrl, name)
        if self._hold_at is not None:  # a held world waits for commands, not for the plan
            with self._hold_cv:
                self._hold_cv.notify_all()
        return handle

    def _serve_held(self) -> None:
        """One round of the held world (simulation thread, while every plan thread waits):
        publish once when it starts to hold, then start what was sent and deliver what ended
        (the plan threads that wakes get their turns in `_run`, as after a step), or wait for
        more commands, `release` or `close`."""
        if not self.held.is_set():
            self._publish()
            self.held.set()
            _log.info("the world holds at t=%.3f s of simulated time", self._engine.time)
            return
        self._drain_inbox()
        if self._finished:
            self._publish()
            finished, self._finished = self._finished, []
            for handle, outcome in finished:
                handle._finish(outcome)
            return
        with self._hold_cv:
            while self._hold_at is not None and self._inbox.empty() and not self._stop.is_set():
                self._hold_cv.wait()
            if self._hold_at is None:
                self.held.clear()

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
        # wake anybody waiting on simulated time one last time (no turns any more: nothing steps)
        if isinstance(self.clock, LockstepClock):
            self.clock.stop()
        self.clock.advance_to(self._engine.time + 1e9)

    def _tool_poses(self) -> dict[str, Pose]:
        return self._engine.deferred_tool_poses()()

    def _item_poses(self) -> dict[str, Pose]:
        return self._engine.item_poses()

    def _publish(self) -> None:
        """Set every sensor fluent to the state now (simulation thread). The values that often
        go unread -- `joint_states`, `tool_poses`, `item_poses`, `container_states` -- are
        published as `Deferred`: the few arrays they need are copied now and the value is built
        when first read, so a reader still sees this tick's state and an unread one costs a
        copy; the others are built at once (the relays and callbacks on them read them anyway)."""
        eng = self._engine
        data = eng.data
        self._state = state = StateSnapshot.of(data)  # first: whoever a fluent wakes sees this state
        self.sim_time.set_value(eng.time)
        self.base_pose.set_value(eng.base_pose())
        self.joint_states.set_value(eng.deferred_joint_states())
        for g in eng.grippers:
            gripper = eng.gripper_state(g)
            self.gripper_states[g].set_value(gripper)
            self.gripper_openings[g].set_value(gripper.opening)
        self.tool_poses.set_value(eng.deferred_tool_poses())
        self.item_poses.set_value(eng.deferred_item_poses())
        if eng.furniture.containers:
            self.container_states.set_value(Deferred(_joint_positions, eng.furniture.qpos, state.qpos))

    # ------------------------------------------------------------------ prospection
    def prospection(self, belief: Any = None) -> SimProspection:
        """The robot's prospection (`pycram.world.prospection.Prospection`) in this world: "what
        if" questions answered on scratch copies of a state (thread-safe; never disturbs the
        simulation).

        With `belief` (the robot's `pycram.world.belief.BeliefState`): prospection of the world
        the robot believes in -- the environment's description, the robot's own joints as its
        sensors last published them, the containers as last seen, the objects it perceived,
        named as the belief names them; nothing it did not perceive (see
        `pycram.backends.sim.believed_world`). This is what a robot's reasoning uses. Without:
        prospection of the simulation's true state, as last published (for tools and tests).
        The same object for the same `belief` on every call."""
        with self._lock:
            if belief is None:
                if self._prospection is None:
                    from .prospection import SimProspection

                    self._prospection = SimProspection(self.scene, lambda: self._state)
                return self._prospection
            for known, prospection in self._believed_prospections:
                if known is belief:
                    return prospection
        from .believed_world import BelievedWorld
        from .prospection import SimProspection

        believed = BelievedWorld.of_simulation(self.scene, belief, lambda: self._state)  # compiles outside the lock
        with self._lock:
            for known, prospection in self._believed_prospections:
                if known is belief:
                    return prospection
            prospection = SimProspection(believed.scene, believed.snapshot, believed=believed)
            self._believed_prospections.append((belief, prospection))
            return prospection

    # ------------------------------------------------------------------ conveniences
    def kitchen_base_pose(self, place: str) -> Pose2D:
        """The description's base pose in front of `place` ("cooker #1", "cooker #2")."""
        poses = self.description.KITCHEN_BASE_POSES
        if place not in poses:
            raise UnknownNameError("place", place, poses)
        return Pose2D(*poses[place])

    def __repr__(self) -> str:
        return f"<World {self.robot} t={self.sim_time.get_value():.2f}s {'running' if self.running else 'closed'}>"


__all__ = ["World", "DEFAULT_BASE_POSE", "REALTIME_SLACK", "TIME_SPENT_PARTS", "TRAJECTORY_PERIOD"]
