"""Inverse kinematics: damped least squares on `mj_jacSite`, respecting joint limits."""

from __future__ import annotations

import logging
import math
from collections.abc import Sequence
from dataclasses import dataclass

import mujoco
import numpy as np

from pycram.world.types import Pose

from .engine import Engine
from .robot_model import NOT_IK_SEEDS

_log = logging.getLogger(__name__)


@dataclass(frozen=True)
class IKSolution:
    """Joint positions of an arm and the remaining errors: position [m], orientation [rad]."""

    positions: tuple[float, ...]
    position_error: float
    orientation_error: float


def solve_ik(
    eng: Engine,
    arm: str,
    goal: Pose,
    use_orientation: bool = True,
    seeds: Sequence[Sequence[float]] = (),
    position_tolerance: float = 0.002,
    orientation_tolerance: float = 0.02,
    iterations: int = 400,
    damping: float = 0.02,
    rng_seed: int = 0,
) -> IKSolution | None:
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
    rng = np.random.default_rng(rng_seed)
    candidates = [eng.data.qpos[qadr].copy()] + [np.asarray(s, float) for s in seeds]
    candidates += [np.asarray(c, float) for n, c in eng.desc.ARM_CONFIGURATIONS[arm].items() if n not in NOT_IK_SEEDS]
    for _ in range(6):
        r = rng.uniform(np.where(limited, lo, -np.pi), np.where(limited, hi, np.pi))
        candidates.append(r)
    best: IKSolution | None = None
    for seed in candidates:
        sol, converged = dls_ik(
            m,
            scratch,
            site,
            qadr,
            dadr,
            lo,
            hi,
            target_p,
            target_q if use_orientation else None,
            seed,
            iterations,
            damping,
            position_tolerance,
            orientation_tolerance,
        )
        if converged:
            return sol
        if best is None or sol.position_error < best.position_error:
            best = sol
    _log.debug(
        "IK for %s failed; best errors %.3f m / %.3f rad",
        arm,
        best.position_error if best else -1,
        best.orientation_error if best else -1,
    )
    return None


def dls_ik(
    model: mujoco.MjModel,
    data: mujoco.MjData,
    site: int,
    qadr: np.ndarray,
    dadr: np.ndarray,
    lo: np.ndarray,
    hi: np.ndarray,
    target_p: np.ndarray,
    target_q: np.ndarray | None,
    seed: Sequence[float] | np.ndarray,
    iterations: int = 400,
    damping: float = 0.02,
    position_tolerance: float = 0.002,
    orientation_tolerance: float = 0.02,
    stall_window: int = 0,
) -> tuple[IKSolution, bool]:
    """Damped least squares from `seed` for the joints at qpos `qadr` / dofs `dadr`, clipped to
    [`lo`, `hi`], moving `site` to `target_p` [m] (and `target_q` (w, x, y, z) unless None).

    Works on `data` (a scratch `MjData` whose other joints are set by the caller; its arm joints
    are left at the result). Returns the last iterate and whether it is within the tolerances.
    With `stall_window` > 0, gives up when the error has not shrunk by 1 % over that many
    iterations. Thread-safe as long as `data` belongs to the caller.
    """
    jacp, jacr = np.zeros((3, model.nv)), np.zeros((3, model.nv))
    site_quat, neg, dq_rot, e_r = np.zeros(4), np.zeros(4), np.zeros(4), np.zeros(3)
    rows = 6 if target_q is not None else 3
    J = np.zeros((rows, len(dadr)))
    e = np.zeros(rows)
    damp = np.eye(rows) * damping**2
    q = np.clip(np.asarray(seed, float), lo, hi)
    pe = re = float("inf")
    history: list[float] = []
    for it in range(iterations):
        data.qpos[qadr] = q
        mujoco.mj_kinematics(model, data)
        np.subtract(target_p, data.site_xpos[site], out=e[:3])
        pe = math.sqrt(float(e[:3] @ e[:3]))
        if target_q is not None:
            mujoco.mju_mat2Quat(site_quat, data.site_xmat[site])
            mujoco.mju_negQuat(neg, site_quat)
            mujoco.mju_mulQuat(dq_rot, target_q, neg)
            mujoco.mju_quat2Vel(e_r, dq_rot, 1.0)
            re = math.sqrt(float(e_r @ e_r))
            e[3:] = 0.5 * e_r
        else:
            re = 0.0
        if pe < position_tolerance and re < orientation_tolerance:
            return IKSolution(tuple(map(float, q)), pe, re), True
        if stall_window:
            err = pe + 0.1 * re
            history.append(err)
            if it >= stall_window and err > 0.99 * history[it - stall_window]:
                break
        mujoco.mj_comPos(model, data)
        mujoco.mj_jacSite(model, data, jacp, jacr if target_q is not None else None, site)
        J[:3] = jacp[:, dadr]
        if target_q is not None:
            J[3:] = 0.5 * jacr[:, dadr]
        dq = J.T @ np.linalg.solve(J @ J.T + damp, e)
        step = float(np.abs(dq).max())
        if step > 0.3:
            dq *= 0.3 / step
        q = np.clip(q + dq, lo, hi)
    return IKSolution(tuple(map(float, q)), pe, re), False
