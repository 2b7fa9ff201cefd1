"""Following a timed joint path with one arm, watching for contacts and for joints that lag.

:class:`JointPath` is the controller that executes a planned arm motion
(:mod:`pycram.reasoning.motion`: a collision-free path in prospection's world, timed by
:func:`~pycram.reasoning.motion.timing.time_parameterize`): every control tick the arm's position
servos get the path's reference, linearly interpolated between the samples, with its velocity as
feed-forward (:meth:`Engine.set_target_ff`), so the joints do not lag.

Monitoring (every tick, in the simulation thread), because the world may differ from what the
plan was made in (an obstacle nobody perceived, an object that moved):

- **an unexpected contact** -- a geom of the arm (the bodies below its first joint) or of the
  object its gripper holds, touching the environment or an object -- stops the arm where it is
  and ends with reason ``"collision"``; the message names the pair ("r_forearm_link touches
  obstacle_0"). Not unexpected: the object being grasped (``exempt_item``, or the item nearest
  to ``exempt_near``) and any object the gripper touches when the motion starts, touching the
  gripper; a pair already touching when the motion starts, until it comes apart (a lifted object
  leaves the counter it stood on; fingers that start at a handle); contacts with the environment
  shallower than ``environment_depth`` [m] (a finger brushing a counter top); contacts with an
  object shallower than `ITEM_DEPTH` while it has neither moved ``item_displacement`` [m] nor
  turned `ITEM_TURN` [rad] since the path started (a finger brushing a plate's rim: an object
  pushed gives way rather than being penetrated, so it is its moving that tells a push);
- **a deviation** -- a joint more than ``max_deviation`` [rad or m] from its reference -- stops the
  arm and ends with reason ``"blocked"``, the message naming the joint.

"Stops the arm where it is": the servos are set to the measured positions (:meth:`stop`), so the
arm presses no further against what it hit. The outcome's value is a :class:`PathStop`: the
configuration where it stopped and the index of the last sample it had passed, so the caller can
back off along the executed part of the path and plan again.

Success: after the last sample every joint is within ``tolerance`` of the path's end, or within
`LOADED_TOLERANCE` once ``settle_time`` [s] has passed (servos holding a load stop a little short);
else the outcome is ``"blocked"`` (naming the joint farthest off). Value on success: the largest
remaining joint error [rad or m].

Every input is checked before anything moves (outcome ``"invalid"``): samples must be finite, of
the joints' length, at strictly increasing times from 0, within the joints' position limits.
"""

from __future__ import annotations

import bisect
import math
import weakref
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from pycram.world.types import Outcome

from .arm_checker import arm_bodies
from .controllers import Controller, fail, invalid_input, ok
from .engine import Engine

__all__ = [
    "JointPath",
    "PathStop",
    "ENVIRONMENT_DEPTH",
    "EXEMPT_RADIUS",
    "ITEM_DEPTH",
    "ITEM_DISPLACEMENT",
    "ITEM_TURN",
    "LOADED_TOLERANCE",
    "MAX_DEVIATION",
    "PATH_TOLERANCE",
    "SETTLE_TIME",
]

#: Contacts of the arm with the environment shallower than this [m] are not collisions: a finger
#: tip brushing a counter top while grasping, soft contacts of the tracking arm. An object is
#: pushed aside rather than penetrated, so every contact with an object counts.
ENVIRONMENT_DEPTH = 0.005
#: A contact with an object counts once the object has moved this far [m] since the path started:
#: the arm is pushing it (a finger brushing a plate's rim does not move it; a push that knocks an
#: object over starts by moving it).
ITEM_DISPLACEMENT = 0.003
#: ... or once it has turned this far [rad] (a thin box tipping over turns before it moves) ...
ITEM_TURN = 0.02
#: ... or once the arm presses this deep [m] into it (an object that cannot give way).
ITEM_DEPTH = 0.001
#: The item being grasped, given by a believed position (``exempt_near``), is the item whose
#: centre is nearest to it, if within this distance [m] (perceived poses are off by a few cm).
EXEMPT_RADIUS = 0.1
#: A joint this far [rad or m] from its reference is blocked (the servos track to a few
#: hundredths of a radian with the velocity feed-forward; the PR2's forearm roll, carrying a
#: cereal box, lagged 0.1 rad).
MAX_DEVIATION = 0.25
#: The path has ended when every joint is this close [rad or m] to its last sample.
PATH_TOLERANCE = 0.01
#: Time [s] the joints get after the last sample to come within the tolerance.
SETTLE_TIME = 2.0
#: After the settle time, joints this close [rad or m] to the last sample, touching nothing, have
#: arrived: their servos hold them there under the load (the PR2's forearm roll, a cereal box
#: held by its side, stops 0.032-0.034 rad short; reported 'blocked', the pick-up let the box go
#: and it fell: set-table-anywhere, ``procedural:14``, seed 1).
LOADED_TOLERANCE = 0.05


@dataclass(frozen=True)
class PathStop:
    """Where a :class:`JointPath` stopped early: the measured ``positions`` [rad or m] (order of
    the path's joints), the index of the last sample the reference had passed (``sample``), the
    simulated time since the path started (``elapsed`` [s]) and, for a contact, the touching pair
    (arm part or held object, obstacle)."""

    positions: tuple[float, ...]
    sample: int
    elapsed: float
    contact: tuple[str, str] | None = None


@dataclass(frozen=True)
class _Masks:
    arm: np.ndarray  #: geoms below the arm's first joint
    gripper: np.ndarray  #: geoms below the gripper's palm
    environment: np.ndarray  #: static environment geoms (furniture, walls, obstacles)


_MASKS: weakref.WeakKeyDictionary[Engine, dict[str, _Masks]] = weakref.WeakKeyDictionary()


def _masks(eng: Engine, arm: str) -> _Masks:
    """The geom masks of ``arm`` in ``eng``'s scene (computed once per engine and arm)."""
    per_engine = _MASKS.setdefault(eng, {})
    found = per_engine.get(arm)
    if found is None:
        parts = arm_bodies(eng.scene, arm, False)
        environment = np.zeros(eng.model.ngeom, bool)
        environment[list(eng.scene.environment_geoms)] = True
        found = per_engine[arm] = _Masks(parts.arm, parts.gripper, environment)
    return found


class JointPath(Controller):
    """Follow ``samples`` ((t [s] from 0, positions) pairs, joint order of ``joints``) with ``arm``,
    monitored as the module docstring says. The item being grasped (it may touch the gripper) is
    ``exempt_item`` (a simulator item's name) or the item nearest to ``exempt_near`` (a believed
    position [m, map]) within :data:`EXEMPT_RADIUS`; none when both are None. The object the arm's gripper
    holds when the motion starts moves with the arm and is monitored with it."""

    def __init__(
        self,
        arm: str,
        joints: Sequence[str],
        samples: Sequence[tuple[float, Sequence[float]]],
        *,
        exempt_item: str | None = None,
        exempt_near: Sequence[float] | None = None,
        tolerance: float = PATH_TOLERANCE,
        max_deviation: float = MAX_DEVIATION,
        environment_depth: float = ENVIRONMENT_DEPTH,
        item_displacement: float = ITEM_DISPLACEMENT,
        settle_time: float = SETTLE_TIME,
    ) -> None:
        self.channel = f"arm:{arm}"
        self.arm, self.joints = arm, list(joints)
        self.times = [float(t) for t, _ in samples]
        self.positions = np.array([[float(v) for v in q] for _, q in samples], float).reshape(len(self.times), -1)
        self.exempt_item = exempt_item
        self.exempt_near = None if exempt_near is None else tuple(float(v) for v in exempt_near)
        self.tol, self.max_deviation = tolerance, max_deviation
        self.environment_depth, self.settle = environment_depth, settle_time
        self.item_displacement = item_displacement

    # ------------------------------------------------------------------ lifecycle
    def start(self, eng: Engine) -> Outcome | None:
        refused = invalid_input(
            times=self.times or None,
            positions=self.positions if self.positions.size else None,
            exempt_near=self.exempt_near,
            positive_tolerance=self.tol,
            positive_max_deviation=self.max_deviation,
            environment_depth=self.environment_depth,
            item_displacement=self.item_displacement,
            positive_settle_time=self.settle,
        )
        if refused is not None:
            return refused
        if not self.times:
            return fail("invalid", "a joint path needs at least one sample")
        if self.positions.shape[1] != len(self.joints):
            return fail(
                "invalid",
                f"{len(self.joints)} joints {self.joints}, got samples of {self.positions.shape[1]} positions",
            )
        if self.times[0] != 0.0 or any(b <= a for a, b in zip(self.times, self.times[1:])):
            return fail("invalid", "sample times must start at 0 and increase strictly")
        desc = eng.desc
        if self.arm not in desc.ARMS:
            return fail("invalid", f"unknown arm {self.arm!r}; valid arms: {list(desc.ARMS)}")
        arm_joints = set(desc.ARMS[self.arm]["joints"])
        m = eng.model
        for i, j in enumerate(self.joints):
            if j not in arm_joints:
                return fail("invalid", f"{j!r} is not a joint of the {self.arm} arm ({sorted(arm_joints)})")
            jid = eng.scene.joint_id(j)
            if m.jnt_limited[jid]:
                lo, hi = m.jnt_range[jid]
                column = self.positions[:, i]
                if column.min() < lo - 1e-3 or column.max() > hi + 1e-3:
                    return fail("invalid", f"{j} leaves [{lo:.3f}, {hi:.3f}] on the path")
        self.qadr = np.array([eng.scene.joint_qpos(j) for j in self.joints])
        # the joints' servos and their velocity feed-forward gains kv / kp (`Engine.set_target_ff`),
        # read once: nothing changes a servo's gains during a run
        self.actuators = np.array([eng.actuator(j) for j in self.joints], int)
        self.feed_forward = -m.actuator_biasprm[self.actuators, 2] / m.actuator_gainprm[self.actuators, 0]
        self.masks = _masks(eng, self.arm)
        self._roles: tuple[str | None, np.ndarray] | None = None  # see `_geom_roles`
        self.gripper = eng.grippers[desc.ARMS[self.arm]["gripper"]]
        self.exempt = np.zeros(m.ngeom, bool)
        if self.exempt_item is not None:
            if self.exempt_item not in eng.item_part_geoms:
                return fail("invalid", f"unknown item {self.exempt_item!r}; items: {sorted(eng.item_part_geoms)}")
            self.exempt[eng.item_part_geoms[self.exempt_item]] = True
        if self.exempt_near is not None:
            near = np.asarray(self.exempt_near)
            distances = {
                name: float(np.linalg.norm(eng.data.xpos[body] - near)) for name, body in eng.item_bodies.items()
            }
            nearest = min(distances, key=lambda name: (distances[name], name), default=None)
            if nearest is not None and distances[nearest] <= EXEMPT_RADIUS:
                self.exempt[eng.item_part_geoms[nearest]] = True
        self.t0 = eng.time
        self.sample = 0
        self.commanded = eng.data.qpos[self.qadr].copy()
        # an item the gripper touches at the start is the one the hand is at (it leaves it, or
        # grasps it): exempt at the fingers for the whole motion
        self.item_start = {
            body: (eng.data.xpos[body].copy(), eng.data.xquat[body].copy()) for body in eng.item_bodies.values()
        }
        for a, b in self._pairs(eng, touching=True):
            if self.masks.gripper[a] and b in eng.geom_item:
                self.exempt[eng.item_part_geoms[eng.geom_item[b]]] = True
        self.allowed = self._pairs(eng, touching=True)  # other pairs touching at the start: allowed until they part
        return None

    def _reference(self, elapsed: float) -> tuple[np.ndarray, np.ndarray]:
        """Position and velocity of the path at ``elapsed`` [s] (linear between samples)."""
        times = self.times
        if elapsed >= times[-1]:
            self.sample = len(times) - 1
            return self.positions[-1], np.zeros(len(self.joints))
        k = max(0, bisect.bisect_right(times, elapsed) - 1)
        self.sample = k
        a, b = self.positions[k], self.positions[k + 1]
        dt = times[k + 1] - times[k]
        s = (elapsed - times[k]) / dt
        return a + s * (b - a), (b - a) / dt

    def update(self, eng: Engine, t: float) -> Outcome | None:
        elapsed = t - self.t0
        q = eng.data.qpos[self.qadr]
        touching = self._touching(eng)
        if touching:
            return self._stop(eng, "collision", f"{touching[0][0]} touches {touching[0][1]}", elapsed, touching[0])
        lag = np.abs(q - self.commanded)  # against the reference commanded last tick
        worst = int(np.argmax(lag))
        if lag[worst] > self.max_deviation:
            return self._stop(
                eng, "blocked", f"{self.joints[worst]} is {lag[worst]:.3f} from its reference on the path", elapsed
            )
        position, velocity = self._reference(elapsed)
        # `Engine.set_target_ff` for every joint at once (the same arithmetic, element-wise)
        eng.data.ctrl[self.actuators] = position + self.feed_forward * velocity
        self.commanded = position
        if elapsed >= self.times[-1]:
            errors = np.abs(q - self.positions[-1])
            worst = int(np.argmax(errors))
            if errors[worst] <= self.tol:
                return ok(float(errors[worst]))
            if elapsed > self.times[-1] + self.settle:
                if errors[worst] <= max(self.tol, LOADED_TOLERANCE):
                    return ok(float(errors[worst]))
                return self._stop(
                    eng, "blocked", f"joints stopped {errors[worst]:.3f} from the goal ({self.joints[worst]})", elapsed
                )
        return None

    def stop(self, eng: Engine) -> None:
        eng.hold(self.joints)

    def _stop(self, eng: Engine, reason: str, message: str, elapsed: float, pair=None) -> Outcome:
        eng.hold(self.joints)
        q = tuple(float(v) for v in eng.data.qpos[self.qadr])
        return fail(reason, message, PathStop(q, self.sample, elapsed, pair))

    # ------------------------------------------------------------------ contacts
    def _pairs(self, eng: Engine, touching: bool = False) -> set[tuple[int, int]]:
        """The pairs (moving geom, obstacle geom) in contact now that count (see the module
        docstring): the arm or the held object against the environment (deeper than
        ``environment_depth``) or an object (that moved, unless ``touching``: every object
        touched), the grasped object at the gripper excepted."""
        d = eng.data
        if d.ncon == 0:
            return set()
        masks = self.masks
        roles = self._geom_roles(eng)
        contact = d.contact[: d.ncon]
        g1, g2, dist = contact.geom1, contact.geom2, contact.dist
        first = roles[g1]
        hits = np.flatnonzero(((first ^ roles[g2]) == _PAIR) & (dist <= 0.0))  # a moving geom and an obstacle
        if not hits.size:
            return set()
        out: set[tuple[int, int]] = set()
        for i in hits.tolist():
            a, b = (int(g1[i]), int(g2[i])) if first[i] == _MOVING else (int(g2[i]), int(g1[i]))
            if self.exempt[b] and masks.gripper[a]:
                continue  # the object being grasped, at the fingers
            if masks.environment[b]:
                if float(dist[i]) > -self.environment_depth:
                    continue  # brushing a surface
            elif not touching and float(dist[i]) > -ITEM_DEPTH and not self._moved(eng, b):
                continue  # touching an object without pushing it (yet)
            out.add((a, b))
        return out

    def _geom_roles(self, eng: Engine) -> np.ndarray:
        """Each geom's role in a contact, by geom: `_MOVING` (the arm, the object its gripper
        holds), `_OBSTACLE` (the environment, the other objects) or 0. Built again only when
        what the gripper holds changes (most motions: never), not every tick."""
        held = self.gripper.holding
        cached = self._roles
        if cached is not None and cached[0] == held:
            return cached[1]
        masks = self.masks
        moving = masks.arm.copy()
        if held is not None:
            moving[eng.item_part_geoms[held]] = True
        obstacle = (masks.environment | _item_mask(eng)) & ~moving
        roles = np.zeros(len(moving), np.int8)
        roles[moving] = _MOVING
        roles[obstacle] = _OBSTACLE
        self._roles = (held, roles)
        return roles

    def _moved(self, eng: Engine, geom: int) -> bool:
        """Whether the item of ``geom`` moved more than ``item_displacement`` [m] or turned more
        than `ITEM_TURN` [rad] since the path started."""
        body = int(eng.model.geom_bodyid[geom])
        start = self.item_start.get(body)
        if start is None:
            return False
        position, quat = start
        if float(np.linalg.norm(eng.data.xpos[body] - position)) > self.item_displacement:
            return True
        dot = min(1.0, abs(float(np.dot(eng.data.xquat[body], quat))))
        return 2.0 * math.acos(dot) > ITEM_TURN

    def _touching(self, eng: Engine) -> list[tuple[str, str]]:
        """The unexpected touching pairs (moving part, obstacle) by name; pairs allowed at the
        start stay allowed until they come apart."""
        now = self._pairs(eng)
        self.allowed &= now
        m = eng.model
        return [(_geom_name(m, a), _geom_name(m, b)) for a, b in sorted(now - self.allowed)]


#: Roles of a geom in `JointPath._geom_roles`: the two differ in each bit, so a pair of a moving
#: geom and an obstacle is the one whose roles' exclusive or is `_PAIR`.
_MOVING, _OBSTACLE = 1, 2
_PAIR = _MOVING ^ _OBSTACLE

_ITEMS: weakref.WeakKeyDictionary[Engine, np.ndarray] = weakref.WeakKeyDictionary()


def _item_mask(eng: Engine) -> np.ndarray:
    """Geoms of the simulator's items (objects), as a mask (computed once per engine)."""
    mask = _ITEMS.get(eng)
    if mask is None:
        mask = np.zeros(eng.model.ngeom, bool)
        mask[list(eng.geom_item)] = True
        _ITEMS[eng] = mask
    return mask


def _geom_name(m, g: int) -> str:
    """A geom's name, else its body's."""
    return m.geom(g).name or m.body(int(m.geom_bodyid[g])).name
