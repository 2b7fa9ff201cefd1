"""Inverse kinematics of one arm with `mink` (differential IK as a QP, solved by `daqp`).

Where this lives, and why: mink works on a MuJoCo model and data, and the MuJoCo model is the
simulator backend's. The reasoning layer never imports a backend (import-linter contract) and
would otherwise have to be handed the backend's model, so the solver sits here, behind
:meth:`pycram.world.prospection.Prospection.solve_ik` (`SimProspection.solve_ik`); reasoning and
actions ask prospection, and a ROS backend answers the same question its own way.

Each iteration solves for a joint step that moves the tool site towards the target (mink's
`FrameTask`), within the joint limits (`ConfigurationLimit`), with every joint but the arm's held
fixed (`DofFreezingTask` as equality constraints), and optionally keeping the arm
:data:`COLLISION_DISTANCE` away from obstacles (`CollisionAvoidanceLimit`; obstacles within
:data:`COLLISION_DETECTION` are considered). The benchmark ``benchmarks/motion_planning.py``
compares it with the damped-least-squares solver of :mod:`pycram.backends.sim.ik` on the same
random reachable targets.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import mink
import mujoco
import numpy as np

from .arm_checker import ArmBodies
from .robot_model import tool_site

__all__ = ["MinkArmIK", "COLLISION_DISTANCE", "COLLISION_DETECTION", "DAMPING", "SOLVER"]

#: The QP solver mink uses (`daqp`: a dual active-set solver, a small wheel with no dependencies).
SOLVER = "daqp"
#: Levenberg-Marquardt damping of the tool-frame task (keeps steps bounded near singularities).
DAMPING = 1e-3
#: With collision avoidance: the least distance [m] kept between the arm and obstacles.
COLLISION_DISTANCE = 0.005
#: With collision avoidance: obstacles closer than this [m] to the arm constrain a step.
COLLISION_DETECTION = 0.05


class MinkArmIK:
    """mink IK for one arm of one model; holds its own `mink.Configuration` (MuJoCo data), so one
    instance serves one thread at a time (`SimProspection` keeps a pool)."""

    def __init__(self, model: mujoco.MjModel, arm: str, parts: ArmBodies, arm_joints: Sequence[int]) -> None:
        self.model = model
        self.configuration = mink.Configuration(model)
        self.site = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, tool_site(arm))
        self.qadr = np.array([model.jnt_qposadr[j] for j in arm_joints])
        dofs = {int(model.jnt_dofadr[j]) for j in arm_joints}
        self.task = mink.FrameTask(tool_site(arm), "site", position_cost=1.0, orientation_cost=1.0, lm_damping=DAMPING)
        self.freeze = mink.DofFreezingTask(model, dof_indices=[i for i in range(model.nv) if i not in dofs])
        self.joint_limit = mink.ConfigurationLimit(model)
        self.collision_limit = mink.CollisionAvoidanceLimit(
            model,
            geom_pairs=[(np.nonzero(parts.arm)[0].tolist(), np.nonzero(parts.obstacles)[0].tolist())],
            minimum_distance_from_collisions=COLLISION_DISTANCE,
            collision_detection_distance=COLLISION_DETECTION,
        )
        limited = [
            j for j in range(model.njnt) if model.jnt_limited[j] and model.jnt_type[j] != mujoco.mjtJoint.mjJNT_FREE
        ]
        self._limited_qadr = np.array([model.jnt_qposadr[j] for j in limited], int)
        self._limited_range = model.jnt_range[limited].copy() if limited else np.zeros((0, 2))
        self._quat, self._neg, self._dq, self._err = np.zeros(4), np.zeros(4), np.zeros(4), np.zeros(3)

    def errors(self, target_p: np.ndarray, target_q: np.ndarray | None) -> tuple[float, float]:
        """Position [m] and orientation [rad] errors of the tool site in the current configuration."""
        d = self.configuration.data
        pe = float(np.linalg.norm(target_p - d.site_xpos[self.site]))
        if target_q is None:
            return pe, 0.0
        mujoco.mju_mat2Quat(self._quat, d.site_xmat[self.site])
        mujoco.mju_negQuat(self._neg, self._quat)
        mujoco.mju_mulQuat(self._dq, target_q, self._neg)
        mujoco.mju_quat2Vel(self._err, self._dq, 1.0)
        return pe, float(np.linalg.norm(self._err))

    def solve(
        self,
        qpos: np.ndarray,
        target_p: np.ndarray,
        target_q: np.ndarray | None,
        seed: np.ndarray,
        iterations: int,
        position_tolerance: float,
        orientation_tolerance: float,
        avoid_collisions: bool,
    ) -> tuple[np.ndarray, float, float, int, bool]:
        """From ``qpos`` (the whole state) with the arm at ``seed`` (clipped into its limits), iterate
        towards the target. Returns (arm positions, position error [m], orientation error [rad],
        iterations, converged). Stops early when the error stops shrinking."""
        q = qpos.copy()
        if len(self._limited_qadr):  # the simulated state may sit a hair outside soft limits
            q[self._limited_qadr] = np.clip(q[self._limited_qadr], self._limited_range[:, 0], self._limited_range[:, 1])
        lo, hi = self.joint_limit.lower[self.qadr], self.joint_limit.upper[self.qadr]
        q[self.qadr] = np.clip(seed, lo, hi)
        conf = self.configuration
        conf.update(q)
        rotation = (
            mink.SO3(target_q)
            if target_q is not None
            else mink.SO3.from_matrix(conf.data.site_xmat[self.site].reshape(3, 3))
        )
        self.task.set_orientation_cost(1.0 if target_q is not None else 0.0)
        self.task.set_target(mink.SE3.from_rotation_and_translation(rotation, target_p))
        limits: list[mink.Limit] = [self.joint_limit]
        if avoid_collisions:
            limits.append(self.collision_limit)
        best = math.inf
        stall = 0
        pe = re = math.inf
        for it in range(iterations):
            pe, re = self.errors(target_p, target_q)
            if pe < position_tolerance and re < orientation_tolerance:
                return conf.data.qpos[self.qadr].copy(), pe, re, it, True
            err = pe + 0.1 * re
            if err < 0.99 * best:
                best, stall = err, 0
            else:
                stall += 1
                if stall >= 10:
                    return conf.data.qpos[self.qadr].copy(), pe, re, it, False
            try:
                v = mink.solve_ik(conf, [self.task], 1.0, SOLVER, limits=limits, constraints=[self.freeze])
            except mink.NoSolutionFound:
                return conf.data.qpos[self.qadr].copy(), pe, re, it, False
            conf.integrate_inplace(v, 1.0)
        pe, re = self.errors(target_p, target_q)
        ok = pe < position_tolerance and re < orientation_tolerance
        return conf.data.qpos[self.qadr].copy(), pe, re, iterations, ok
