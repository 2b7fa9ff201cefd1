"""Inverse kinematics: damped least squares on `mj_jacSite`, respecting joint limits."""

from __future__ import annotations

import logging
from dataclasses import dataclass
from typing import Sequence

import mujoco
import numpy as np

from .engine import Engine
from .types import Pose

_log = logging.getLogger(__name__)


@dataclass(frozen=True)
class IKSolution:
    """Joint positions of an arm and the remaining errors: position [m], orientation [rad]."""

    positions: tuple[float, ...]
    position_error: float
    orientation_error: float


def solve_ik(eng: Engine, arm: str, goal: Pose, use_orientation: bool = True,
             seeds: Sequence[Sequence[float]] = (), position_tolerance: float = 0.002,
             orientation_tolerance: float = 0.02, iterations: int = 400, damping: float = 0.02,
             rng_seed: int = 0) -> IKSolution | None:
    """Arm joint positions that put the tool site of `arm` at `goal` (map frame), or None.

    Uses a scratch copy of the current state (the base and torso stay where they are). Tries the
    current arm configuration, the given `seeds`, the named configurations and a few random
    ones; the first solution within the tolerances is returned.
    """
    m = eng.model
    scratch = mujoco.MjData(m)
    scratch.qpos[:] = eng.data.qpos
    joints = eng.desc.ARMS[arm]["joints"]
    jids = [eng.scene.joint_id(j) for j in joints]
    qadr = np.array([m.jnt_qposadr[j] for j in jids])
    dadr = np.array([m.jnt_dofadr[j] for j in jids])
    limited = np.array([bool(m.jnt_limited[j]) for j in jids])
    lo = np.where(limited, m.jnt_range[jids, 0], -np.inf)
    hi = np.where(limited, m.jnt_range[jids, 1], np.inf)
    site = eng.tool_sites[arm]
    target_p = np.asarray(goal.position, float)
    target_q = np.asarray(goal.orientation, float)
    target_q = target_q / np.linalg.norm(target_q)
    jacp, jacr = np.zeros((3, m.nv)), np.zeros((3, m.nv))
    rng = np.random.default_rng(rng_seed)
    candidates = [eng.data.qpos[qadr].copy()] + [np.asarray(s, float) for s in seeds]
    candidates += [np.asarray(c, float) for c in eng.desc.ARM_CONFIGURATIONS[arm].values()]
    for _ in range(6):
        r = rng.uniform(np.where(limited, lo, -np.pi), np.where(limited, hi, np.pi))
        candidates.append(r)
    site_quat, neg, dq_rot = np.zeros(4), np.zeros(4), np.zeros(4)
    best: IKSolution | None = None
    for seed in candidates:
        q = np.clip(seed, lo, hi)
        for _ in range(iterations):
            scratch.qpos[qadr] = q
            mujoco.mj_kinematics(m, scratch)
            mujoco.mj_comPos(m, scratch)
            e_p = target_p - scratch.site_xpos[site]
            mujoco.mju_mat2Quat(site_quat, scratch.site_xmat[site])
            mujoco.mju_negQuat(neg, site_quat)
            mujoco.mju_mulQuat(dq_rot, target_q, neg)
            e_r = np.zeros(3)
            mujoco.mju_quat2Vel(e_r, dq_rot, 1.0)
            pe, re = float(np.linalg.norm(e_p)), float(np.linalg.norm(e_r))
            if pe < position_tolerance and (not use_orientation or re < orientation_tolerance):
                sol = IKSolution(tuple(map(float, q)), pe, re)
                return sol
            mujoco.mj_jacSite(m, scratch, jacp, jacr, site)
            if use_orientation:
                J = np.vstack([jacp[:, dadr], 0.5 * jacr[:, dadr]])
                e = np.concatenate([e_p, 0.5 * e_r])
            else:
                J, e = jacp[:, dadr], e_p
            dq = J.T @ np.linalg.solve(J @ J.T + damping ** 2 * np.eye(len(e)), e)
            step = np.max(np.abs(dq))
            if step > 0.3:
                dq *= 0.3 / step
            q = np.clip(q + dq, lo, hi)
        if best is None or pe < best.position_error:
            best = IKSolution(tuple(map(float, q)), pe, re)
    _log.debug("IK for %s failed; best errors %.3f m / %.3f rad", arm, best.position_error if best else -1,
               best.orientation_error if best else -1)
    return None
