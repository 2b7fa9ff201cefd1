"""Prospection in the simulator: "what if" on scratch copies of the current state.

`SimProspection` implements `pycram.world.prospection.Prospection` for one `World`. The
simulation thread publishes a `StateSnapshot` (joint positions, mocap poses; a few hundred
bytes, microseconds to copy) with every sensor update and right before a command's outcome is
delivered. A question takes the latest snapshot and works on an `MjData` of its own, taken
from a pool (one per concurrently asking thread, created on demand, reused afterwards):
it never touches the simulation thread's `MjData` and never copies the world. The model is
shared read-only (MuJoCo only reads it in kinematics, collision detection and ray casts).

Costs on this machine (PR2 in the thesis kitchen, one thread, simulation paused): a collision
check ~0.1 ms, a reachability check of 3 poses ~1-5 ms (more when it fails), a visibility
check ~0.5 ms; with the simulation running beside it, about half as many per second (see
`benchmarks/prospection.py`).

For arm motion planning (:mod:`pycram.reasoning.motion`) it also gives an arm's joint limits
(:mod:`.arm_limits`), configuration checkers on planning copies of the model whose collision
filter lets only the arm's pairs through (:mod:`.arm_checker`: ~20-30 us a check), and IK with
mink (:mod:`.mink_ik`).
"""

from __future__ import annotations

import math
import queue
import threading
from collections.abc import Callable, Iterator, Mapping, Sequence
from contextlib import contextmanager
from typing import Any, cast

import mujoco
import numpy as np

from pycram.world.prospection import (
    ConfigurationChecker,
    IKResult,
    JointLimits,
    Prospection,
    Reachability,
    ToolPose,
    Visibility,
    as_base_pose,
    as_tool_pose,
)

from . import arm_checker
from .arm_checker import (
    ArmBodies,
    SelfGroup,
    SimConfigurationChecker,
    arm_bodies,
    configure_filter,
    self_collision_exclusions,
    self_collision_groups,
)
from .arm_limits import joint_limits
from .believed_world import BelievedWorld
from .ik import dls_ik
from .occupancy import descends
from .recording import StateSnapshot
from .robot_model import BASE_JOINTS, HEAD_CAMERA, NOT_IK_SEEDS, tool_site
from .scene import Scene

#: Geom groups a camera sees (MuJoCo's default visualisation: groups 0, 1 and 2).
VISIBLE_GROUPS = np.array([1, 1, 1, 0, 0, 0], np.uint8)
#: Visibility rays start this far [m] ahead of the camera along its view axis, past the head.
HEAD_CLEARANCE = 0.06
#: Sample points per target geom for visibility.
POINTS_PER_GEOM = 24
#: Contacts penetrating less than this [m] do not count as collisions: mesh links collide as
#: their convex hulls (larger than the links), and MuJoCo's soft contacts let the running robot
#: brush surfaces this much (the thesis demo's grasps touch the counter by ~1 cm).
COLLISION_TOLERANCE = 0.015
#: IK: iterations per seed and the stall window (iterations without 1 % progress end a seed).
IK_ITERATIONS = 100
IK_STALL = 15
#: IK: after this many solutions that all collide, the pose counts as "collision".
MAX_COLLIDING_SOLUTIONS = 3
#: `solve_ik` (mink): iterations per seed, random seeds after the named ones.
MINK_ITERATIONS = 80
MINK_RANDOM_SEEDS = 4


class _Arm:
    """Index data of one arm for IK on scratch data."""

    def __init__(self, scene: Scene, arm: str) -> None:
        m = scene.model
        self.name = arm
        self.joints = tuple(scene.description.ARMS[arm]["joints"])
        jids = [scene.joint_id(j) for j in self.joints]
        self.jids = jids
        self.qadr = np.array([m.jnt_qposadr[j] for j in jids])
        self.dadr = np.array([m.jnt_dofadr[j] for j in jids])
        limited = np.array([bool(m.jnt_limited[j]) for j in jids])
        self.lo = np.where(limited, m.jnt_range[jids, 0], -np.inf)
        self.hi = np.where(limited, m.jnt_range[jids, 1], np.inf)
        self.limited = limited
        self.site = scene.site(tool_site(arm))
        self.configurations = [
            np.asarray(c, float)
            for name, c in sorted(scene.description.ARM_CONFIGURATIONS[arm].items())
            if name not in NOT_IK_SEEDS
        ]
        rng = np.random.default_rng(0)
        self.random_seeds = [
            rng.uniform(np.where(limited, self.lo, -np.pi), np.where(limited, self.hi, np.pi)) for _ in range(2)
        ]
        self.reach = 0.0  # [m] from the first joint's anchor; measured by SimProspection

    def seeds(self, current: np.ndarray, previous: np.ndarray | None) -> list[np.ndarray]:
        out = [] if previous is None else [previous]
        return out + [current] + self.configurations + self.random_seeds


class SimProspection(Prospection):
    """Prospection for the robot of `scene`, on the states returned by `snapshot()`;
    contacts penetrating less than `tolerance` [m] are not collisions.

    `snapshot` must return the latest `StateSnapshot` published by the simulation thread (a
    reference read is enough: snapshots are immutable once published).

    With `believed` (a :class:`~pycram.backends.sim.believed_world.BelievedWorld`; `scene` and
    `snapshot` are then its scene and its `snapshot`), objects are named as the belief names
    them ("cup-1") and stand in prospection as the believed world's proxies: the robot's
    prospection, which knows only what the robot knows.
    """

    def __init__(
        self,
        scene: Scene,
        snapshot: Callable[[], StateSnapshot],
        tolerance: float = COLLISION_TOLERANCE,
        believed: BelievedWorld | None = None,
    ) -> None:
        self.scene = scene
        self.believed = believed
        self.tolerance = tolerance
        self.model = scene.model
        self._snapshot = snapshot
        self._pool: queue.SimpleQueue[mujoco.MjData] = queue.SimpleQueue()
        m = self.model
        desc = scene.description
        self._base_qpos = [scene.joint_qpos(j) for j in BASE_JOINTS]
        self._joint_qpos = {
            m.joint(j).name: int(m.jnt_qposadr[j]) for j in range(m.njnt) if m.jnt_type[j] != mujoco.mjtJoint.mjJNT_FREE
        }
        self._is_robot = np.zeros(m.ngeom, bool)
        self._is_robot[list(scene.robot_geoms)] = True
        self._is_env = np.zeros(m.ngeom, bool)
        self._is_env[list(scene.environment_geoms)] = True
        self._arms = {a: _Arm(scene, a) for a in desc.ARMS}
        self._camera = scene.camera(HEAD_CAMERA)
        self._camera_body = int(m.cam_bodyid[self._camera])
        head = desc.HEAD
        self._head_jids = [scene.joint_id(head["pan_joint"]), scene.joint_id(head["tilt_joint"])]
        self._head_qpos = [int(m.jnt_qposadr[j]) for j in self._head_jids]
        self._head_dofs = [int(m.jnt_dofadr[j]) for j in self._head_jids]
        width, height = head.get("resolution", (320, 240))
        self._tan_y = math.tan(math.radians(head["fovy"]) / 2.0)
        self._tan_x = self._tan_y * width / height
        self._points: dict[int, np.ndarray] = {}
        self._target_geoms: dict[str, list[int]] = {}
        # geoms that move with the camera (the head it is mounted on): never occluders
        tilt_body = int(m.jnt_bodyid[self._head_jids[1]])
        head_bodies = {b for b in range(m.nbody) if descends(m, b, tilt_body)}
        self._is_head = np.array([int(m.geom_bodyid[g]) in head_bodies for g in range(m.ngeom)], bool)
        with self._data() as d:
            self._measure_reach(d)
        # arm motion planning: planning copies of the model, per-arm geom masks, IK solvers
        self._planning_pool: queue.SimpleQueue[tuple[mujoco.MjModel, mujoco.MjData]] = queue.SimpleQueue()
        self._parts: dict[tuple[str, bool], tuple[ArmBodies, np.ndarray, list[SelfGroup]]] = {}
        self._ik_pools: dict[str, queue.SimpleQueue[Any]] = {}
        self._planning_lock = threading.Lock()
        # navigation's goal check (`drivable`): built on first use; its planner per state
        self._drive_check: Any = None
        self._drive_planner: tuple[Any, Any] | None = None

    # ------------------------------------------------------------------ plumbing
    @property
    def arms(self) -> tuple[str, ...]:
        return tuple(self._arms)

    @contextmanager
    def _data(self) -> Iterator[mujoco.MjData]:
        try:
            d = self._pool.get_nowait()
        except queue.Empty:
            d = mujoco.MjData(self.model)
        try:
            yield d
        finally:
            self._pool.put(d)

    def _prepare(self, d: mujoco.MjData, base_pose: Any, joint_configuration: Mapping[str, float] | None) -> None:
        """`d` := the latest snapshot, the base at `base_pose`, joints as configured; kinematics."""
        pose = as_base_pose(base_pose)
        snap = self._snapshot()
        d.qpos[:] = snap.qpos
        d.mocap_pos[:] = snap.mocap_pos
        d.mocap_quat[:] = snap.mocap_quat
        for adr, v in zip(self._base_qpos, (pose.x, pose.y, pose.yaw)):
            d.qpos[adr] = v
        if joint_configuration:
            for name, value in joint_configuration.items():
                joint_adr = self._joint_qpos.get(name)
                if joint_adr is None:
                    raise ValueError(
                        f"unknown joint {name!r} of {self.scene.robot}; valid joints: {sorted(self._joint_qpos)}"
                    )
                d.qpos[joint_adr] = float(value)
        mujoco.mj_kinematics(self.model, d)

    def _touching(
        self,
        d: mujoco.MjData,
        robot: np.ndarray | None = None,
        obstacles: np.ndarray | None = None,
        tolerance: float | None = None,
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Collision detection on `d` (kinematics computed): contact geoms (g1, g2), whether g1
        is the robot's one, and which contacts are robot-obstacle collisions (`robot`: the mask
        of the robot's geoms, with those of objects it carries; default: the robot's own;
        `obstacles`: the mask of the obstacles' geoms, default: the environment's), penetrating
        more than `tolerance` [m] (default: this prospection's)."""
        mujoco.mj_collision(self.model, d)
        n = d.ncon
        geoms = d.contact.geom[:n]
        g1, g2 = geoms[:, 0], geoms[:, 1]
        is_robot = self._is_robot if robot is None else robot
        is_obstacle = self._is_env if obstacles is None else obstacles
        hit1 = is_robot[g1] & is_obstacle[g2]
        hit2 = is_robot[g2] & is_obstacle[g1]
        allowed = self.tolerance if tolerance is None else tolerance
        return g1, g2, hit1, (hit1 | hit2) & (d.contact.dist[:n] < -allowed)

    def _contacts(self, d: mujoco.MjData) -> list[tuple[str, str]]:
        """Distinct (robot part, environment part) pairs that touch in `d` (kinematics computed)."""
        g1, g2, hit1, sel = self._touching(d)
        out: dict[tuple[str, str], None] = {}
        for i in np.nonzero(sel)[0]:
            a, b = (int(g1[i]), int(g2[i])) if hit1[i] else (int(g2[i]), int(g1[i]))
            out[(self._geom_name(a), self._geom_name(b))] = None
        return list(out)

    def _geom_name(self, g: int) -> str:
        name = self.model.geom(g).name
        return name or self.model.body(int(self.model.geom_bodyid[g])).name

    def joint_position(self, name: str) -> float:
        """The position [rad or m] of joint `name` in the latest snapshot (the world as it is now)."""
        address = self._joint_qpos.get(name)
        if address is None:
            raise ValueError(f"unknown joint {name!r} of {self.scene.robot}; valid joints: {sorted(self._joint_qpos)}")
        return float(self._snapshot().qpos[address])

    # ------------------------------------------------------------------ collision
    def collisions(
        self, base_pose: Any, joint_configuration: Mapping[str, float] | None = None
    ) -> list[tuple[str, str]]:
        with self._data() as d:
            self._prepare(d, base_pose, joint_configuration)
            return self._contacts(d)

    def in_collision(
        self,
        base_pose: Any,
        joint_configuration: Mapping[str, float] | None = None,
        carried: Sequence[str] = (),
        objects: bool = False,
        tolerance: float | None = None,
    ) -> bool:
        """`Prospection.in_collision`; contacts penetrating less than `tolerance` [m] (default:
        this prospection's, `COLLISION_TOLERANCE` unless built with another) do not count."""
        with self._data() as d:
            self._prepare(d, base_pose, joint_configuration)
            robot = self._carry(d, base_pose, carried) if carried else self._is_robot
            obstacles = self._is_env
            if objects:  # every object but the carried ones is an obstacle too
                obstacles = (self._is_env | self._object_geoms()) & ~robot
            return bool(self._touching(d, robot, obstacles, tolerance)[3].any())

    def drivable(
        self, base_pose: Any, joint_configuration: Mapping[str, float] | None = None, carried: Sequence[str] = ()
    ) -> bool:
        """The drive's own goal check (`PathPlanner.pose_free` of `drive_check.DriveCheck`: the
        floor map's bands, the footprint grown by the drive's clearance, the robot's outline in
        `joint_configuration`) in this prospection's world, the objects not `carried` in the
        bands of their tops; where only an arm's outline is in the way, `in_collision` with the
        objects decides, as the drive's exact check does, with the drive's tolerance
        (`drive_check.DRIVE_TOLERANCE`: none). The planner is kept per state and
        configuration (one designator resolution asks many poses of one state)."""
        from .drive_check import DRIVE_TOLERANCE, DriveCheck

        pose = as_base_pose(base_pose)
        snap = self._snapshot()
        configuration = tuple(sorted((str(k), float(v)) for k, v in (joint_configuration or {}).items()))
        key = (snap.qpos.tobytes(), snap.mocap_pos.tobytes(), snap.mocap_quat.tobytes(), configuration, tuple(carried))
        cached = self._drive_planner
        if cached is None or cached[0] != key:
            with self._data() as d:
                self._prepare(d, pose, joint_configuration)
                check = self._drive_check
                if check is None:
                    check = self._drive_check = DriveCheck(self.scene, d)
                bodies = self.model.geom_bodyid
                held = {self._object_body(name) for name in carried}
                objects = [int(g) for g in np.flatnonzero(self._object_geoms()) if int(bodies[g]) not in held]
                cached = self._drive_planner = (key, check.planner(d, objects))
        planner = cached[1]

        def exact(x: float, y: float, yaw: float) -> bool:
            return not self.in_collision(
                (x, y, yaw), joint_configuration, carried, objects=True, tolerance=DRIVE_TOLERANCE
            )

        return planner.pose_free(pose.x, pose.y, pose.yaw, exact)

    def _carry(self, d: mujoco.MjData, base_pose: Any, carried: Sequence[str]) -> np.ndarray:
        """Move the objects `carried` in `d` (prepared: base and joints as asked, kinematics
        computed) with the hand that holds them -- the arm whose tool frame is nearest to the
        object in the snapshot -- as they sit in it now: with the base when the arm keeps its
        joints, with the tool when the arm moves too. Recomputes kinematics. Returns the mask of
        the robot's geoms with the carried objects'."""
        m = self.model
        with self._data() as now:  # the snapshot as it is: where each object sits in its hand
            snap = self._snapshot()
            now.qpos[:] = snap.qpos
            now.mocap_pos[:] = snap.mocap_pos
            now.mocap_quat[:] = snap.mocap_quat
            mujoco.mj_kinematics(m, now)
            robot = self._is_robot.copy()
            for name in carried:
                body = self._object_body(name)
                adr = int(m.jnt_qposadr[m.body_jntadr[body]])
                position = np.asarray(now.qpos[adr : adr + 3], float)
                arm = min(self._arms.values(), key=lambda a: float(np.linalg.norm(now.site_xpos[a.site] - position)))
                rot_then = now.site_xmat[arm.site].reshape(3, 3)
                rot_now = d.site_xmat[arm.site].reshape(3, 3)
                # the object's position and orientation in the tool frame, then placed at the tool now
                local = rot_then.T @ (position - now.site_xpos[arm.site])
                d.qpos[adr : adr + 3] = d.site_xpos[arm.site] + rot_now @ local
                turn = np.empty(4)
                mujoco.mju_mat2Quat(turn, (rot_now @ rot_then.T).ravel())
                quat = np.empty(4)
                mujoco.mju_mulQuat(quat, turn, np.asarray(now.qpos[adr + 3 : adr + 7], float))
                d.qpos[adr + 3 : adr + 7] = quat
                robot[m.geom_bodyid == body] = True
        mujoco.mj_kinematics(m, d)
        return robot

    # ------------------------------------------------------------------ arm motion planning
    def arm_joint_limits(self, arm: str, include_torso: bool = False) -> JointLimits:
        return joint_limits(self.scene, arm, include_torso)

    def _arm_parts(self, arm: str, include_torso: bool) -> tuple[ArmBodies, np.ndarray, list[SelfGroup]]:
        """The geom masks of `arm`, the (ngeom x ngeom) pairs never counted as collisions
        (self-collision exclusions) and the self-collision groups, measured once per arm."""
        key = (arm, include_torso)
        with self._planning_lock:
            found = self._parts.get(key)
        if found is not None:
            return found
        if arm not in self._arms:
            raise ValueError(f"unknown arm {arm!r} of {self.scene.robot}; valid arms: {list(self._arms)}")
        parts = arm_bodies(self.scene, arm, include_torso)
        model, data = arm_checker.take(self._planning_pool, self.model)
        try:
            initial = self._initial_qpos()
            pairs = self_collision_exclusions(model, data, self.scene, parts, initial)
        finally:
            self._planning_pool.put((model, data))
        body = self.model.geom_bodyid
        ignore = pairs[body[:, None], body[None, :]]
        groups = self_collision_groups(self.model, parts, pairs)
        with self._planning_lock:
            return self._parts.setdefault(key, (parts, ignore, groups))

    def _initial_qpos(self) -> np.ndarray:
        """The latest snapshot with the robot's joints at the description's initial configuration."""
        qpos = np.array(self._snapshot().qpos, float)
        desc = self.scene.description
        for name, value in {**desc.INITIAL_CONFIGURATION, desc.TORSO["joint"]: desc.TORSO["default"]}.items():
            adr = self._joint_qpos.get(name)
            if adr is not None:
                qpos[adr] = value
        return qpos

    def _body_name(self, name: str) -> str:
        """The body that stands for the object `name` here: itself, or in a believed world the
        proxy of the believed object of that name (ValueError naming the believed objects)."""
        if self.believed is None:
            return name
        proxy = self.believed.body_of(name)
        if proxy is None:
            raise ValueError(f"unknown object {name!r}; believed objects: {self.believed.names()}")
        return proxy

    def _object_body(self, name: str) -> int:
        """The body of the object `name` (a body with a free joint); ValueError listing the objects."""
        m = self.model
        bid = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, self._body_name(name))
        free = mujoco.mjtJoint.mjJNT_FREE
        if bid < 0 or m.body_jntnum[bid] != 1 or m.jnt_type[m.body_jntadr[bid]] != free:
            known = sorted(
                m.body(b).name
                for b in range(1, m.nbody)
                if m.body_jntnum[b] == 1 and m.jnt_type[m.body_jntadr[b]] == free
            )
            raise ValueError(f"unknown object {name!r}; known objects: {known}")
        return bid

    def _object_geoms(self) -> np.ndarray:
        """Mask of the geoms of objects (bodies with a free joint: items, believed objects)."""
        mask = getattr(self, "_objects_mask", None)
        if mask is None:
            m = self.model
            free = mujoco.mjtJoint.mjJNT_FREE
            bodies = np.array(
                [m.body_jntnum[b] == 1 and m.jnt_type[m.body_jntadr[b]] == free for b in range(m.nbody)], bool
            )
            mask = self._objects_mask = bodies[m.geom_bodyid]
        return mask

    def configuration_checker(
        self,
        arm: str,
        base_pose: Any,
        joint_configuration: Mapping[str, float] | None = None,
        *,
        include_torso: bool = False,
        held_object: str | None = None,
        exempt_object: str | None = None,
        clearance: float = 0.0,
        object_clearance: float = 0.0,
        self_collision: bool = True,
    ) -> ConfigurationChecker:
        if not math.isfinite(clearance):
            raise ValueError(f"clearance must be finite [m], got {clearance!r}")
        if not math.isfinite(object_clearance):
            raise ValueError(f"object_clearance must be finite [m], got {object_clearance!r}")
        parts, self_ignore, groups = self._arm_parts(arm, include_torso)
        m = self.model
        held_geoms = np.zeros(m.ngeom, bool)
        held = None
        ignore = self_ignore
        if exempt_object is not None:
            exempt = m.geom_bodyid == self._object_body(exempt_object)
            ignore = ignore.copy()
            ignore[np.ix_(exempt, parts.gripper)] = True
            ignore[np.ix_(parts.gripper, exempt)] = True
        planning, d = arm_checker.take(self._planning_pool, m)
        # objects sized since the copy was made (a believed world's generic proxies)
        planning.geom_size[:] = m.geom_size
        planning.geom_rbound[:] = m.geom_rbound
        planning.geom_aabb[:] = m.geom_aabb
        try:
            if held_object is not None:
                body = self._object_body(held_object)
                held_geoms = m.geom_bodyid == body
                # the grasp as it is now: the object's pose in the hand, from the latest snapshot
                snap = self._snapshot()
                d.qpos[:] = snap.qpos
                d.mocap_pos[:] = snap.mocap_pos
                d.mocap_quat[:] = snap.mocap_quat
                mujoco.mj_kinematics(m, d)
                hand = parts.hand_body
                inv_pos, inv_quat = np.zeros(3), np.zeros(4)
                mujoco.mju_negPose(inv_pos, inv_quat, d.xpos[hand], d.xquat[hand])
                rel_pos, rel_quat = np.zeros(3), np.zeros(4)
                mujoco.mju_mulPose(rel_pos, rel_quat, inv_pos, inv_quat, d.xpos[body], d.xquat[body])
                held = (int(m.jnt_qposadr[m.body_jntadr[body]]), rel_pos, rel_quat)
            objects = self._object_geoms() & ~held_geoms
            configure_filter(
                planning, parts, held_geoms, groups if self_collision else None, clearance, objects, object_clearance
            )
            thresholds = np.full(m.ngeom, clearance)
            thresholds[objects] = max(clearance, object_clearance)
            self._prepare(d, base_pose, joint_configuration)
        except BaseException:
            self._planning_pool.put((planning, d))
            raise
        return SimConfigurationChecker(
            planning,
            d,
            parts,
            ignore,
            thresholds,
            held,
            self._geom_name,
            lambda: self._planning_pool.put((planning, d)),
            # the robot's own links collide as their convex hulls, which overlap a little in
            # ordinary configurations (the TIAGo's shoulder and torso column by 11 mm, the torso
            # up): counted, such an overlap at the start made every plan from there tolerate
            # shallow contacts with everything, a carried spoon's with a drawer's handle too
            self_tolerance=self.tolerance,
        )

    def tool_pose(self, arm: str, base_pose: Any, joint_configuration: Mapping[str, float] | None = None) -> ToolPose:
        if arm not in self._arms:
            raise ValueError(f"unknown arm {arm!r} of {self.scene.robot}; valid arms: {list(self._arms)}")
        site = self._arms[arm].site
        with self._data() as d:
            self._prepare(d, base_pose, joint_configuration)
            quat = np.empty(4)
            mujoco.mju_mat2Quat(quat, d.site_xmat[site])
            position = cast(tuple[float, float, float], tuple(float(v) for v in d.site_xpos[site]))
            return ToolPose(position, cast(tuple[float, float, float, float], tuple(float(v) for v in quat)))

    def solve_ik(
        self,
        arm: str,
        pose: Any,
        base_pose: Any,
        joint_configuration: Mapping[str, float] | None = None,
        *,
        seeds: Sequence[Sequence[float]] = (),
        avoid_collisions: bool = True,
        held_object: str | None = None,
        exempt_object: str | None = None,
        clearance: float = 0.0,
        position_tolerance: float = 0.001,
        orientation_tolerance: float = 0.01,
    ) -> IKResult:
        from .mink_ik import MinkArmIK

        goal = as_tool_pose(pose)
        parts = self._arm_parts(arm, False)[0]
        a = self._arms[arm]
        with self._planning_lock:
            pool = self._ik_pools.setdefault(arm, queue.SimpleQueue())
        try:
            solver = pool.get_nowait()
        except queue.Empty:
            solver = MinkArmIK(self.model, arm, parts, a.jids)
        target_p = np.asarray(goal.position, float)
        target_q = None if goal.orientation is None else np.asarray(goal.orientation, float)
        try:
            with self._data() as d:
                self._prepare(d, base_pose, joint_configuration)
                qpos = d.qpos.copy()
            candidates = [np.asarray(s, float) for s in seeds] + a.seeds(qpos[a.qadr], None)
            rng = np.random.default_rng(0)
            candidates += [
                rng.uniform(np.where(a.limited, a.lo, -np.pi), np.where(a.limited, a.hi, np.pi))
                for _ in range(MINK_RANDOM_SEEDS)
            ]
            checker = (
                self.configuration_checker(
                    arm,
                    base_pose,
                    joint_configuration,
                    held_object=held_object,
                    exempt_object=exempt_object,
                    clearance=clearance,
                )
                if avoid_collisions
                else None
            )
            best = (math.inf, math.inf)
            iterations = colliding = 0
            collided: list[tuple[str, str]] = []
            try:
                for seed in candidates:
                    if len(seed) != len(a.joints):
                        raise ValueError(
                            f"an IK seed has {len(a.joints)} positions ({', '.join(a.joints)}), got {len(seed)}"
                        )
                    q, pe, re, its, converged = solver.solve(
                        qpos,
                        target_p,
                        target_q,
                        seed,
                        MINK_ITERATIONS,
                        position_tolerance,
                        orientation_tolerance,
                        # mink's limit keeps the whole arm off every object: not with an object
                        # grasped or held (the solution is checked below either way)
                        avoid_collisions and held_object is None and exempt_object is None,
                    )
                    iterations += its
                    if pe + 0.1 * re < best[0] + 0.1 * best[1]:
                        best = (pe, re)
                    if not converged:
                        continue
                    if checker is not None:
                        contacts = checker.contacts(q)
                        if contacts:
                            collided = collided or contacts
                            colliding += 1
                            if colliding >= MAX_COLLIDING_SOLUTIONS:
                                break  # a goal in contact (a hand round a handle): the rest would touch too
                            continue
                    return IKResult(arm, a.joints, tuple(map(float, q)), pe, re, None, "", iterations)
            finally:
                if checker is not None:
                    checker.close()
        finally:
            pool.put(solver)
        if collided:
            a_part, b_part = collided[0]
            return IKResult(
                arm,
                a.joints,
                (),
                best[0],
                best[1],
                "collision",
                f"every solution found touches {b_part} with {a_part}",
                iterations,
            )
        return IKResult(
            arm,
            a.joints,
            (),
            best[0],
            best[1],
            "no_solution",
            f"no seed converged within {position_tolerance} m / {orientation_tolerance} rad "
            f"(best {best[0]:.4f} m / {best[1]:.4f} rad)",
            iterations,
        )

    # ------------------------------------------------------------------ reachability
    def _measure_reach(self, d: mujoco.MjData) -> None:
        """Each arm's reach [m]: the farthest its tool gets from its first joint's anchor."""
        rng = np.random.default_rng(1)
        m = self.model
        for arm in self._arms.values():
            far = 0.0
            for _ in range(300):
                q = rng.uniform(np.where(arm.limited, arm.lo, -np.pi), np.where(arm.limited, arm.hi, np.pi))
                d.qpos[arm.qadr] = q
                mujoco.mj_kinematics(m, d)
                far = max(far, float(np.linalg.norm(d.site_xpos[arm.site] - d.xanchor[arm.jids[0]])))
            arm.reach = far * 1.05  # sampling under-estimates the true maximum a little

    def reachable(
        self, arm: str, poses: Sequence[Any], base_pose: Any, joint_configuration: Mapping[str, float] | None = None
    ) -> Reachability:
        if arm not in self._arms:
            raise ValueError(f"unknown arm {arm!r} of {self.scene.robot}; valid arms: {list(self._arms)}")
        goals = [as_tool_pose(p) for p in poses]
        if not goals:
            raise ValueError("reachable needs at least one tool pose")
        a = self._arms[arm]
        with self._data() as d:
            self._prepare(d, base_pose, joint_configuration)
            contacts = self._contacts(d)
            if contacts:
                return Reachability(
                    arm,
                    (),
                    "collision",
                    -1,
                    f"the robot at the base pose touches {contacts[0][1]} with {contacts[0][0]}",
                )
            current = d.qpos[a.qadr].copy()
            solutions: list[tuple[float, ...]] = []
            previous: np.ndarray | None = None
            for i, goal in enumerate(goals):
                result = self._solve(d, a, goal, current, previous)
                if isinstance(result, tuple):
                    reason, message = result
                    return Reachability(arm, tuple(solutions), reason, i, f"pose {i}: {message}")
                solutions.append(tuple(map(float, result)))
                previous = result
            return Reachability(arm, tuple(solutions))

    def _solve(
        self, d: mujoco.MjData, a: _Arm, goal: ToolPose, current: np.ndarray, previous: np.ndarray | None
    ) -> np.ndarray | tuple[str, str]:
        """A collision-free IK solution for `goal`, or (reason, message)."""
        m = self.model
        target_p = np.asarray(goal.position, float)
        target_q = None if goal.orientation is None else np.asarray(goal.orientation, float)
        distance = float(np.linalg.norm(target_p - d.xanchor[a.jids[0]]))
        if distance > a.reach:
            return "out_of_reach", (
                f"{distance:.2f} m from the {a.name} shoulder, farther than its reach of {a.reach:.2f} m"
            )
        seeds = a.seeds(current, previous)
        collided: list[tuple[str, str]] | None = None
        colliding = 0
        for seed in seeds:
            sol, converged = dls_ik(
                m, d, a.site, a.qadr, a.dadr, a.lo, a.hi, target_p, target_q, seed, IK_ITERATIONS, stall_window=IK_STALL
            )
            if not converged:
                continue
            q = np.asarray(sol.positions)
            d.qpos[a.qadr] = q
            mujoco.mj_kinematics(m, d)
            contacts = self._contacts(d)
            if not contacts:
                return q
            collided = collided or contacts
            colliding += 1
            if colliding >= MAX_COLLIDING_SOLUTIONS:
                break
        if collided:
            return "collision", f"every solution found touches {collided[0][1]} with {collided[0][0]}"
        free_lo, free_hi = np.full_like(a.lo, -np.inf), np.full_like(a.hi, np.inf)
        for seed in seeds[:2]:
            sol, converged = dls_ik(
                m,
                d,
                a.site,
                a.qadr,
                a.dadr,
                free_lo,
                free_hi,
                target_p,
                target_q,
                seed,
                IK_ITERATIONS,
                stall_window=IK_STALL,
            )
            if converged:
                q = np.asarray(sol.positions)
                worst = int(np.argmax(np.maximum(a.lo - q, q - a.hi)))
                return "joint_limit", (
                    f"only outside the joint limits ({a.joints[worst]}={q[worst]:.2f} "
                    f"outside [{a.lo[worst]:.2f}, {a.hi[worst]:.2f}])"
                )
        return "out_of_reach", f"no arm configuration puts the tool there ({distance:.2f} m from the shoulder)"

    # ------------------------------------------------------------------ visibility
    def _target_points(self, target: Any, d: mujoco.MjData) -> tuple[np.ndarray, set[int]]:
        """Sample points (n x 3, map) of `target` and the geoms that belong to it."""
        if isinstance(target, str):
            geoms = self._target_geoms.get(target)
            if geoms is None:
                geoms = self._target_geoms[target] = self._geoms_of(target)
            pts = [self._local_points(g) @ d.geom_xmat[g].reshape(3, 3).T + d.geom_xpos[g] for g in geoms]
            return np.vstack(pts), set(geoms)
        try:
            p = np.asarray([float(v) for v in target], float)
        except (TypeError, ValueError):
            p = np.zeros(0)
        if p.shape != (3,) or not np.all(np.isfinite(p)):
            raise ValueError(f"a visibility target is an object name or a point (x, y, z) [m]; got {target!r}")
        return p[None, :], set()

    def _geoms_of(self, name: str) -> list[int]:
        """The visible geoms of the object (body) `name`; ValueError listing the objects if none."""
        m = self.model
        bid = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, self._body_name(name))
        geoms = [
            g
            for g in range(m.ngeom)
            if bid >= 0 and int(m.geom_bodyid[g]) == bid and VISIBLE_GROUPS[min(int(m.geom_group[g]), 5)]
        ]
        if not geoms:
            known = sorted(
                {
                    m.body(int(m.geom_bodyid[g])).name
                    for g in range(m.ngeom)
                    if m.geom_bodyid[g] > 0
                    and m.body(int(m.geom_bodyid[g])).name == m.geom(g).name
                    and not self._is_robot[g]
                }
            )
            raise ValueError(f"unknown object {name!r}; known objects: {known}")
        return geoms

    def _local_points(self, g: int) -> np.ndarray:
        pts = self._points.get(g)
        if pts is None:
            m = self.model
            rng = np.random.default_rng(g)
            size, n = m.geom_size[g], POINTS_PER_GEOM
            t = m.geom_type[g]
            if t == mujoco.mjtGeom.mjGEOM_BOX:
                pts = rng.uniform(-0.9, 0.9, (n, 3)) * size
            elif t in (mujoco.mjtGeom.mjGEOM_CYLINDER, mujoco.mjtGeom.mjGEOM_CAPSULE):
                r, a = size[0] * 0.9 * np.sqrt(rng.uniform(0, 1, n)), rng.uniform(0, 2 * np.pi, n)
                pts = np.column_stack([r * np.cos(a), r * np.sin(a), rng.uniform(-0.9, 0.9, n) * size[1]])
            elif t == mujoco.mjtGeom.mjGEOM_SPHERE:
                v = rng.normal(size=(n, 3))
                pts = (
                    v / np.linalg.norm(v, axis=1, keepdims=True) * size[0] * 0.9 * rng.uniform(0, 1, (n, 1)) ** (1 / 3)
                )
            elif t == mujoco.mjtGeom.mjGEOM_MESH and m.geom_dataid[g] >= 0:
                mesh = int(m.geom_dataid[g])
                adr, num = int(m.mesh_vertadr[mesh]), int(m.mesh_vertnum[mesh])
                verts = np.asarray(m.mesh_vert[adr : adr + num], float)
                pick = verts[rng.choice(num, min(n, num), replace=False)]
                centre = verts.mean(axis=0)
                pts = centre + 0.8 * (pick - centre)
            else:
                c, h = m.geom_aabb[g, :3], m.geom_aabb[g, 3:]
                pts = c + rng.uniform(-0.5, 0.5, (n, 3)) * h
            self._points[g] = pts
        return pts

    def _point_head(self, d: mujoco.MjData, point: np.ndarray) -> None:
        """Turn pan/tilt (within limits) so that the camera looks at `point`; camera poses set."""
        m = self.model
        jacr = np.zeros((3, m.nv))
        for _ in range(6):
            mujoco.mj_camlight(m, d)
            forward = -d.cam_xmat[self._camera].reshape(3, 3)[:, 2]
            to = point - d.cam_xpos[self._camera]
            to /= max(float(np.linalg.norm(to)), 1e-9)
            axis = np.cross(forward, to)
            s = float(np.linalg.norm(axis))
            angle = math.atan2(s, float(forward @ to))
            if angle < 0.005 or s < 1e-9:
                return
            mujoco.mj_comPos(m, d)
            mujoco.mj_jacBody(m, d, None, jacr, self._camera_body)
            dq = np.linalg.lstsq(jacr[:, self._head_dofs], axis / s * angle, rcond=1e-3)[0]
            for adr, jid, step in zip(self._head_qpos, self._head_jids, dq):
                lo, hi = m.jnt_range[jid]
                d.qpos[adr] = float(np.clip(d.qpos[adr] + step, lo, hi)) if m.jnt_limited[jid] else d.qpos[adr] + step
            mujoco.mj_kinematics(m, d)
        mujoco.mj_camlight(m, d)

    def _look_past_head(
        self, d: mujoco.MjData, cam: np.ndarray, vec: np.ndarray, geomid: np.ndarray, dist: np.ndarray
    ) -> None:
        """Re-cast the rays whose first hit is part of the head, from just beyond that hit."""
        unit = np.zeros(1, np.int32)
        for i in np.nonzero(self._is_head[np.maximum(geomid, 0)] & (geomid >= 0))[0]:
            travelled = float(dist[i])
            for _ in range(8):
                g = int(geomid[i])
                if g < 0 or not self._is_head[g]:
                    break
                start = cam + (travelled + 1e-4) * vec[i]
                x = mujoco.mj_ray(self.model, d, start, vec[i], VISIBLE_GROUPS, 1, int(self.model.geom_bodyid[g]), unit)
                geomid[i] = unit[0] if x >= 0 else -1
                travelled += 1e-4 + max(x, 0.0)
            dist[i] = travelled

    def visible(
        self,
        target: Any,
        base_pose: Any,
        threshold: float = 0.5,
        joint_configuration: Mapping[str, float] | None = None,
    ) -> Visibility:
        m = self.model
        with self._data() as d:
            self._prepare(d, base_pose, joint_configuration)
            points, own = self._target_points(target, d)
            self._point_head(d, points.mean(axis=0))
            rot = d.cam_xmat[self._camera].reshape(3, 3)
            # rays start a little ahead of the lens, clear of the head the camera sits in
            cam = d.cam_xpos[self._camera] - HEAD_CLEARANCE * rot[:, 2]
            vec = points - cam
            local = vec @ rot  # camera frame: looks along -z, up +y
            depth = -local[:, 2]
            with np.errstate(divide="ignore", invalid="ignore"):
                in_view = (
                    (depth > 1e-6)
                    & (np.abs(local[:, 0]) <= self._tan_x * depth)
                    & (np.abs(local[:, 1]) <= self._tan_y * depth)
                )
            n = len(points)
            geomid = np.full(n, -1, np.int32)
            dist = np.zeros(n)
            mujoco.mj_multiRay(
                m, d, cam, vec.ravel().copy(), VISIBLE_GROUPS, 1, self._camera_body, geomid, dist, None, n, np.inf
            )
            self._look_past_head(d, cam, vec, geomid, dist)
            if own:
                seen = np.isin(geomid, list(own))
            else:  # a point: seen when nothing is hit before it (1 cm tolerance)
                length = np.linalg.norm(vec, axis=1)
                seen = (geomid < 0) | (dist * length >= length - 0.01)
            seen &= in_view
            blockers: dict[str, int] = {}
            for g, s, v in zip(geomid, seen, in_view):
                if v and not s and g >= 0:
                    name = self._geom_name(int(g))
                    blockers[name] = blockers.get(name, 0) + 1
            fraction = float(seen.sum()) / n
            return Visibility(
                fraction,
                fraction >= threshold,
                float(in_view.sum()) / n,
                tuple(sorted(blockers, key=lambda k: -blockers[k])),
            )
