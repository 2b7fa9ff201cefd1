"""Fast collision checks of arm configurations: the simulator's `ConfigurationChecker`.

A motion planner asks thousands of times "is the arm free at q?" with everything else fixed (base
pose, other joints, held object). A check here is `mj_kinematics` + `mj_collision` on a
*planning copy* of the model whose collision filter (contype/conaffinity bits, rewritten per
checker) only lets the pairs that matter reach the narrow phase:

- the arm (the bodies below its first joint, with the held object) against obstacles (the
  environment and the objects) and, with self-collision, against the robot's other parts;
- with the torso planned, the rest of the upper body (head, other arm) against obstacles.

Everything else (objects resting on counters, the base on the floor, the robot's own links) is
filtered out before the broad phase, so a check costs ~20-30 us (PR2 or TIAGo in the apartment,
this machine; see ``benchmarks/motion_planning.py``), against ~60 us for
`SimProspection.in_collision`.

Self-collision: link meshes collide as their convex hulls, which overlap at the joints, so pairs
of bodies that touch in most random configurations (adjacent links) or in the robot's initial
configuration are never counted (the "disabled collisions" of MoveIt's setup assistant), measured
once per arm by :func:`self_collision_exclusions`. The excluded pairs are kept out of the narrow
phase too (a contype bit per group of robot bodies with the same excluded arm bodies:
:func:`self_collision_groups`), which halves a check's cost on the PR2. The other pairs' hulls
still overlap a little in ordinary configurations (the TIAGo's shoulder and torso column by 11 mm
with the torso down, in each of 300 random arm configurations; with 15 mm tolerated, 12 % of them
self-collide, as with the torso up): a self-contact counts only deeper than the checker's
``self_tolerance`` (prospection's collision tolerance, 15 mm). Counted, such an overlap put the
start of a motion "in collision", and arm motion planning fell back to tolerating 15 mm with
everything (``pycram.robots.common.arm_motion.CLEARANCES``): a carried spoon grazed a drawer's
handle that deep and was knocked out of the hand.
"""

from __future__ import annotations

import copy
import math
import queue
import threading
from collections import OrderedDict
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import mujoco
import numpy as np

from pycram.world.prospection import ConfigurationChecker

from . import collision
from .arm_limits import arm_joint_names
from .scene import Scene

__all__ = [
    "ArmBodies",
    "threshold_table",
    "SimConfigurationChecker",
    "arm_bodies",
    "configure_filter",
    "self_collision_exclusions",
    "take",
    "SELF_SAMPLES",
]

#: Random configurations sampled to find the body pairs that (nearly) always touch.
SELF_SAMPLES = 300
#: A pair touching in at least this share of the samples is adjacent: never a collision.
_ALWAYS = 0.9
#: contype bits: the arm (and held object) and the torso-moved rest against obstacles; the bits
#: from `_FIRST_GROUP` on are the self-collision groups (at most `_MAX_GROUPS`).
_ARM, _UPPER = 1 << 0, 1 << 1
_FIRST_GROUP, _MAX_GROUPS = 2, 28


#: Threshold tables (see `SimConfigurationChecker._bad`) of the latest checkers, by their
#: exclusions (the same array for every checker of an arm without an exempt object) and
#: clearances: making one costs 0.5 ms for 194 geoms, 2 ms for 400, at a plan's first contact.
_TABLES: OrderedDict[tuple[int, bytes, bytes, float], tuple[np.ndarray, np.ndarray]] = OrderedDict()
_TABLES_KEPT = 6
_TABLES_LOCK = threading.Lock()


def threshold_table(
    ignore: np.ndarray, clearance: np.ndarray, robot: np.ndarray | None = None, self_threshold: float = 0.0
) -> np.ndarray:
    """The (ngeom x ngeom) table of the distances [m] below which a contact between two geoms
    counts: the larger ``clearance`` of the two; between two geoms of ``robot`` (a mask: a
    self-collision) at most ``self_threshold``; -inf where ``ignore`` (never counted). Cached
    for the latest few arguments: do not change the arrays afterwards."""
    robot_key = b"" if robot is None else np.packbits(robot).tobytes()
    key = (id(ignore), clearance.tobytes(), robot_key, float(self_threshold))
    with _TABLES_LOCK:
        hit = _TABLES.get(key)
        if hit is not None and hit[0] is ignore:
            _TABLES.move_to_end(key)
            return hit[1]
    table = np.maximum(clearance[:, None], clearance[None, :])
    if robot is not None:
        pairs = np.ix_(robot, robot)
        table[pairs] = np.minimum(table[pairs], self_threshold)
    table[ignore] = -np.inf
    with _TABLES_LOCK:
        _TABLES[key] = (ignore, table)
        while len(_TABLES) > _TABLES_KEPT:
            _TABLES.popitem(last=False)
    return table


def _descends(model: mujoco.MjModel, body: int, root: int) -> bool:
    while body > 0:
        if body == root:
            return True
        body = int(model.body_parentid[body])
    return False


@dataclass(frozen=True)
class ArmBodies:
    """Which geoms of a scene move when an arm (and the torso) moves: boolean masks over geoms."""

    joints: tuple[str, ...]
    qadr: np.ndarray
    arm: np.ndarray  #: robot geoms below the arm's first joint (arm and gripper)
    upper: np.ndarray  #: other robot geoms below the torso joint (only when the torso is planned)
    rest: np.ndarray  #: the robot's remaining geoms (base; the upper body when the torso stays)
    gripper: np.ndarray  #: robot geoms below the gripper's palm
    obstacles: np.ndarray  #: environment and object geoms
    hand_body: int  #: the palm body (a held object moves rigidly with it)


@dataclass(frozen=True)
class SelfGroup:
    """Robot geoms that the arm may hit (``partners``) and the arm geoms that may hit them
    (``hitters``: those whose bodies are never excluded with any partner's body)."""

    partners: np.ndarray
    hitters: np.ndarray


def self_collision_groups(model: mujoco.MjModel, parts: ArmBodies, excluded: np.ndarray) -> list[SelfGroup]:
    """Group the robot's other bodies by the arm bodies they are excluded with (``excluded``: the
    nbody x nbody matrix of :func:`self_collision_exclusions`); one contype bit per group keeps
    the excluded pairs out of collision detection. Past `_MAX_GROUPS` groups, the rest share one
    group that only excludes what all its bodies exclude (a superset of pairs: still correct)."""
    body = model.geom_bodyid
    arm_bodies = sorted({int(b) for b in body[parts.arm]})
    keys: dict[frozenset[int], list[int]] = {}
    for b in sorted({int(b) for b in body[parts.rest | parts.upper]}):
        keys.setdefault(frozenset(a for a in arm_bodies if excluded[b, a]), []).append(b)
    items = sorted(keys.items(), key=lambda kv: (len(kv[0]), kv[1]))
    if len(items) > _MAX_GROUPS:
        tail = items[_MAX_GROUPS - 1 :]
        common = frozenset.intersection(*(k for k, _ in tail))
        items = items[: _MAX_GROUPS - 1] + [(common, [b for _, bodies in tail for b in bodies])]
    robot = parts.rest | parts.upper
    groups = []
    for key, bodies in items:
        partners = robot & np.isin(body, bodies)
        hitters = parts.arm & ~np.isin(body, list(key))
        groups.append(SelfGroup(partners, hitters))
    return groups


def arm_bodies(scene: Scene, arm: str, include_torso: bool) -> ArmBodies:
    """The geom masks of ``arm`` (see :class:`ArmBodies`)."""
    m = scene.model
    desc = scene.description
    joints = arm_joint_names(scene, arm, include_torso)
    qadr = np.array([scene.joint_qpos(j) for j in joints])
    robot = np.zeros(m.ngeom, bool)
    robot[list(scene.robot_geoms)] = True
    body_of = m.geom_bodyid
    arm_root = int(m.jnt_bodyid[scene.joint_id(desc.ARMS[arm]["joints"][0])])
    torso_root = int(m.jnt_bodyid[scene.joint_id(desc.TORSO["joint"])])
    hand = scene.body(desc.GRIPPERS[desc.ARMS[arm]["gripper"]]["palm_link"])
    below = lambda root: np.array([_descends(m, int(body_of[g]), root) for g in range(m.ngeom)])  # noqa: E731
    arm_mask = robot & below(arm_root)
    upper = robot & below(torso_root) & ~arm_mask if include_torso else np.zeros(m.ngeom, bool)
    obstacles = np.zeros(m.ngeom, bool)
    obstacles[list(scene.environment_geoms)] = True
    obstacles |= (m.geom_contype == collision.ITEM) & ~robot
    return ArmBodies(
        joints=joints,
        qadr=qadr,
        arm=arm_mask,
        upper=upper,
        rest=robot & ~arm_mask & ~upper,
        gripper=robot & below(hand),
        obstacles=obstacles,
        hand_body=hand,
    )


def configure_filter(
    model: mujoco.MjModel,
    parts: ArmBodies,
    moving_objects: np.ndarray,
    self_groups: Sequence[SelfGroup] | None,
    clearance: float,
    objects: np.ndarray | None = None,
    object_clearance: float = 0.0,
) -> None:
    """Rewrite the collision filter of ``model`` (a planning copy) for ``parts``: the arm (and the
    geoms of ``moving_objects``, a held object) against obstacles and, given ``self_groups``
    (:func:`self_collision_groups`), the robot's other parts; the torso-moved rest against
    obstacles; nothing else. Contacts are found within ``clearance`` [m] of the arm, and within
    ``object_clearance`` of the geoms of ``objects`` (a mask) if that is larger."""
    arm = parts.arm | moving_objects
    obstacles = parts.obstacles & ~moving_objects
    contype = np.zeros(model.ngeom, np.int32)
    conaffinity = np.zeros(model.ngeom, np.int32)
    contype[arm] = _ARM
    contype[parts.upper] = _UPPER
    conaffinity[obstacles] = _ARM | _UPPER
    for i, group in enumerate(self_groups or ()):
        bit = 1 << (_FIRST_GROUP + i)
        conaffinity[group.partners] |= bit
        contype[group.hitters | moving_objects] |= bit
    model.geom_contype[:] = contype
    model.geom_conaffinity[:] = conaffinity
    margin = np.zeros(model.ngeom)
    margin[arm | parts.upper] = max(clearance, 0.0)
    if objects is not None:
        margin[objects] = max(clearance, object_clearance, 0.0)
    model.geom_margin[:] = margin
    body_contype = np.zeros(model.nbody, np.int32)
    body_conaffinity = np.zeros(model.nbody, np.int32)
    body_margin = np.zeros(model.nbody)
    np.bitwise_or.at(body_contype, model.geom_bodyid, contype)
    np.bitwise_or.at(body_conaffinity, model.geom_bodyid, conaffinity)
    np.maximum.at(body_margin, model.geom_bodyid, margin)
    model.body_contype[:] = body_contype
    model.body_conaffinity[:] = body_conaffinity
    model.body_margin[:] = body_margin


def self_collision_exclusions(
    model: mujoco.MjModel,
    data: mujoco.MjData,
    scene: Scene,
    parts: ArmBodies,
    initial_qpos: np.ndarray,
    samples: int = SELF_SAMPLES,
) -> np.ndarray:
    """An (nbody x nbody) boolean matrix of body pairs whose contacts never count as
    self-collisions: those touching in ``initial_qpos`` (the robot's initial configuration) or in
    at least 90 % of ``samples`` random configurations of all the robot's limited joints.

    ``model`` is a planning copy (its filter is rewritten); deterministic (fixed seed)."""
    m = model
    everything = [SelfGroup(parts.rest | parts.upper, parts.arm)]
    configure_filter(m, parts, np.zeros(m.ngeom, bool), everything, 0.0)
    m.geom_conaffinity[parts.obstacles] = 0
    m.body_conaffinity[:] = 0
    np.bitwise_or.at(m.body_conaffinity, m.geom_bodyid, m.geom_conaffinity)
    robot_joints = [
        j
        for j in range(m.njnt)
        if m.jnt_limited[j] and any(parts.arm[g] or parts.rest[g] or parts.upper[g] for g in _geoms_below(m, j))
    ]
    rng = np.random.default_rng(7)
    counts = np.zeros((m.nbody, m.nbody), int)
    first = np.zeros((m.nbody, m.nbody), bool)

    def touching() -> np.ndarray:
        mujoco.mj_kinematics(m, data)
        mujoco.mj_collision(m, data)
        seen = np.zeros((m.nbody, m.nbody), bool)
        for c in data.contact[: data.ncon]:
            b1, b2 = int(m.geom_bodyid[c.geom[0]]), int(m.geom_bodyid[c.geom[1]])
            seen[b1, b2] = seen[b2, b1] = True
        return seen

    data.qpos[:] = initial_qpos
    first |= touching()
    for _ in range(samples):
        data.qpos[:] = initial_qpos
        for j in robot_joints:
            lo, hi = m.jnt_range[j]
            data.qpos[m.jnt_qposadr[j]] = rng.uniform(lo, hi)
        counts += touching()
    return first | (counts >= _ALWAYS * samples)


def _geoms_below(model: mujoco.MjModel, joint: int) -> list[int]:
    root = int(model.jnt_bodyid[joint])
    return [g for g in range(model.ngeom) if _descends(model, int(model.geom_bodyid[g]), root)]


class SimConfigurationChecker(ConfigurationChecker):
    """`ConfigurationChecker` on a planning copy of the model (see the module docstring).

    Made by `SimProspection.configuration_checker` with ``data`` prepared (the world as it is,
    the base at its pose, the other joints set, kinematics computed); ``release`` gives the
    planning copy and its data back to their pool on :meth:`close`; ``clearance`` [m, per geom]:
    a contact counts closer than the larger of its two geoms'; ``self_tolerance`` [m]: a contact
    between two of the robot's geoms counts only deeper than this (link hulls overlap).
    """

    def __init__(
        self,
        model: mujoco.MjModel,
        data: mujoco.MjData,
        parts: ArmBodies,
        ignore: np.ndarray,
        clearance: np.ndarray,
        held: tuple[int, np.ndarray, np.ndarray] | None,
        geom_name: Callable[[int], str],
        release: Callable[[], None],
        self_tolerance: float = 0.0,
    ) -> None:
        if not self_tolerance >= 0.0:
            raise ValueError(f"self_tolerance must be >= 0 [m], got {self_tolerance!r}")
        self.model, self.data = model, data
        self.joints = parts.joints
        self.checks = 0
        self._qadr = parts.qadr
        self._ignore = ignore
        self._clearance = clearance  # per geom [m]: a pair is touching below the larger of its two
        self._robot = parts.arm | parts.upper | parts.rest
        self._self_tolerance = float(self_tolerance)
        self._held = held  # (qpos address of the free joint, position in the hand, quaternion in the hand)
        self._hand = parts.hand_body
        self._geom_name = geom_name
        self._release: Callable[[], None] | None = release
        self._pos, self._quat = np.zeros(3), np.zeros(4)
        self._below: np.ndarray | None = None  # see _bad
        self._up = np.zeros(3)
        self._held_up: np.ndarray | None = None  # the held object's frame: the direction up when made
        if held is not None:
            adr = held[0]
            quat = np.asarray(data.qpos[adr + 3 : adr + 7], float)  # the object as it is (prepared data)
            inverse = np.zeros(4)
            mujoco.mju_negQuat(inverse, quat)
            up = np.zeros(3)
            mujoco.mju_rotVecQuat(up, np.array([0.0, 0.0, 1.0]), inverse)
            self._held_up = up

    def _collide(self, q: Sequence[float]) -> int:
        """Set the arm to ``q``, run kinematics and collision detection; the contact count."""
        if self._release is None:
            raise RuntimeError("this configuration checker is closed")
        if len(q) != len(self._qadr):
            raise ValueError(
                f"a configuration has {len(self._qadr)} positions ({', '.join(self.joints)}), got {len(q)}"
            )
        self.checks += 1
        m, d = self.model, self.data
        d.qpos[self._qadr] = q
        mujoco.mj_kinematics(m, d)
        if self._held is not None:
            adr, rel_pos, rel_quat = self._held
            mujoco.mju_mulPose(self._pos, self._quat, d.xpos[self._hand], d.xquat[self._hand], rel_pos, rel_quat)
            d.qpos[adr : adr + 3] = self._pos
            d.qpos[adr + 3 : adr + 7] = self._quat
            mujoco.mj_kinematics(m, d)
        mujoco.mj_collision(m, d)
        return int(d.ncon)

    def _bad(self, n: int) -> np.ndarray:
        """Which of the first ``n`` contacts count as collisions: closer than the pair's threshold
        (the larger clearance of its two geoms; between two robot geoms at most
        ``-self_tolerance``), the pair not ignored. The thresholds are one
        table (:func:`threshold_table`), taken at the first contact: one lookup a contact
        (measured: 3 instead of 7 us with 5 contacts, 4 instead of 16 us with 18)."""
        below = self._below
        if below is None:
            below = self._below = threshold_table(self._ignore, self._clearance, self._robot, -self._self_tolerance)
        contact = self.data.contact
        geoms = contact.geom
        if len(geoms) != n:
            geoms = geoms[:n]
        return contact.dist[:n] < below[geoms[:, 0], geoms[:, 1]]

    def _lean(self) -> float:
        """How far [rad] the held object's up direction (`held_lean`) leans after `_collide`."""
        if self._held_up is None:
            return 0.0
        mujoco.mju_rotVecQuat(self._up, self._held_up, self._quat)
        return math.acos(max(-1.0, min(1.0, float(self._up[2]))))

    def held_lean(self, q: Sequence[float]) -> float:
        self._collide(q)
        return self._lean()

    def _leans_too_far(self) -> bool:
        return self.max_held_lean < math.inf and self._lean() > self.max_held_lean

    def is_free(self, q: Sequence[float]) -> bool:
        n = self._collide(q)
        if self._leans_too_far():
            return False
        return n == 0 or not bool(self._bad(n).any())

    def contacts(self, q: Sequence[float]) -> list[tuple[str, str]]:
        n = self._collide(q)
        out: dict[tuple[str, str], None] = {}
        if self._leans_too_far():
            out[("the held object", f"its tilt limit ({math.degrees(self.max_held_lean):.0f} deg)")] = None
        if n == 0:
            return list(out)
        moving = self.model.geom_contype
        for i in np.nonzero(self._bad(n))[0]:
            g1, g2 = (int(g) for g in self.data.contact.geom[i])
            if not moving[g1]:
                g1, g2 = g2, g1
            out[(self._geom_name(g1), self._geom_name(g2))] = None
        return list(out)

    def close(self) -> None:
        if self._release is not None:
            release, self._release = self._release, None
            release()


def take(
    pool: queue.SimpleQueue[tuple[mujoco.MjModel, mujoco.MjData]], model: mujoco.MjModel
) -> tuple[mujoco.MjModel, mujoco.MjData]:
    """A planning copy of ``model`` with its data from ``pool`` (made on demand)."""
    try:
        return pool.get_nowait()
    except queue.Empty:
        planning = copy.copy(model)
        return planning, mujoco.MjData(planning)
