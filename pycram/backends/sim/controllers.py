"""Controllers: what a command does in the simulation thread, tick by tick.

A controller is started once, updated every control tick (before the physics steps) until it
returns an `Outcome`, and stopped when it is cancelled or preempted. Controllers that share a
`channel` (a part of the robot) preempt each other.

Every controller with an end ends within a bounded simulated time, whatever its input: `start`
refuses (outcome "invalid", nothing moves) goals, durations, tolerances and time-outs that are
not finite numbers or out of range -- a NaN goal would otherwise make a duration NaN, and a
comparison with NaN never ends a motion. Only `HeadPointing(track=True)` runs until cancelled.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Sequence

import mujoco
import numpy as np

from pycram.world.base_kinematics import BaseKinematics, arc_point, arc_radius, drive_moves
from pycram.world.prospection import BasePose
from pycram.world.types import Outcome, Pose2D, wrap_angle

from .engine import Engine
from .profiles import Trapezoid, smoothstep
from .robot_model import BASE_JOINTS

_log = logging.getLogger(__name__)


def ok(value: object = None, message: str = "") -> Outcome:
    return Outcome(True, "succeeded", message, value)


def fail(reason: str, message: str, value: object = None) -> Outcome:
    return Outcome(False, reason, message, value)


def invalid_input(**inputs: object) -> Outcome | None:
    """An "invalid" outcome naming the first input that is not finite, else None.

    Each input is a number, a sequence of numbers, or None (not given); a duration-like input
    named with a `positive_` prefix must also be > 0.
    """
    for name, value in inputs.items():
        if value is None:
            continue
        values = np.atleast_1d(np.asarray(value, dtype=float)) if _numeric(value) else None
        label = name.removeprefix("positive_")
        if values is None or not np.all(np.isfinite(values)):
            return fail("invalid", f"{label} must be finite, got {value!r}")
        if name.startswith("positive_") and not np.all(values > 0):
            return fail("invalid", f"{label} must be positive, got {value!r}")
    return None


def _numeric(value: object) -> bool:
    try:
        np.asarray(value, dtype=float)
        return True
    except (TypeError, ValueError):
        return False


class Controller:
    """Base class; `channel` None means the command takes effect at once (one tick)."""

    channel: str | None = None

    def start(self, eng: Engine) -> Outcome | None:
        """Begin; may end at once by returning an outcome."""
        return None

    def update(self, eng: Engine, t: float) -> Outcome | None:
        """One control tick at simulated time `t` [s]; return an outcome to end."""
        return None

    def stop(self, eng: Engine) -> None:
        """Called when ended early (cancelled, preempted) or failed: leave the part at rest."""


class Instant(Controller):
    """Runs a function of the engine once in the simulation thread; its return value is the result."""

    def __init__(self, fn, *args) -> None:
        self.fn, self.args = fn, args

    def start(self, eng: Engine) -> Outcome | None:
        return ok(self.fn(eng, *self.args))


class BaseDrive(Controller):
    """Drive the base on a straight line to a map pose while turning, with trapezoidal profiles.

    A differential drive (the description's ``BASE["kind"]``, `pycram.world.base_kinematics`)
    never steps sideways: it reaches a goal by the moves of `drive_moves` -- straight, on an arc
    (position and heading from one profile, so the base faces along the arc) or turning on the
    spot (the references obey the drive's constraint; the joint servos correct millimetres of
    tracking error).

    Fails with "collision" when a base link touches the environment, with "blocked" when the base
    lags its reference by more than `max_lag` [m] (or 0.15 rad), and with "timeout" when it does
    not settle within 2 cm / 2 deg. Succeeds within `tolerance` [m] and `yaw_tolerance` [rad].
    What a base link touches as the drive starts does not fail it until the base is
    `LEAVING_CONTACT` away from where it started: a base that came to rest touching something
    may drive off (else every drive failed at once and the robot stood there for good; measured:
    the TIAGo Pro against a drawer handle, set-table seed 29); driving into it, the base lags its
    reference and the drive fails "blocked".
    """

    channel = "base"

    #: How far [m] the base may drive before what it touched at the start counts as a collision.
    LEAVING_CONTACT = 0.15

    #: Tolerances [m], [rad] of the intermediate stops of a differential drive's turn-drive-turn.
    STOP_TOLERANCE = (0.01, 0.02)

    def __init__(
        self, goal: Pose2D, tolerance: float = 0.005, yaw_tolerance: float = 0.009, max_lag: float = 0.06
    ) -> None:
        self.goal, self.tol, self.yaw_tol, self.max_lag = goal, tolerance, yaw_tolerance, max_lag
        self._stops: list[Pose2D] = []
        self._last = goal  # the last move's target: `goal`, or the turn on the spot that reaches it
        self.kinematics = BaseKinematics()
        self._origin = (0.0, 0.0)  # where the base started [m]
        self._touching: set[str] = set()  # what a base link touched then (environment geom names)

    def start(self, eng: Engine) -> Outcome | None:
        refused = invalid_input(
            goal=(self.goal.x, self.goal.y, self.goal.yaw),
            positive_tolerance=self.tol,
            positive_yaw_tolerance=self.yaw_tol,
            positive_max_lag=self.max_lag,
        )
        if refused is not None:
            return refused
        p = eng.base_pose()
        self._origin = (p.x, p.y)
        self._touching = {other for _, other in eng.base_contacts()}  # what it may drive off
        self.kinematics = BaseKinematics.of(eng.desc.BASE)
        here, goal = BasePose(p.x, p.y, p.yaw), BasePose(self.goal.x, self.goal.y, self.goal.yaw)
        self._last = self.goal
        if not self.kinematics.holonomic:
            # a goal within the tolerance is reached by turning on the spot (`drive_moves`)
            moves = drive_moves(here, goal, self.kinematics, self.yaw_tol, reach=self.tol)
            self._stops = [Pose2D(m.x, m.y, m.yaw) for m in moves[:-1]]
            self._last = Pose2D(moves[-1].x, moves[-1].y, moves[-1].yaw)
        self._begin(eng, self._stops[0] if self._stops else self._last)
        return None

    def _begin(self, eng: Engine, target: Pose2D) -> None:
        """Start the straight, turning move from where the base is to `target`."""
        b = eng.desc.BASE
        self.target = target
        p = eng.base_pose()
        self.dx, self.dy = target.x - p.x, target.y - p.y
        # unwrap the current yaw joint value to stay continuous
        self.yaw0 = eng.q("base_yaw")
        self.dyaw = wrap_angle(target.yaw - p.yaw)
        self.lin = Trapezoid(math.hypot(self.dx, self.dy), b["max_linear_velocity"], b["linear_acceleration"])
        self.ang = Trapezoid(abs(self.dyaw), b["max_angular_velocity"], b["angular_acceleration"])
        self.duration = max(self.lin.duration, self.ang.duration)
        self.t0 = eng.time
        self.x0, self.y0 = eng.q("base_x"), eng.q("base_y")
        # a differential drive's arc: one profile moves along it and turns (no sideways step)
        self.arc = None
        if not self.kinematics.holonomic:
            here = BasePose(self.x0, self.y0, self.yaw0)
            self.arc = arc_radius(here, BasePose(target.x, target.y, self.yaw0 + self.dyaw))
            if self.arc is not None:
                length = abs(self.arc * self.dyaw)
                self.lin = Trapezoid(length, b["max_linear_velocity"], b["linear_acceleration"])
                self.duration = max(self.lin.duration, self.ang.duration)
                self.profile = self.lin if self.lin.duration >= self.ang.duration else self.ang

    def _reference(self, t: float) -> tuple[float, float, float]:
        if self.arc is not None:
            s = self.profile.fraction(t - self.t0, self.duration)
            yaw = self.yaw0 + s * self.dyaw
            return (*arc_point(self.x0, self.y0, self.yaw0, self.arc, yaw), yaw)
        s_lin = self.lin.fraction(t - self.t0, self.duration)
        s_ang = self.ang.fraction(t - self.t0, self.duration)
        return (self.x0 + s_lin * self.dx, self.y0 + s_lin * self.dy, self.yaw0 + s_ang * self.dyaw)

    def update(self, eng: Engine, t: float) -> Outcome | None:
        rx, ry, ryaw = self._reference(t)
        qpos = eng.data.qpos
        x, y, yaw = (float(qpos[i]) for i in eng.base_qpos)  # BASE_JOINTS: x, y, yaw
        contacts = eng.base_contacts()
        if contacts and self._touching:
            if math.hypot(x - self._origin[0], y - self._origin[1]) < self.LEAVING_CONTACT:
                contacts = [c for c in contacts if c[1] not in self._touching]
            else:
                self._touching = set()  # it has driven off: every contact counts again
        if contacts:
            return fail("collision", f"base touches {contacts[0][1]}", eng.base_pose())
        lag = math.hypot(rx - x, ry - y)
        if lag > self.max_lag or abs(ryaw - yaw) > 0.15:
            return fail("blocked", f"base is {lag:.3f} m behind its reference", eng.base_pose())
        ahead = self._reference(t + 0.01)
        for j, v, v2 in zip(BASE_JOINTS, (rx, ry, ryaw), ahead):
            eng.set_target_ff(j, v, (v2 - v) / 0.01)
        elapsed = t - self.t0
        if elapsed >= self.duration:
            p = eng.base_pose()
            err = p.distance_to(self.target)
            yerr = p.yaw_error_to(self.target)
            if self._stops:  # an intermediate stop of a differential drive
                tol, yaw_tol = self.STOP_TOLERANCE
                if err <= tol and yerr <= yaw_tol:
                    self._stops.pop(0)
                    self._begin(eng, self._stops[0] if self._stops else self._last)
                elif elapsed > self.duration + 3.0:
                    return fail("timeout", f"base settled {err:.3f} m / {math.degrees(yerr):.1f} deg off a stop", p)
                return None
            if err <= self.tol and yerr <= self.yaw_tol:
                return ok(p)
            if elapsed > self.duration + 3.0:
                if err <= 0.02 and yerr <= math.radians(2.0):
                    return ok(p)
                return fail("timeout", f"base settled {err:.3f} m / {math.degrees(yerr):.1f} deg off", p)
        return None

    def stop(self, eng: Engine) -> None:
        eng.hold(list(BASE_JOINTS))


class JointTrajectory(Controller):
    """Move joints to goal positions along a smooth (cubic) path, all arriving together.

    The duration is chosen from `max_velocity` [rad/s or m/s] unless given. Succeeds when every
    joint is within `tolerance` of its goal after the path ends, or within `loaded_tolerance`
    (if given) once `settle_time` [s] has passed (servos holding a load stop a little short:
    `pycram.backends.sim.arm_path.LOADED_TOLERANCE`); else fails with "blocked".
    """

    def __init__(
        self,
        channel: str,
        joints: Sequence[str],
        goal: Sequence[float],
        duration: float | None = None,
        max_velocity: float = 1.0,
        tolerance: float = 0.01,
        settle_time: float = 2.0,
        loaded_tolerance: float | None = None,
    ) -> None:
        self.channel = channel
        self.joints, self.goal = list(joints), np.asarray(goal, float)
        self.duration, self.vmax = duration, max_velocity
        self.tol, self.settle = tolerance, settle_time
        self.loaded_tol = tolerance if loaded_tolerance is None else max(tolerance, loaded_tolerance)

    def start(self, eng: Engine) -> Outcome | None:
        refused = invalid_input(
            goal=self.goal,
            positive_duration=self.duration,
            positive_max_velocity=self.vmax,
            positive_tolerance=self.tol,
            positive_settle_time=self.settle,
        )
        if refused is not None:
            return refused
        if len(self.goal) != len(self.joints):
            return fail("invalid", f"{len(self.joints)} joints {self.joints}, got {len(self.goal)} positions")
        m = eng.model
        for j, g in zip(self.joints, self.goal):
            jid = eng.scene.joint_id(j)
            if m.jnt_limited[jid]:
                lo, hi = m.jnt_range[jid]
                if not lo - 1e-3 <= g <= hi + 1e-3:
                    return fail("invalid", f"{j}={g:.3f} outside [{lo:.3f}, {hi:.3f}]")
        self.q0 = np.array([eng.q(j) for j in self.joints])
        if self.duration is None:
            # cubic path peak velocity is 1.5 x mean velocity
            self.duration = max(0.3, 1.5 * float(np.max(np.abs(self.goal - self.q0))) / self.vmax)
        self.t0 = eng.time
        return None

    def update(self, eng: Engine, t: float) -> Outcome | None:
        duration = self.duration
        assert duration is not None  # chosen by start()
        s = smoothstep((t - self.t0) / duration)
        for j, v in zip(self.joints, self.q0 + s * (self.goal - self.q0)):
            eng.set_target(j, float(v))
        if s >= 1.0:
            errs = [abs(eng.q(j) - g) for j, g in zip(self.joints, self.goal)]
            err = max(errs)
            if err <= self.tol:
                return ok(err)
            if t - self.t0 > duration + self.settle:
                if err <= self.loaded_tol:
                    return ok(err)
                worst = self.joints[errs.index(err)]
                return fail("blocked", f"joints stopped {err:.3f} from the goal ({worst})", err)
        return None

    def stop(self, eng: Engine) -> None:
        eng.hold(self.joints)


class GripperCommand(Controller):
    """Open or close a gripper to `opening` [m] with `effort` [N]; ends when the fingers stop.

    Closing on an item stalls the fingers at the item's width (the command still succeeds; the
    outcome's value is the measured opening [m]). Opening releases a held item.
    """

    def __init__(self, gripper: str, opening: float, effort: float | None) -> None:
        self.channel = f"gripper:{gripper}"
        self.gripper, self.opening, self.effort = gripper, opening, effort

    def start(self, eng: Engine) -> Outcome | None:
        refused = invalid_input(opening=self.opening, effort=self.effort)
        if refused is not None:
            return refused
        g = eng.grippers[self.gripper]
        spec = g.spec
        effort = spec["default_effort"] if self.effort is None else self.effort
        if effort <= 0:
            return fail("invalid", f"effort must be positive, got {effort}")
        width = min(max(self.opening, 0.0), spec["max_opening"])
        current = g.opening(eng.data)
        eng.model.actuator_forcerange[g.actuator] = (-effort * spec["effort_lever"], effort * spec["effort_lever"])
        # opening as wide as the fingers go never closes, even when a held item pushed them
        # a little further (measured: 92 mm of 90, a carton held across its diagonal)
        widest = width >= spec["max_opening"] - 1e-3
        g.closing = (width < current - 1e-3 and not widest) or width <= 0.005
        g.target_opening = width
        if not g.closing:
            # any command that does not close lets go -- also when the fingers already stand at
            # that width (a held item can push them open as far as they go: then "open" is no wider)
            eng.release(g)
        # close a little beyond the goal so the fingers squeeze what they meet
        q = g.joint_for_opening(width)
        eng.set_target(g.joint, q - (0.05 * (spec["joint_range"][1] - spec["joint_range"][0]) if g.closing else 0.0))
        self.t0 = eng.time
        self.still_since: float | None = None
        return None

    def update(self, eng: Engine, t: float) -> Outcome | None:
        g = eng.grippers[self.gripper]
        v = abs(float(eng.data.qvel[g.dof]))
        speed_limit = 0.02 * (g.spec["joint_range"][1] - g.spec["joint_range"][0])
        if t - self.t0 > 0.15 and v < speed_limit:
            if self.still_since is None:
                self.still_since = t
            elif t - self.still_since > 0.05:
                return ok(g.opening(eng.data))
        else:
            self.still_since = None
        if t - self.t0 > 3.0:
            return ok(g.opening(eng.data))
        return None


class HeadPointing(Controller):
    """Point the head camera at a map point [m], by pan/tilt feedback on the camera's view axis.

    Every tick the pan/tilt angles that put the point on the view axis are computed (one
    Jacobian step from the current ones); the servos get them with their rate of change as a
    velocity feed-forward, so the head keeps up while the base drives and turns (measured:
    the view axis stays within ~2 deg of the point during a drive with both robots).
    With `track=True` it keeps pointing until cancelled or preempted; otherwise it succeeds once
    the view axis is within `tolerance` [rad] of the point for 0.1 s, and fails with
    "unreachable" after 5 s (a point outside the head's joint range).
    """

    #: Low-pass weight of a new finite-difference joint velocity in the feed-forward (per tick).
    FEED_FORWARD_GAIN = 0.3

    channel = "head"

    def __init__(self, point: Sequence[float], track: bool = False, tolerance: float = 0.02) -> None:
        self.point = np.asarray(point, float)
        self.track, self.tol = track, tolerance

    def start(self, eng: Engine) -> Outcome | None:
        h = eng.desc.HEAD
        self.joints = (h["pan_joint"], h["tilt_joint"])  # before any outcome: `stop` holds them
        refused = invalid_input(point=self.point, positive_tolerance=self.tol)
        if refused is not None:
            return refused
        self.dofs = [eng.scene.joint_dof(j) for j in self.joints]
        self.jids = [eng.scene.joint_id(j) for j in self.joints]
        self.qadr = [eng.scene.joint_qpos(j) for j in self.joints]
        self.ranges = [tuple(float(v) for v in eng.model.jnt_range[jid]) for jid in self.jids]
        self.jacr = np.zeros((3, eng.model.nv))
        self.t0 = eng.time
        self.good_since: float | None = None
        self._previous: tuple[float, np.ndarray] | None = None  # (time [s], wanted angles [rad])
        self._velocity = np.zeros(2)  # [rad/s] filtered rate of the wanted angles
        return None

    def error(self, eng: Engine) -> tuple[np.ndarray, float]:
        """Rotation vector (world frame) that turns the view axis onto the point, and its angle."""
        d = eng.data
        cam = eng.camera
        forward = -d.cam_xmat[cam].reshape(3, 3)[:, 2]
        to = self.point - d.cam_xpos[cam]
        to /= max(math.sqrt(float(to @ to)), 1e-9)
        (f0, f1, f2), (t0, t1, t2) = forward.tolist(), to.tolist()
        axis = np.array((f1 * t2 - f2 * t1, f2 * t0 - f0 * t2, f0 * t1 - f1 * t0))  # forward x to
        s = math.sqrt(float(axis @ axis))
        angle = math.atan2(s, f0 * t0 + f1 * t1 + f2 * t2)
        if s < 1e-9:
            return np.zeros(3), angle
        return axis / s * angle, angle

    def update(self, eng: Engine, t: float) -> Outcome | None:
        m, d = eng.model, eng.data
        err, angle = self.error(eng)
        body = int(m.cam_bodyid[eng.camera])
        mujoco.mj_jacBody(m, d, None, self.jacr, body)
        J = self.jacr[:, self.dofs]
        normal = J.T @ J  # 2 x 2: solved directly unless (nearly) singular, e.g. looking straight down
        (a, b), (_, c) = normal.tolist()
        if a * c - b * b > 1e-6 * (a + c) ** 2:
            dq = np.linalg.solve(normal, J.T @ err)
        else:
            dq = np.linalg.lstsq(J, err, rcond=1e-3)[0]
        wanted = d.qpos[self.qadr] + dq
        if self._previous is not None and t > self._previous[0]:
            rate = (wanted - self._previous[1]) / (t - self._previous[0])
            self._velocity += self.FEED_FORWARD_GAIN * (rate - self._velocity)
        self._previous = (t, wanted)
        for j, (lo, hi), goal, velocity in zip(self.joints, self.ranges, wanted.tolist(), self._velocity.tolist()):
            inside = lo < goal < hi
            eng.set_target_ff(j, min(max(goal, lo), hi), velocity if inside else 0.0)
        if not self.track:
            if angle <= self.tol:
                if self.good_since is None:
                    self.good_since = t
                elif t - self.good_since > 0.1:
                    return ok(angle)
            else:
                self.good_since = None
            if t - self.t0 > 5.0:
                return fail("unreachable", f"head cannot point within {math.degrees(angle):.1f} deg", angle)
        return None

    def stop(self, eng: Engine) -> None:
        eng.hold(list(self.joints))


class Reach(Controller):
    """Move the tool frame of `arm` to a map pose: IK (see `ik.solve_ik`), then a joint trajectory.

    Fails with "unreachable" when IK finds no solution within the joint limits, with "blocked"
    when the arm does not get within `tolerance` [m] of the goal.
    """

    channel: str

    def __init__(
        self, arm: str, goal, use_orientation: bool = True, duration: float | None = None, tolerance: float = 0.01
    ) -> None:
        self.channel = f"arm:{arm}"
        self.arm, self.goal, self.use_orientation = arm, goal, use_orientation
        self.duration, self.tol = duration, tolerance
        self.inner: JointTrajectory | None = None

    def start(self, eng: Engine) -> Outcome | None:
        from .ik import solve_ik

        refused = invalid_input(
            position=self.goal.position,
            orientation=self.goal.orientation,
            positive_duration=self.duration,
            positive_tolerance=self.tol,
        )
        if refused is not None:
            return refused
        sol = solve_ik(eng, self.arm, self.goal, self.use_orientation)
        if sol is None:
            return fail("unreachable", f"no IK solution for {self.arm} arm to {self.goal}")
        self.inner = JointTrajectory(
            self.channel, eng.desc.ARMS[self.arm]["joints"], sol.positions, self.duration, tolerance=0.005
        )
        return self.inner.start(eng)

    def update(self, eng: Engine, t: float) -> Outcome | None:
        assert self.inner is not None
        out = self.inner.update(eng, t)
        if out is None:
            return None
        pose = eng.site_pose(eng.tool_sites[self.arm])
        err = float(np.linalg.norm(np.asarray(pose.position) - np.asarray(self.goal.position)))
        if err > self.tol:
            return fail("blocked", f"tool stopped {err:.3f} m from the goal", pose)
        return ok(pose)

    def stop(self, eng: Engine) -> None:
        if self.inner is not None:
            self.inner.stop(eng)


class GiveItem(Controller):
    """Fault injection: a person hands `item` into an open `gripper` and holds it until it is grasped.

    Opens the gripper if needed and holds the item at the tool frame. With `close` the person
    also closes the gripper on it (default effort); without, the person waits for the robot to
    close its gripper -- this command then runs on a channel of its own (`hand:<gripper>`), so
    the robot's gripper command does not preempt it. Either way the grasp is the gripper's own
    contact-triggered one. Succeeds (value: the measured opening [m]) once the gripper holds the
    item; fails with "timeout" when it has not after `timeout` [s], and the item drops.
    """

    def __init__(self, item: str, gripper: str, arm: str, close: bool = True, timeout: float = 5.0) -> None:
        self.channel = f"gripper:{gripper}" if close else f"hand:{gripper}"
        self.item, self.gripper, self.arm, self.close, self.timeout = item, gripper, arm, close, timeout
        self.closer: GripperCommand | None = None

    def start(self, eng: Engine) -> Outcome | None:
        refused = invalid_input(positive_timeout=self.timeout)
        if refused is not None:
            return refused
        g = eng.grippers[self.gripper]
        if g.holding is not None:
            return fail("invalid", f"gripper {self.gripper} already holds {g.holding}")
        holder = eng.holder_of(self.item)
        if holder is not None:
            eng.release(holder)
        self.phase = "open"
        self.opener = GripperCommand(self.gripper, g.spec["max_opening"], None)
        self.opener.start(eng)
        self.t0 = eng.time
        return None

    def _put(self, eng: Engine) -> None:
        pose = eng.site_pose(eng.tool_sites[self.arm])
        eng.set_item_pose(self.item, pose.position, (1.0, 0.0, 0.0, 0.0))

    def update(self, eng: Engine, t: float) -> Outcome | None:
        g = eng.grippers[self.gripper]
        if self.phase == "open":
            if self.opener.update(eng, t) is not None:
                self.phase = "hold"
                self._put(eng)
                if self.close:
                    self.closer = GripperCommand(self.gripper, 0.0, None)
                    self.closer.start(eng)
            return None
        if g.holding == self.item:
            if self.closer is None or self.closer.update(eng, t) is not None:
                return ok(g.opening(eng.data))
            return None
        if self.closer is not None and self.item in eng._touching_items(g, either=True):
            # the person lets go as soon as a finger presses the item against the other one
            eng.weld(g, self.item)
            return None
        self._put(eng)
        if t - self.t0 > self.timeout:
            return fail("timeout", f"gripper {self.gripper} did not take {self.item}")
        return None
