"""One call builds a scene: an environment, one robot and the items, compiled into a MuJoCo model.

`build_scene` is cheap (well under a second) and can be repeated in one process.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Sequence
from dataclasses import dataclass, field

import mujoco
import numpy as np

from pycram import environments
from pycram.world.environment import Environment
from pycram.world.robot_description import RobotDescription
from pycram.world.robot_registry import DEFAULT_ROBOT

from .environment_builder import add_environment
from .errors import UnknownNameError
from .items import DEFAULT_ITEMS, ItemSpec, add_item
from .robot_model import BASE_JOINTS, HEAD_CAMERA, add_robot, build_robot_spec, load_description, pad_site, tool_site

_log = logging.getLogger(__name__)

TIMESTEP = 0.002  # [s]


def weld_name(gripper: str, item: str) -> str:
    """Name of the (normally inactive) weld equality that holds `item` in `gripper`."""
    return f"grasp:{gripper}:{item}"


@dataclass
class Scene:
    """A compiled scene: the model, the robot's description and name/id lookups."""

    model: mujoco.MjModel
    description: RobotDescription
    items: tuple[ItemSpec, ...]
    environment: Environment
    robot_geoms: frozenset[int] = field(default_factory=frozenset)
    base_geoms: frozenset[int] = field(default_factory=frozenset)
    environment_geoms: frozenset[int] = field(default_factory=frozenset)
    #: Joint name -> id, filled as joints are looked up (controllers look up every tick).
    _joint_ids: dict[str, int] = field(default_factory=dict, repr=False, compare=False)

    @property
    def robot(self) -> str:
        """The robot's name (a registered robot, :mod:`pycram.world.robot_registry`)."""
        return self.description.NAME

    def joint_qpos(self, joint: str) -> int:
        """Index of `joint` in qpos."""
        return int(self.model.jnt_qposadr[self.joint_id(joint)])

    def joint_dof(self, joint: str) -> int:
        """Index of `joint` in qvel."""
        return int(self.model.jnt_dofadr[self.joint_id(joint)])

    def joint_id(self, joint: str) -> int:
        jid = self._joint_ids.get(joint)
        if jid is None:
            jid = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_JOINT, joint)
            if jid < 0:
                raise UnknownNameError("joint", joint, self.joint_names())
            self._joint_ids[joint] = jid
        return jid

    def joint_names(self) -> list[str]:
        return [self.model.joint(i).name for i in range(self.model.njnt)]

    def actuator(self, joint: str) -> int:
        """Index of the position servo driving `joint`."""
        aid = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_ACTUATOR, joint)
        if aid < 0:
            names = [self.model.actuator(i).name for i in range(self.model.nu)]
            raise UnknownNameError("actuated joint", joint, names)
        return aid

    def body(self, name: str) -> int:
        bid = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_BODY, name)
        if bid < 0:
            raise UnknownNameError("body", name, [self.model.body(i).name for i in range(self.model.nbody)])
        return bid

    def site(self, name: str) -> int:
        sid = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_SITE, name)
        if sid < 0:
            raise UnknownNameError("site", name, [self.model.site(i).name for i in range(self.model.nsite)])
        return sid

    def camera(self, name: str) -> int:
        cid = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_CAMERA, name)
        if cid < 0:
            raise UnknownNameError("camera", name, self.camera_names())
        return cid

    def camera_names(self) -> list[str]:
        return [self.model.camera(i).name for i in range(self.model.ncam)]

    def equality(self, name: str) -> int:
        eid = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_EQUALITY, name)
        if eid < 0:
            raise UnknownNameError("equality", name, [])
        return eid

    def item(self, name: str) -> ItemSpec:
        for it in self.items:
            if it.name == name:
                return it
        raise UnknownNameError("item", name, [it.name for it in self.items])


def _subtree_bodies(model: mujoco.MjModel, root: int) -> set[int]:
    out = {root}
    for b in range(model.nbody):
        p = b
        while p > 0:
            if p == root:
                out.add(b)
                break
            p = int(model.body_parentid[p])
    return out


def build_scene(
    robot: str = DEFAULT_ROBOT,
    items: Sequence[ItemSpec] | None = None,
    offscreen_size: tuple[int, int] = (640, 480),
    environment: str | Environment = environments.DEFAULT_ENVIRONMENT,
) -> Scene:
    """Compile `environment` (a name or a description) with `robot` (a registered robot) and
    `items` (default: `DEFAULT_ITEMS` in the thesis kitchen, none elsewhere).

    An item without a z stands on the highest open surface below it (the floor when there is
    none). Offscreen renders are limited to `offscreen_size` [px]. Raises `UnknownNameError`
    for an unknown robot or environment.
    """
    t0 = time.perf_counter()
    env = environments.load(environment)
    desc = load_description(robot)
    if items is None:  # the default items belong to the thesis kitchen
        items = DEFAULT_ITEMS if env.name == environments.DEFAULT_ENVIRONMENT else ()
    items = tuple(items)
    names = [it.name for it in items]
    if len(set(names)) != len(names):
        raise ValueError(f"item names must be unique: {names}")
    spec = build_robot_spec(desc)  # the robot's spec becomes the scene's (no attach, no renaming)
    spec.modelname = f"{env.name}_{robot}"
    spec.option.timestep = TIMESTEP
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    spec.option.cone = mujoco.mjtCone.mjCONE_ELLIPTIC
    spec.visual.quality.shadowsize = 0
    spec.visual.global_.offwidth = offscreen_size[0]
    spec.visual.global_.offheight = offscreen_size[1]
    spec.visual.headlight.ambient = [0.35, 0.35, 0.35]
    spec.visual.headlight.diffuse = [0.5, 0.5, 0.5]
    add_environment(spec, env)
    for it in items:
        add_item(spec, it, it.resting_position(env.support_height(it.position[0], it.position[1])))
    add_robot(spec, desc)
    for gname, g in desc.GRIPPERS.items():
        for it in items:
            eq = spec.add_equality(
                name=weld_name(gname, it.name),
                type=mujoco.mjtEq.mjEQ_WELD,
                objtype=mujoco.mjtObj.mjOBJ_BODY,
                name1=g["palm_link"],
                name2=it.name,
            )
            eq.active = False
            eq.solref = [0.01, 1.0]
    model = spec.compile()
    mount = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, desc.ROOT_LINK)
    robot_bodies = _subtree_bodies(model, mount)
    base_bodies = {mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, n) for n in desc.BASE["collision_links"]}
    geoms_of = lambda bodies: frozenset(  # noqa: E731
        g for g in range(model.ngeom) if model.geom_bodyid[g] in bodies and model.geom_contype[g]
    )
    env_geoms = frozenset(g for g in range(model.ngeom) if model.geom_contype[g] == 1)
    scene = Scene(
        model=model,
        description=desc,
        items=items,
        environment=env,
        robot_geoms=geoms_of(robot_bodies),
        base_geoms=geoms_of(base_bodies),
        environment_geoms=env_geoms,
    )
    _log.info(
        "scene %s built in %.3f s (nq=%d, ngeom=%d)", spec.modelname, time.perf_counter() - t0, model.nq, model.ngeom
    )
    return scene


def initial_state(scene: Scene, base: tuple[float, float, float]) -> mujoco.MjData:
    """Fresh data with the robot at `base` (x, y, yaw) and its initial configuration, servos holding it."""
    model = scene.model
    data = mujoco.MjData(model)
    desc = scene.description
    q = dict(zip(BASE_JOINTS, base))
    q.update(desc.INITIAL_CONFIGURATION)
    q[desc.TORSO["joint"]] = desc.TORSO["default"]
    for joint, value in q.items():
        data.qpos[scene.joint_qpos(joint)] = value
    gripper_joints = {g["joint"] for g in desc.GRIPPERS.values()}
    for e in range(model.neq):  # coupled gripper joints: half open
        if model.eq_type[e] == mujoco.mjtEq.mjEQ_JOINT:
            j2 = int(model.eq_obj2id[e])
            if j2 >= 0 and model.joint(j2).name in gripper_joints:
                q2 = 0.5 * float(model.jnt_range[j2, 1])
                data.qpos[model.jnt_qposadr[j2]] = q2
                data.qpos[model.jnt_qposadr[model.eq_obj1id[e]]] = model.eq_data[e, 0] + model.eq_data[e, 1] * q2
    for aid in range(model.nu):
        jid = int(model.actuator_trnid[aid, 0])
        data.ctrl[aid] = data.qpos[model.jnt_qposadr[jid]]
    mujoco.mj_forward(model, data)
    return data


__all__ = ["Scene", "build_scene", "initial_state", "weld_name", "HEAD_CAMERA", "tool_site", "pad_site", "np"]
