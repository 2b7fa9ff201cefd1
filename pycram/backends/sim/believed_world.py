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
- **its state** (`BelievedWorld.snapshot`): the robot's base and joints from the latest
  published sensor state (the robot's encoders), each container at its believed opening
  (``belief.container_states``; closed until measured), each present believed object's proxy at
  its believed centre and yaw, an object in a gripper at that arm's tool frame (where the grasp
  holds it), every unused proxy parked far below the floor.

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
from collections.abc import Callable
from typing import Any

import mujoco
import numpy as np

from pycram.world.environment import Environment
from pycram.world.objects import OBJECT_TYPES

from .items import ItemSpec
from .recording import StateSnapshot
from .robot_model import BASE_JOINTS, tool_site
from .scene import Scene, _subtree_bodies, build_scene

__all__ = ["BelievedWorld", "GENERIC_SLOTS", "SLOTS_PER_TYPE", "believed_scene"]

_log = logging.getLogger(__name__)

#: Proxies per known object type: how many objects of one type prospection can know at once.
SLOTS_PER_TYPE = 6
#: Box proxies for objects of types without a nominal shape (sized when first used).
GENERIC_SLOTS = 8
#: Where unused proxies wait [m]: far below the floor, 1 m apart.
PARKING_DEPTH = -50.0
#: The generic proxy's type name.
GENERIC = "generic"

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


class BelievedWorld:
    """Prospection's model and state for one robot: the environment description plus the
    belief (see the module docstring).

    `true_scene` is the simulation's scene (for the robot's joint names and the sensor state's
    layout: only the robot's own joints are read from `sensor_state()`), `belief` the robot's
    :class:`pycram.world.belief.BeliefState`, `sensor_state` returns the latest published
    `StateSnapshot` of the simulation.
    """

    def __init__(self, true_scene: Scene, belief: Any, sensor_state: Callable[[], StateSnapshot]) -> None:
        shared = believed_scene(true_scene.robot, true_scene.environment)
        # a model of its own: generic proxies are sized for this belief's objects
        self.scene = dataclasses.replace(shared, model=copy.copy(shared.model))
        self.belief = belief
        self._sensor_state = sensor_state
        model, true_model = self.scene.model, true_scene.model
        mount = mujoco.mj_name2id(true_model, mujoco.mjtObj.mjOBJ_BODY, true_scene.description.ROOT_LINK)
        robot_bodies = _subtree_bodies(true_model, mount)
        own = [
            j
            for j in range(true_model.njnt)
            if int(true_model.jnt_bodyid[j]) in robot_bodies or true_model.joint(j).name in BASE_JOINTS
        ]
        own = [j for j in own if true_model.jnt_type[j] != mujoco.mjtJoint.mjJNT_FREE]
        # (qpos address here, qpos address in the simulation) of each of the robot's joints
        self._own = np.array(
            [
                (self.scene.joint_qpos(true_model.joint(j).name), int(true_model.jnt_qposadr[j]))
                for j in own
                if true_model.jnt_type[j] != mujoco.mjtJoint.mjJNT_BALL
            ],
            dtype=np.int64,
        ).reshape(-1, 2)
        self._containers = {c.name: self.scene.joint_qpos(c.joint_name) for c in true_scene.environment.containers}
        self._free: dict[str, list[str]] = {}  # type -> proxy names, in slot order
        for spec in self.scene.items:
            self._free.setdefault(spec.type, []).append(spec.name)
        self._qadr = {
            spec.name: int(model.jnt_qposadr[model.body_jntadr[self.scene.body(spec.name)]])
            for spec in self.scene.items
        }
        self._tool_sites = {arm: self.scene.site(tool_site(arm)) for arm in true_scene.description.ARMS}
        self._lock = threading.Lock()
        self._assigned: dict[str, str] = {}  # belief name -> proxy name (kept for good)
        self._left_out: set[str] = set()
        self._data = mujoco.MjData(model)  # for the tool frames (under the lock)
        self._mocap = self._data.mocap_pos.copy(), self._data.mocap_quat.copy()  # obstacles, parked

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
    def snapshot(self) -> StateSnapshot:
        """The believed world now, as a state of `scene` (see the module docstring)."""
        sensed = self._sensor_state()
        with self._lock:
            model, d = self.scene.model, self._data
            qpos = model.qpos0.copy()  # every proxy parked where it was compiled (`_parking`)
            qpos[self._own[:, 0]] = sensed.qpos[self._own[:, 1]]
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
                    site = self._tool_sites[gripper]
                    quat = np.zeros(4)
                    mujoco.mju_mat2Quat(quat, d.site_xmat[site])
                    qpos[adr : adr + 3] = d.site_xpos[site]
                    qpos[adr + 3 : adr + 7] = quat
                    continue
                yaw = float(getattr(obj, "yaw", 0.0))
                qpos[adr : adr + 3] = [float(v) for v in obj.pose[:3]]
                qpos[adr + 3 : adr + 7] = (math.cos(yaw / 2.0), 0.0, 0.0, math.sin(yaw / 2.0))
        return StateSnapshot(sensed.time, qpos, self._mocap[0].copy(), self._mocap[1].copy())
