"""The believed world: what the robot's prospection is built from -- the environment's
description and the robot's belief, never the simulator's truth.

A real robot plans against what it knows: the building's map (the environment description), its
own joints (proprioception), the containers as it last saw them open, the objects it perceived.
:class:`BelievedWorld` gives a :class:`~pycram.backends.sim.prospection.SimProspection` exactly
that:

- **its own model** (`believed_scene`, compiled once per robot and environment): the
  environment and the robot, and instead of the simulator's items a pool of *proxy* objects --
  `SLOTS_PER_TYPE` free bodies of each known object type's nominal shape
  (:data:`pycram.world.objects.OBJECT_TYPES`) and `GENERIC_SLOTS` boxes for objects of other
  types, sized from their measured size when first used. No obstacles: nobody perceived them.
  An object nobody perceived is not in it; a drawer a person pulled out unseen is closed in it.
- **its state** (`BelievedWorld.snapshot`): the robot's base and joints as its own sensors report
  them (proprioception: a `SensedRobot` -- joint positions by name and the base pose, what a ROS
  robot's ``/joint_states`` and localisation give; for a simulated robot, the latest published
  sensor state of the simulation, read by `BelievedWorld.of_simulation`), each container at its
  believed opening (``belief.container_states``; closed until measured), each present believed
  object's proxy at its believed centre and orientation (upright at its yaw, or on its side as
  measured), an object in a gripper where the hand holds it (its believed pose in the tool frame
  when first seen held, carried with the hand from then on), every unused proxy parked far below
  the floor.

Nothing here needs the simulator's true scene: `BelievedWorld(robot, environment, belief,
sensed)` is built from the robot's name, the environment's description, the belief and the
robot's sensed state alone -- MuJoCo serves as a geometry and kinematics engine for reasoning.
A robot over ROS gets its prospection this way (:mod:`pycram.robots.common.ros_prospection`).

Names: prospection answers about believed objects by their belief names ("cup-1"); the proxy
standing for one is found with `BelievedWorld.body_of`. Believed objects beyond a type's slots
are left out (logged once per object): prospection then does not know them.

Thread-safe: `snapshot` may be called from any thread; snapshots are immutable once made.
"""

from __future__ import annotations

import copy
import dataclasses
import logging
import math
import threading
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import mujoco
import numpy as np

from pycram.world.environment import Environment
from pycram.world.objects import OBJECT_TYPES
from pycram.world.types import Pose, Pose2D

from .items import ItemSpec
from .recording import StateSnapshot
from .robot_model import BASE_JOINTS, tool_site
from .scene import Scene, _subtree_bodies, build_scene

__all__ = ["BelievedWorld", "GENERIC_SLOTS", "SLOTS_PER_TYPE", "SensedRobot", "believed_scene"]

_log = logging.getLogger(__name__)

#: Proxies per known object type: how many objects of one type prospection can know at once.
SLOTS_PER_TYPE = 6
#: Box proxies for objects of types without a nominal shape (sized when first used).
GENERIC_SLOTS = 8
#: Where unused proxies wait [m]: far below the floor, 1 m apart.
PARKING_DEPTH = -50.0
#: The generic proxy's type name.
GENERIC = "generic"
#: A held object believed farther than this [m] from the tool frame when first seen held is put at
#: the tool frame (its believed pose is stale): no gripper holds an object by a point that far.
GRIP_REACH = 0.3

_scenes: dict[tuple[str, Environment], Scene] = {}
_scenes_lock = threading.Lock()


def _proxy_name(type_name: str, slot: int) -> str:
    return f"believed:{type_name}:{slot}"


def _parking(index: int) -> tuple[float, float, float]:
    return (float(index), 0.0, PARKING_DEPTH)


def believed_scene(robot: str, environment: Environment) -> Scene:
    """The prospection scene of `robot` in `environment`: both, with proxy objects and no items
    or obstacles (see the module docstring). Compiled on first use (~0.1-0.5 s), then shared
    (read-only: each `BelievedWorld` works on its own copy of the model)."""
    key = (robot, environment)
    with _scenes_lock:
        scene = _scenes.get(key)
        if scene is None:
            proxies: list[ItemSpec] = []
            for type_name in sorted(OBJECT_TYPES):
                for slot in range(SLOTS_PER_TYPE):
                    spec = ItemSpec.of(OBJECT_TYPES[type_name], _proxy_name(type_name, slot), _parking(len(proxies)))
                    proxies.append(spec)
            for slot in range(GENERIC_SLOTS):
                position = _parking(len(proxies))
                proxies.append(ItemSpec(_proxy_name(GENERIC, slot), GENERIC, "box", (0.05, 0.05, 0.05), 0.1, position))
            scene = _scenes[key] = build_scene(robot, proxies, (64, 48), environment)
        return scene


@dataclass(frozen=True)
class SensedRobot:
    """The robot as its own sensors report it: what a believed world takes from the robot.

    ``time``: when it was sensed [s, the robot's clock]; ``joints``: joint positions [rad or m]
    by joint name (the names of the robot's model, as its URDF and ``/joint_states`` name them;
    names the model does not know are ignored, joints not named stay where the model was
    compiled); ``base``: the base pose in the map frame (x [m], y [m], yaw [rad]), which wins
    over base joints in ``joints`` (None: those, if any)."""

    time: float
    joints: Mapping[str, float]
    base: Pose2D | None = None


#: Reads the robot's sensed state into a believed scene's ``qpos`` (its own joints only) and
#: returns the time it was sensed [s].
_RobotReader = Callable[[np.ndarray], float]


class BelievedWorld:
    """Prospection's model and state for one robot: the environment description plus the
    belief (see the module docstring).

    `robot` is the robot's registered name, `environment` the environment's description,
    `belief` the robot's :class:`pycram.world.belief.BeliefState`, `sensed` returns the robot's
    latest `SensedRobot` (called at every `snapshot`, from any thread; it may raise
    ``LookupError`` while nothing was sensed yet). ``ValueError`` when `sensed` names a
    joint with a position that is not a finite number. For a simulated robot,
    `of_simulation` reads the simulation's published sensor state directly.
    """

    def __init__(self, robot: str, environment: Environment, belief: Any, sensed: Callable[[], SensedRobot]) -> None:
        self._setup(robot, environment, belief)
        addresses = {self.scene.model.joint(j).name: int(self.scene.model.jnt_qposadr[j]) for j in self._own_joints()}
        base = [addresses[j] for j in BASE_JOINTS if j in addresses]

        def read(qpos: np.ndarray) -> float:
            state = sensed()
            for name, value in state.joints.items():
                address = addresses.get(name)
                if address is not None:
                    position = float(value)
                    if not math.isfinite(position):
                        raise ValueError(f"sensed joint {name!r} at {value!r}: not a finite position [rad or m]")
                    qpos[address] = position
            if state.base is not None and len(base) == 3:
                qpos[base] = (state.base.x, state.base.y, state.base.yaw)
            return float(state.time)

        self._read: _RobotReader = read

    @classmethod
    def of_simulation(cls, true_scene: Scene, belief: Any, sensor_state: Callable[[], StateSnapshot]) -> BelievedWorld:
        """The believed world of the simulated robot of `true_scene` (the simulation's scene):
        its joints are read from `sensor_state()`, the latest published `StateSnapshot` of the
        simulation (only the robot's own joints: its encoders), by address -- nothing else of
        the simulation's state or scene is read."""
        world = cls.__new__(cls)
        world._setup(true_scene.robot, true_scene.environment, belief)
        model = world.scene.model
        # (qpos address here, qpos address in the simulation) of each of the robot's joints
        pairs = np.array(
            [(int(model.jnt_qposadr[j]), true_scene.joint_qpos(model.joint(j).name)) for j in world._own_joints()],
            dtype=np.int64,
        ).reshape(-1, 2)

        def read(qpos: np.ndarray) -> float:
            state = sensor_state()
            qpos[pairs[:, 0]] = state.qpos[pairs[:, 1]]
            return float(state.time)

        world._read = read
        return world

    def _setup(self, robot: str, environment: Environment, belief: Any) -> None:
        shared = believed_scene(robot, environment)
        # a model of its own: generic proxies are sized for this belief's objects
        self.scene = dataclasses.replace(shared, model=copy.copy(shared.model))
        self.belief = belief
        model = self.scene.model
        self._containers = {c.name: self.scene.joint_qpos(c.joint_name) for c in environment.containers}
        self._free: dict[str, list[str]] = {}  # type -> proxy names, in slot order
        for spec in self.scene.items:
            self._free.setdefault(spec.type, []).append(spec.name)
        self._qadr = {
            spec.name: int(model.jnt_qposadr[model.body_jntadr[self.scene.body(spec.name)]])
            for spec in self.scene.items
        }
        self._tool_sites = {arm: self.scene.site(tool_site(arm)) for arm in self.scene.description.ARMS}
        self._lock = threading.Lock()
        self._assigned: dict[str, str] = {}  # belief name -> proxy name (kept for good)
        self._left_out: set[str] = set()
        #: (id of a held object, gripper) -> its pose in the tool frame when first seen held
        self._grips: dict[tuple[int, str], tuple[np.ndarray, np.ndarray]] = {}
        self._data = mujoco.MjData(model)  # for the tool frames (under the lock)
        self._mocap = self._data.mocap_pos.copy(), self._data.mocap_quat.copy()  # obstacles, parked

    def _own_joints(self) -> list[int]:
        """The robot's own joints in this model (its base and every hinge or slide below its
        root link; not the proxies' free joints, not the furniture's), in model order."""
        model = self.scene.model
        mount = self.scene.body(self.scene.description.ROOT_LINK)
        robot_bodies = _subtree_bodies(model, mount)
        return [
            j
            for j in range(model.njnt)
            if (int(model.jnt_bodyid[j]) in robot_bodies or model.joint(j).name in BASE_JOINTS)
            and model.jnt_type[j] not in (mujoco.mjtJoint.mjJNT_FREE, mujoco.mjtJoint.mjJNT_BALL)
        ]

    # ------------------------------------------------------------------ names
    def body_of(self, name: str) -> str | None:
        """The proxy body standing for the believed object `name`, or None (not believed, or
        left out)."""
        with self._lock:
            proxy = self._assigned.get(name)
            if proxy is None:
                for obj in self._objects():
                    if obj.name == name:
                        return self._slot(obj)
            return proxy

    def name_of(self, body: str) -> str | None:
        """The believed object the proxy `body` stands for (its belief name), or None."""
        with self._lock:
            return next((name for name, proxy in self._assigned.items() if proxy == body), None)

    def names(self) -> list[str]:
        """The names of the objects believed now (present or held), sorted."""
        return sorted(obj.name for obj in self._objects() if not getattr(obj, "gone", False) or self._held(obj))

    def _objects(self) -> list[Any]:
        objects = getattr(self.belief, "objects", None)
        return list(objects()) if callable(objects) else []

    def _held(self, obj: Any) -> bool:
        return any(o is obj for o in dict(getattr(self.belief, "in_hand", {})).values())

    def _slot(self, obj: Any) -> str | None:
        """The proxy of `obj` (assigned on first use; under the lock)."""
        proxy = self._assigned.get(obj.name)
        if proxy is not None:
            return proxy
        known = obj.type in OBJECT_TYPES
        free = self._free.get(obj.type if known else GENERIC, [])
        if not free:
            if obj.name not in self._left_out:
                self._left_out.add(obj.name)
                _log.warning(
                    "prospection knows no more %s objects (%d proxies): %s is left out",
                    obj.type if known else "untyped",
                    SLOTS_PER_TYPE if known else GENERIC_SLOTS,
                    obj.name,
                )
            return None
        proxy = self._assigned[obj.name] = free.pop(0)
        if not known:
            self._size_generic(proxy, obj.properties.get("size"))
        return proxy

    def _size_generic(self, proxy: str, size: Any) -> None:
        """Give the generic box `proxy` the measured `size` (x, y, z) [m] (before any snapshot
        shows it in place: queries on older snapshots find it parked)."""
        try:
            half = [max(0.005, float(v) / 2.0) for v in size][:3]
        except (TypeError, ValueError):
            half = [0.05, 0.05, 0.05]
        if len(half) != 3:
            half = [0.05, 0.05, 0.05]
        model = self.scene.model
        for g in np.flatnonzero(model.geom_bodyid == self.scene.body(proxy)):
            model.geom_size[g] = half
            model.geom_rbound[g] = math.sqrt(sum(h * h for h in half))
            model.geom_aabb[g] = [0.0, 0.0, 0.0, *half]

    # ------------------------------------------------------------------ state
    def tool_poses(self) -> dict[str, Pose]:
        """Each arm's tool frame (map frame: position [m], orientation (w, x, y, z)) with the robot
        as it is sensed now: forward kinematics of its joints and base pose (what a real robot's
        tf tree gives)."""
        qpos = self.scene.model.qpos0.copy()
        self._read(qpos)
        poses: dict[str, Pose] = {}
        with self._lock:
            d = self._data
            d.qpos[:] = qpos
            mujoco.mj_kinematics(self.scene.model, d)
            for arm, site in self._tool_sites.items():
                quat = np.zeros(4)
                mujoco.mju_mat2Quat(quat, d.site_xmat[site])
                x, y, z = (float(v) for v in d.site_xpos[site])
                w, qx, qy, qz = (float(v) for v in quat)
                poses[arm] = Pose((x, y, z), (w, qx, qy, qz))
        return poses

    def snapshot(self) -> StateSnapshot:
        """The believed world now, as a state of `scene` (see the module docstring)."""
        qpos = self.scene.model.qpos0.copy()  # every proxy parked where it was compiled (`_parking`)
        time = self._read(qpos)
        with self._lock:
            model, d = self.scene.model, self._data
            for name, q in dict(getattr(self.belief, "container_states", {})).items():
                address = self._containers.get(name)
                if address is not None:
                    qpos[address] = float(q)
            in_hand = dict(getattr(self.belief, "in_hand", {}))
            held = {id(obj): gripper for gripper, obj in in_hand.items()}
            if held:  # the tool frames of the robot as it stands now
                d.qpos[:] = qpos
                mujoco.mj_kinematics(model, d)
            for obj in self._objects():
                gripper = held.get(id(obj))
                if gripper is None and (getattr(obj, "gone", False) or obj.pose is None):
                    continue
                slot = self._slot(obj)
                if slot is None:
                    continue
                adr = self._qadr[slot]
                if gripper is not None and gripper in self._tool_sites:
                    qpos[adr : adr + 7] = self._in_hand(d, obj, gripper)
                    continue
                qpos[adr : adr + 3] = [float(v) for v in obj.pose[:3]]
                qpos[adr + 3 : adr + 7] = _believed_orientation(obj)
            for key in [k for k in self._grips if held.get(k[0]) != k[1]]:
                del self._grips[key]  # put down or lost: a later grasp is measured anew
        return StateSnapshot(time, qpos, self._mocap[0].copy(), self._mocap[1].copy())

    def _in_hand(self, d: mujoco.MjData, obj: Any, gripper: str) -> np.ndarray:
        """The pose (position [m], quaternion w, x, y, z) of `obj`, held by `gripper`, with the
        robot as `d` has it: the object keeps the pose in the tool frame it had when first seen
        held -- where it was believed when the fingers closed, relative to the tool then (a cereal
        box held by its near side hangs ahead of the tool frame; put at the tool frame, plans
        for it pressed it into the counter). Without a believed pose, or one farther than
        `GRIP_REACH` from the tool (a stale belief), it sits at the tool frame. Under the lock."""
        site = self._tool_sites[gripper]
        tool_pos, tool_quat = d.site_xpos[site].copy(), np.zeros(4)
        mujoco.mju_mat2Quat(tool_quat, d.site_xmat[site])
        key = (id(obj), gripper)
        grip = self._grips.get(key)
        if grip is None:
            grip = (np.zeros(3), np.array([1.0, 0.0, 0.0, 0.0]))
            if obj.pose is not None and math.dist(obj.pose[:3], tool_pos) <= GRIP_REACH:
                obj_quat = np.array(_believed_orientation(obj))
                inv_pos, inv_quat = np.zeros(3), np.zeros(4)
                mujoco.mju_negPose(inv_pos, inv_quat, tool_pos, tool_quat)
                rel_pos, rel_quat = np.zeros(3), np.zeros(4)
                mujoco.mju_mulPose(rel_pos, rel_quat, inv_pos, inv_quat, np.asarray(obj.pose[:3], float), obj_quat)
                grip = (rel_pos, rel_quat)
            self._grips[key] = grip
        pos, quat = np.zeros(3), np.zeros(4)
        mujoco.mju_mulPose(pos, quat, tool_pos, tool_quat, grip[0], grip[1])
        return np.concatenate([pos, quat])


def _believed_orientation(obj: Any) -> tuple[float, float, float, float]:
    """How `obj` is believed to stand or lie (w, x, y, z): its measured ``orientation`` (a lying
    object on its side) when perception measured one, else upright turned by its ``yaw``."""
    measured = getattr(obj, "orientation", None)
    if measured is not None and len(measured) == 4:
        w, x, y, z = (float(v) for v in measured)
        return (w, x, y, z)
    yaw = float(getattr(obj, "yaw", 0.0))
    return (math.cos(yaw / 2.0), 0.0, 0.0, math.sin(yaw / 2.0))
