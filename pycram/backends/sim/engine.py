"""The single-threaded simulation core: model, data, servo targets, grasp welds, measurements.

An `Engine` is used by exactly one thread (the world's simulation thread). Nothing here locks.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable
from typing import Any, Generic, TypeVar, cast

import mujoco
import numpy as np

from pycram.world.types import GripperState, JointStates, Pose, Pose2D, Quat, Vec3

from .furniture import Furniture
from .robot_model import BASE_JOINTS, HEAD_CAMERA, pad_site, tool_site
from .scene import Scene, initial_state, weld_name

_log = logging.getLogger(__name__)

#: Items taken "aside" by fault injection are put on the floor this far [m] beyond the
#: environment's plan (east of everything, out of the way).
ASIDE_DISTANCE = 1.5
#: A closing gripper grasps an item only while its fingers are at least this far apart [m]:
#: fully closed fingers have nothing between them, whatever touches their outsides.
MIN_GRASP_OPENING = 0.003
#: Up to this many geoms, `Engine.base_contacts` looks contacts up in a table of geom pairs.
PAIR_TABLE_GEOMS = 2048


_T = TypeVar("_T")


class Deferred(Generic[_T]):
    """A value computed on its first call, `make(*args)`, from arguments copied when it was made:
    a sensor value that the simulation thread publishes at the cost of a few array copies and
    that is built (dicts, poses) only if somebody reads it (`Fluent.get_value` calls a callable
    value). Every call returns the same object; two threads calling it first at the same time
    both compute it (from the same copies: equal values)."""

    __slots__ = ("_make", "_args", "_value", "_done")

    def __init__(self, make: Callable[..., _T], *args: Any) -> None:
        self._make, self._args = make, args
        self._done = False

    def __call__(self) -> _T:
        if not self._done:
            self._value = self._make(*self._args)
            self._done = True  # after the value: a reader that sees it done sees the value
        return self._value


def _joint_states(stamp: float, names: list[str], positions: np.ndarray, velocities: np.ndarray) -> JointStates:
    return JointStates(stamp, dict(zip(names, positions.tolist())), dict(zip(names, velocities.tolist())))


def _poses(names: list[str], positions: np.ndarray, orientations: np.ndarray) -> dict[str, Pose]:
    """Poses by name from rows of positions [m] and orientations (w, x, y, z)."""
    return {
        n: Pose(cast(Vec3, tuple(p)), cast(Quat, tuple(q)))
        for n, p, q in zip(names, positions.tolist(), orientations.tolist())
    }


def _site_poses(names: list[str], positions: np.ndarray, rotations: np.ndarray) -> dict[str, Pose]:
    """Poses by name from rows of positions [m] and rotation matrices (9 numbers, row-major)."""
    quat = np.zeros(4)
    out = {}
    for name, position, rotation in zip(names, positions, rotations):
        mujoco.mju_mat2Quat(quat, rotation)
        out[name] = Pose(cast(Vec3, tuple(position.tolist())), cast(Quat, tuple(quat.tolist())))
    return out


class Gripper:
    """Index data and grasp state of one gripper."""

    def __init__(self, engine: Engine, name: str, spec: dict) -> None:
        s = engine.scene
        m = s.model
        self.name = name
        self.spec = spec
        self.joint = spec["joint"]
        self.qpos = s.joint_qpos(self.joint)
        self.dof = s.joint_dof(self.joint)
        self.actuator = s.actuator(self.joint)
        self.pads = (s.site(pad_site(name, 0)), s.site(pad_site(name, 1)))
        self.palm = s.body(spec["palm_link"])
        sides = []
        for link in spec["finger_links"]:
            b = s.body(link)
            parent = int(m.body_parentid[b])
            sides.append({b} if parent == self.palm else {b, parent})
        self.sides: tuple[set[int], set[int]] = (sides[0], sides[1])
        self.welds = {it.name: s.equality(weld_name(name, it.name)) for it in s.items}
        self.holding: str | None = None
        #: True while the last command asked the gripper to close (to a width below the current one)
        self.closing = False
        self.target_opening = 0.0
        # opening [m] as a function of the driving joint, sampled on a scratch copy
        lo, hi = spec["joint_range"]
        self.table_q = np.linspace(lo, hi, 25)
        scratch = mujoco.MjData(m)
        scratch.qpos[:] = engine.data.qpos
        jid = s.joint_id(self.joint)
        #: (qpos index, offset, factor) of every joint coupled to the driving one by an equality
        self.coupled = [
            (int(m.jnt_qposadr[m.eq_obj1id[e]]), float(m.eq_data[e, 0]), float(m.eq_data[e, 1]))
            for e in range(m.neq)
            if m.eq_type[e] == mujoco.mjtEq.mjEQ_JOINT and m.eq_obj2id[e] == jid
        ]
        widths = []
        for q in self.table_q:
            self.set_qpos(scratch, q)
            mujoco.mj_kinematics(m, scratch)
            widths.append(self._opening(scratch))
        self.table_w = np.asarray(widths)

    def set_qpos(self, data: mujoco.MjData, q: float) -> None:
        """Set the driving joint and every coupled joint to the configuration of `q`."""
        data.qpos[self.qpos] = q
        for adr, offset, factor in self.coupled:
            data.qpos[adr] = offset + factor * q

    def _opening(self, data: mujoco.MjData) -> float:
        a, b = data.site_xpos[self.pads[0]].tolist(), data.site_xpos[self.pads[1]].tolist()
        return math.dist(a, b) - float(self.spec["pad_offset"])

    def opening(self, data: mujoco.MjData) -> float:
        """Measured opening [m] (distance between the finger pads), clipped at 0."""
        return max(0.0, self._opening(data))

    def joint_for_opening(self, width: float) -> float:
        """Driving joint position that gives an opening of `width` [m] (clipped to the range)."""
        order = np.argsort(self.table_w)
        return float(np.interp(width, self.table_w[order], self.table_q[order]))


class Engine:
    """Owns `MjModel`/`MjData` of one scene; all methods must be called from one thread."""

    def __init__(self, scene: Scene, base_pose: tuple[float, float, float]) -> None:
        self.scene = scene
        self.model = scene.model
        self.data = initial_state(scene, base_pose)
        desc = scene.description
        self.desc = desc
        self.base_qpos = [scene.joint_qpos(j) for j in BASE_JOINTS]
        self.base_dof = [scene.joint_dof(j) for j in BASE_JOINTS]
        self.base_act = [scene.actuator(j) for j in BASE_JOINTS]
        self.grippers = {name: Gripper(self, name, g) for name, g in desc.GRIPPERS.items()}
        self.camera = scene.camera(HEAD_CAMERA)
        self.tool_sites = {arm: scene.site(tool_site(arm)) for arm in desc.ARMS}
        self._tool_index = (list(self.tool_sites), np.array(list(self.tool_sites.values()), dtype=np.int64))
        self.item_bodies = {it.name: scene.body(it.name) for it in scene.items}
        self._item_names = list(self.item_bodies)
        self._item_ids = np.array([self.item_bodies[n] for n in self._item_names], dtype=np.int64)
        self._quat = np.zeros(4)  # scratch of `site_pose` (the simulation thread only)
        self._base_pairs: np.ndarray | None = None  # see `base_contacts`
        self._actuators: dict[str, int] = {}  # joint name -> its servo's index (`actuator`)
        self.item_geoms = {
            it.name: mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_GEOM, it.name) for it in scene.items
        }
        #: every geom of each item (items of several parts: bowls, plates)
        self.item_part_geoms = {
            name: [g for g in range(self.model.ngeom) if self.model.geom_bodyid[g] == b]
            for name, b in self.item_bodies.items()
        }
        self.geom_item = {g: name for name, gs in self.item_part_geoms.items() for g in gs}
        self.item_qpos = {
            it.name: int(self.model.jnt_qposadr[self.model.body_jntadr[b]])
            for it, b in zip(scene.items, self.item_bodies.values())
        }
        self.item_dof = {
            it.name: int(self.model.jnt_dofadr[self.model.body_jntadr[b]])
            for it, b in zip(scene.items, self.item_bodies.values())
        }
        # robot joints reported in joint states: everything but the items' free joints and furniture
        furniture_joints = {c.joint_name for c in scene.environment.containers}
        self.robot_joints = [
            (self.model.joint(j).name, int(self.model.jnt_qposadr[j]), int(self.model.jnt_dofadr[j]))
            for j in range(self.model.njnt)
            if self.model.jnt_type[j] != mujoco.mjtJoint.mjJNT_FREE and self.model.joint(j).name not in furniture_joints
        ]
        self._joint_index = (  # names, qpos and qvel addresses of `robot_joints` (`joint_states`)
            [n for n, _, _ in self.robot_joints],
            np.array([a for _, a, _ in self.robot_joints], dtype=np.int64),
            np.array([d for _, _, d in self.robot_joints], dtype=np.int64),
        )
        self.furniture = Furniture(self)
        self.obstacles = {
            f"obstacle_{i}": int(self.model.body_mocapid[scene.body(f"obstacle_{i}")])
            for i in range(self._count_obstacles())
        }
        self.obstacles_used: set[str] = set()
        self._aside_count = 0

    def _count_obstacles(self) -> int:
        n = 0
        while mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_BODY, f"obstacle_{n}") >= 0:
            n += 1
        return n

    # --- stepping -------------------------------------------------------------------------
    def step(self, nstep: int) -> None:
        """Advance the physics by `nstep` time steps and update the grasp welds."""
        mujoco.mj_step(self.model, self.data, nstep=nstep)
        self._update_grasps()

    @property
    def time(self) -> float:
        """Simulated time [s]."""
        return float(self.data.time)

    # --- servo helpers --------------------------------------------------------------------
    def q(self, joint: str) -> float:
        return float(self.data.qpos[self.scene.joint_qpos(joint)])

    def actuator(self, joint: str) -> int:
        """Index of the position servo driving `joint` (`Scene.actuator`, looked up once per
        name: controllers ask every control tick)."""
        aid = self._actuators.get(joint)
        if aid is None:
            aid = self._actuators[joint] = self.scene.actuator(joint)
        return aid

    def set_target(self, joint: str, value: float) -> None:
        """Command the position servo of `joint` to `value` [m or rad]."""
        self.data.ctrl[self.actuator(joint)] = value

    def set_target_ff(self, joint: str, position: float, velocity: float) -> None:
        """Command `joint` to track `position` while moving at `velocity` (velocity feed-forward).

        A position servo pushes kp (ctrl - q) - kv qdot; offsetting ctrl by kv/kp * velocity turns
        that into kp (position - q) + kv (velocity - qdot), so the joint does not lag behind.
        """
        aid = self.actuator(joint)
        kp = self.model.actuator_gainprm[aid, 0]
        kv = -self.model.actuator_biasprm[aid, 2]
        self.data.ctrl[aid] = position + kv / kp * velocity

    def target(self, joint: str) -> float:
        return float(self.data.ctrl[self.actuator(joint)])

    def hold(self, joints: list[str]) -> None:
        """Command each joint's servo to its current position (stop)."""
        for j in joints:
            self.set_target(j, self.q(j))

    # --- measurements ---------------------------------------------------------------------
    def base_pose(self) -> Pose2D:
        x, y, yaw = (float(self.data.qpos[i]) for i in self.base_qpos)
        return Pose2D(x, y, math.atan2(math.sin(yaw), math.cos(yaw)))

    def joint_states(self) -> JointStates:
        return self.deferred_joint_states()()

    def deferred_joint_states(self) -> Deferred[JointStates]:
        """`joint_states` now, built when first read (the positions and velocities copied now)."""
        names, qadr, dadr = self._joint_index
        return Deferred(_joint_states, self.time, names, self.data.qpos[qadr], self.data.qvel[dadr])

    def gripper_state(self, name: str) -> GripperState:
        """Opening [m], held item and effort [N] at the finger tips of gripper `name`."""
        g = self.grippers[name]
        effort = abs(float(self.data.actuator_force[g.actuator])) / g.spec["effort_lever"]
        return GripperState(g.opening(self.data), g.holding, effort)

    def item_pose(self, name: str) -> Pose:
        b = self.item_bodies[name]
        return Pose(cast(Vec3, tuple(self.data.xpos[b].tolist())), cast(Quat, tuple(self.data.xquat[b].tolist())))

    def item_poses(self) -> dict[str, Pose]:
        """Every item's `item_pose`, by name (one read of the state)."""
        return self.deferred_item_poses()()

    def deferred_item_poses(self) -> Deferred[dict[str, Pose]]:
        """`item_poses` now, built when first read (the items' poses copied now)."""
        ids = self._item_ids
        return Deferred(_poses, self._item_names, self.data.xpos[ids], self.data.xquat[ids])

    def deferred_tool_poses(self) -> Deferred[dict[str, Pose]]:
        """The `site_pose` of each arm's tool site (`tool_sites`) now, by arm, built when first read."""
        names, ids = self._tool_index
        return Deferred(_site_poses, names, self.data.site_xpos[ids], self.data.site_xmat[ids])

    def site_pose(self, site: int) -> Pose:
        quat = self._quat
        mujoco.mju_mat2Quat(quat, self.data.site_xmat[site])
        return Pose(cast(Vec3, tuple(self.data.site_xpos[site].tolist())), cast(Quat, tuple(quat.tolist())))

    def base_contacts(self) -> list[tuple[str, str]]:
        """Pairs (robot geom, environment geom) of base links touching the environment.

        Asked every control tick while the base drives: one lookup per contact in a table of
        the geom pairs that count (built on first use), names only for the few that touch."""
        ncon = self.data.ncon
        if ncon == 0:
            return []
        if self._base_pairs is None:
            self._base_pairs = self._base_pair_table()
        contact = self.data.contact
        geom = contact.geom[:ncon]
        pairs = self._base_pairs
        if pairs.ndim == 2:
            counted = pairs[geom[:, 0], geom[:, 1]]
        else:  # per geom: 1 base, 2 environment
            counted = (pairs[geom[:, 0]] | pairs[geom[:, 1]]) == 3
        if not counted.any():
            return []
        out = []
        base_geoms = self.scene.base_geoms
        for i in np.flatnonzero(counted & (contact.dist[:ncon] <= 0.0)).tolist():
            g1, g2 = int(geom[i, 0]), int(geom[i, 1])
            robot, other = (g1, g2) if g1 in base_geoms else (g2, g1)
            out.append((self.model.geom(robot).name, self.model.geom(other).name))
        return out

    def _base_pair_table(self) -> np.ndarray:
        """For `base_contacts`: a table (geom, geom) -> one is a base geom and the other an
        environment geom (ngeom^2 bytes, up to `PAIR_TABLE_GEOMS` geoms), else per geom 1 for
        a base geom, 2 for an environment geom."""
        n = self.model.ngeom
        kind = np.zeros(n, np.int8)
        kind[list(self.scene.base_geoms)] = 1
        kind[list(self.scene.environment_geoms)] = 2
        if n > PAIR_TABLE_GEOMS:
            return kind
        base, env = kind == 1, kind == 2
        return np.outer(base, env) | np.outer(env, base)

    # --- grasping -------------------------------------------------------------------------
    def _touching_items(self, g: Gripper, either: bool = False) -> set[str]:
        """Items touched by both fingers of `g` (by either finger with `either`)."""
        touched: tuple[set[str], set[str]] = (set(), set())
        bodyid = self.model.geom_bodyid
        for i in range(self.data.ncon):
            c = self.data.contact[i]
            g1, g2 = int(c.geom1), int(c.geom2)
            for a, b in ((g1, g2), (g2, g1)):
                item = self.geom_item.get(b)
                if item is None:
                    continue
                body = int(bodyid[a])
                for side in (0, 1):
                    if body in g.sides[side]:
                        touched[side].add(item)
        return (touched[0] | touched[1]) if either else (touched[0] & touched[1])

    def _update_grasps(self) -> None:
        """Contact-triggered grasping: a gripper that is closing welds an item when both of its
        fingers touch that item and the fingers are still apart (the item is between them).
        Nothing else ever attaches an item (except `GiveItem`, a person's hand-over)."""
        for g in self.grippers.values():
            if g.holding is None and g.closing:
                items = self._touching_items(g)
                if items and g.opening(self.data) >= MIN_GRASP_OPENING:
                    self.weld(g, sorted(items)[0])

    def weld(self, g: Gripper, item: str) -> None:
        """Attach `item` to the palm of `g` at their current relative pose (contact-triggered)."""
        eq = g.welds[item]
        d = self.data
        pb, ib = g.palm, self.item_bodies[item]
        rel_pos = d.xmat[pb].reshape(3, 3).T @ (d.xpos[ib] - d.xpos[pb])
        inv = np.zeros(4)
        mujoco.mju_negQuat(inv, d.xquat[pb])
        rel_quat = np.zeros(4)
        mujoco.mju_mulQuat(rel_quat, inv, d.xquat[ib])
        self.model.eq_data[eq, 0:3] = 0.0
        self.model.eq_data[eq, 3:6] = rel_pos
        self.model.eq_data[eq, 6:10] = rel_quat
        d.eq_active[eq] = 1
        g.holding = item
        _log.info("gripper %s grasped %s", g.name, item)

    def release(self, g: Gripper) -> str | None:
        """Deactivate the weld of `g`; returns the item it held."""
        item = g.holding
        if item is not None:
            self.data.eq_active[g.welds[item]] = 0
            g.holding = None
            _log.info("gripper %s released %s", g.name, item)
        return item

    def holder_of(self, item: str) -> Gripper | None:
        for g in self.grippers.values():
            if g.holding == item:
                return g
        return None

    # --- fault injection ------------------------------------------------------------------
    def set_item_pose(
        self,
        item: str,
        position: tuple[float, float, float],
        orientation: tuple[float, float, float, float] = (1.0, 0.0, 0.0, 0.0),
    ) -> None:
        """Put `item` at a pose with zero velocity (releasing any grasp first)."""
        g = self.holder_of(item)
        if g is not None:
            self.release(g)
        a, d = self.item_qpos[item], self.item_dof[item]
        self.data.qpos[a : a + 3] = position
        self.data.qpos[a + 3 : a + 7] = orientation
        self.data.qvel[d : d + 6] = 0.0
        mujoco.mj_forward(self.model, self.data)

    def aside_position(self, item: str) -> tuple[float, float, float]:
        """A free spot on the floor for `item`, beyond the environment (east of it)."""
        self._aside_count += 1
        spec = self.scene.item(item)
        _, y0, x1, _ = self.scene.environment.plan_bounds
        return (x1 + ASIDE_DISTANCE, y0 + 0.3 * self._aside_count, spec.half_height + 0.002)

    def place_obstacle(self, name: str, x: float, y: float) -> None:
        self.data.mocap_pos[self.obstacles[name]] = (x, y, 0.0)
        mujoco.mj_forward(self.model, self.data)

    def remove_obstacle(self, name: str, parking: tuple[float, float, float]) -> None:
        self.data.mocap_pos[self.obstacles[name]] = parking
        mujoco.mj_forward(self.model, self.data)
