"""How fast arm motions are planned in the apartment: p50/p95 plan time, success, checks per plan;
and IK with mink against the damped-least-squares solver.

Issue 32 targets on this 2-core machine: one arm motion plan p50 <= 30 ms, p95 <= 200 ms (PR2 and
TIAGo, apartment, 200 queries). Per robot, the queries are spread over standing poses in front of
the kitchen counter, the drawer cabinet's top and the dining table (where the set-table scenario
stands), with breakfast objects on the surface in front. Start and goal are random arm
configurations, collision-free, with the tool over the surface in front of the robot
(0.25-0.85 m ahead, 0.02-0.45 m above the surface): reaching between objects, over and around
them, near the furniture. Each plan uses `OMPLPlanner` (straight line first, else RRT-Connect,
OMPL's simplifier and string pulling, a budget of 30000 checks) through prospection's
configuration checker; every planned path is re-checked densely (1/4 of the planning resolution)
to count paths that cut an obstacle between checks. The searched paths' quality: vertices (the
arm stops at each), joint-space length [rad] and duration [s] timed at the arm module's half
speed. ``--slowest`` lists the slowest 10 % of the plans (where, checks, plan time per check,
joint-space distance from start to goal).

IK: targets are the tool poses (position and orientation) of random collision-free configurations
(the same sampler), so each is reachable; mink (`SimProspection.solve_ik`, without and with
collision avoidance) and the DLS solver (`pycram.backends.sim.ik.dls_ik`, the solver of
`reachable` and `Reach`) get the same seeds (current, named, random) and tolerances (1 mm,
0.01 rad).

The simulator is not run: prospection answers on a frozen state (the robot standing, the objects
resting), as a plan's questions do between two simulation steps.

    MUJOCO_GL=egl .venv/bin/python benchmarks/motion_planning.py [--robots pr2 tiago]
        [--queries 200] [--ik-targets 100] [--seed 0] [--slowest]

Measured 2026-11-27 18:27-18:29 UTC on this 2-core machine (``--ik-targets 0``, 200 queries per
robot), the planner before and after that day's changes run alternately, twice each (load average
3.3-4.3: another engineer's simulations ran; a check took 25 us as when idle; the last idle
measurement before the changes: PR2 p50 16.1 / p95 249 ms, TIAGo 8.1 / 87 ms):

- PR2: p50 16.9 / 15.9 -> 12.2 / 12.1 ms, p95 271 / 251 -> 134 / 133 ms; checks per plan
  2115 -> 1194 (p95 of the checks 8187 -> 4492); success 200/200 -> 200/200;
- TIAGo: p50 8.3 / 8.8 -> 6.6 / 6.6 ms, p95 86 / 90 -> 67 / 67 ms; checks per plan 943 -> 703;
  success 200/200 -> 200/200;
- the searched paths: PR2 9.5 -> 4.5 vertices, 6.67 -> 6.37 rad, 11.4 -> 6.7 s at half speed;
  TIAGo 7.7 -> 4.0 vertices, 5.31 -> 5.51 rad, 8.8 -> 6.2 s;
- dense re-check failures: PR2 3 -> 2, TIAGo 0 -> 1 (all grazing: at most 0.2 mm deep).

Under heavier contention the same day (17:56-18:16, load 2.6-4.7, a check taking 25-61 us) the
PR2's p95 was 322-362 ms before and 197-232 ms after, the TIAGo's 111-127 ms and 77-93 ms.

Again at 20:14-20:15 (load average 0.9-2.6), after the robot's own parts were let overlap by
15 mm (`pycram.backends.sim.arm_checker`: the sampled queries change a little), two runs with the
planner of before between them: PR2 p50 12.8 / 14.0 ms, p95 133 / 134 ms, 1217 checks per plan;
TIAGo p50 7.2 / 7.4 ms, p95 67 / 69 ms, 697 checks; before: PR2 16.2 / 266 ms, TIAGo 8.9 / 89 ms;
dense re-check failures PR2 5 (at most 0.1 mm beyond the threshold), TIAGo 0.
"""

from __future__ import annotations

import argparse
import math
import statistics
import sys
import time

import _worlds  # noqa: F401 - puts the repository on the path, MUJOCO_GL
import numpy as np

#: Standing poses per robot: (name, base (x, y, yaw), surface height [m]). The robot's front faces
#: the surface's edge from 0.05 m (PR2: its square base's front is 0.335 m ahead of its centre;
#: TIAGo: its round base's radius is 0.27 m).
STANDS = {
    "pr2": [
        ("counter west", (0.9, 4.0, math.pi / 2), 0.9),
        ("counter east", (1.9, 4.0, math.pi / 2), 0.9),
        ("cabinet top", (1.0, 2.9, math.pi), 0.9),
        ("table south", (4.3, 1.15, math.pi / 2), 0.75),
        ("table north", (4.0, 2.85, -math.pi / 2), 0.75),
    ],
    "tiago": [
        ("counter west", (0.9, 4.08, math.pi / 2), 0.9),
        ("counter east", (1.9, 4.08, math.pi / 2), 0.9),
        ("cabinet top", (0.92, 2.9, math.pi), 0.9),
        ("table south", (4.3, 1.23, math.pi / 2), 0.75),
        ("table north", (4.0, 2.77, -math.pi / 2), 0.75),
    ],
}
#: Objects on the surfaces: (type, x, y) [m].
OBJECTS = [
    ("cup", 0.75, 4.52),
    ("milk", 1.05, 4.55),
    ("bowl", 1.8, 4.55),
    ("cereal", 2.05, 4.6),
    ("cup", 0.4, 2.8),
    ("milk", 0.45, 3.05),
    ("bowl", 4.1, 1.75),
    ("cup", 4.45, 1.7),
    ("milk", 3.9, 2.25),
]


def build(robot: str):
    from pycram.backends.sim.items import ItemSpec
    from pycram.backends.sim.prospection import SimProspection
    from pycram.backends.sim.recording import StateSnapshot
    from pycram.backends.sim.scene import build_scene, initial_state
    from pycram.world.objects import object_type

    items = [ItemSpec.of(object_type(t), f"{t}-{i}", (x, y, None)) for i, (t, x, y) in enumerate(OBJECTS)]
    scene = build_scene(robot, items=items, environment="apartment")
    data = initial_state(scene, STANDS[robot][0][1])
    snapshot = StateSnapshot.of(data)
    return scene, SimProspection(scene, lambda: snapshot), data


def tool_in_box(scene, data, arm, base, surface, q, qadr, site) -> bool:
    """Whether the tool at arm configuration q lies over the surface in front of the base."""
    import mujoco

    data.qpos[qadr] = q
    mujoco.mj_kinematics(scene.model, data)
    p = data.site_xpos[site]
    dx, dy = p[0] - base[0], p[1] - base[1]
    ahead = dx * math.cos(base[2]) + dy * math.sin(base[2])
    side = -dx * math.sin(base[2]) + dy * math.cos(base[2])
    return 0.25 <= ahead <= 0.85 and abs(side) <= 0.45 and surface + 0.02 <= p[2] <= surface + 0.45


def sample_configurations(scene, prospection, data, arm, base, surface, count, rng) -> list[np.ndarray]:
    """`count` collision-free configurations of `arm` with the tool over the surface in front."""
    from pycram.backends.sim.robot_model import BASE_JOINTS, tool_site

    limits = prospection.arm_joint_limits(arm)
    lo = np.where(np.isinf(limits.lower), -math.pi, limits.lower)
    hi = np.where(np.isinf(limits.upper), math.pi, limits.upper)
    qadr = np.array([scene.joint_qpos(j) for j in limits.joints])
    site = scene.site(tool_site(arm))
    for joint, v in zip(BASE_JOINTS, base):
        data.qpos[scene.joint_qpos(joint)] = v
    out: list[np.ndarray] = []
    with prospection.configuration_checker(arm, base) as checker:
        for _ in range(200000):
            q = rng.uniform(lo, hi)
            if tool_in_box(scene, data, arm, base, surface, q, qadr, site) and checker.is_free(q):
                out.append(q)
                if len(out) >= count:
                    break
    return out


def dense_free(checker, path, step) -> bool:
    for a, b in zip(path, path[1:]):
        a, b = np.asarray(a), np.asarray(b)
        n = max(1, math.ceil(float(np.linalg.norm(b - a)) / step))
        if not all(checker.is_free(a + (i / n) * (b - a)) for i in range(n + 1)):
            return False
    return True


def percentile(values, p):
    return float(np.percentile(values, p)) if values else float("nan")


def bench_planning(robot, scene, prospection, data, queries, seed) -> dict:
    from pycram.reasoning.motion import OMPLPlanner, time_parameterize

    planner = OMPLPlanner()
    arm = scene.description.DEFAULT_ARM
    stands = STANDS[robot]
    rng = np.random.default_rng(seed)
    times, checks, kinds, reasons, dense_bad = [], [], {}, {}, 0
    searched = []  # (vertices, length [rad], duration [s]) of the paths RRT-Connect found
    slow = []  # (ms, stand, checks, us per check, distance [rad])
    per_stand = [queries // len(stands) + (1 if i < queries % len(stands) else 0) for i in range(len(stands))]
    check_time = []
    for (name, base, surface), n in zip(stands, per_stand):
        if n == 0:
            continue
        configs = sample_configurations(scene, prospection, data, arm, base, surface, 2 * n, rng)
        if len(configs) < 2 * n:
            print(f"  {robot} {name}: only {len(configs)} free configurations sampled", file=sys.stderr)
        limits = prospection.arm_joint_limits(arm)
        with prospection.configuration_checker(arm, base) as checker:
            t0 = time.perf_counter()
            k0 = checker.checks
            for q in configs[:200]:
                checker.is_free(q)
            check_time.append((time.perf_counter() - t0) / max(1, checker.checks - k0))
            for i in range(min(n, len(configs) // 2)):
                start, goal = configs[2 * i], configs[2 * i + 1]
                t0 = time.perf_counter()
                plan = planner.plan_with(checker, limits, start, goal, seed=seed + i)
                times.append((time.perf_counter() - t0) * 1e3)
                checks.append(plan.checks)
                slow.append(
                    (
                        times[-1],
                        name,
                        plan.checks,
                        times[-1] * 1e3 / max(1, plan.checks),
                        float(np.linalg.norm(np.subtract(goal, start))),
                    )
                )
                if plan:
                    kinds[plan.planner] = kinds.get(plan.planner, 0) + 1
                    if plan.planner != "straight_line":
                        timed = time_parameterize(plan.path, limits, period=0.02, velocity_scale=0.5)
                        searched.append((len(plan.path), plan.length, timed.duration))
                    if not dense_free(checker, plan.path, planner.resolution / 4):
                        dense_bad += 1
                else:
                    reasons[plan.reason] = reasons.get(plan.reason, 0) + 1
    ok = sum(kinds.values())
    return {
        "n": len(times),
        "ok": ok,
        "p50": percentile(times, 50),
        "p95": percentile(times, 95),
        "max": max(times) if times else float("nan"),
        "checks": statistics.mean(checks) if checks else float("nan"),
        "kinds": kinds,
        "reasons": reasons,
        "dense_bad": dense_bad,
        "check_us": statistics.mean(check_time) * 1e6 if check_time else float("nan"),
        "searched": searched,
        "slowest": sorted(slow, reverse=True)[: max(1, len(slow) // 10)],
    }


def bench_ik(robot, scene, prospection, data, targets, seed) -> dict:
    import mujoco

    from pycram.backends.sim.ik import dls_ik
    from pycram.backends.sim.robot_model import BASE_JOINTS, NOT_IK_SEEDS, tool_site

    arm = scene.description.DEFAULT_ARM
    rng = np.random.default_rng(seed + 1)
    site = scene.site(tool_site(arm))
    m = scene.model
    desc = scene.description
    jids = [scene.joint_id(j) for j in desc.ARMS[arm]["joints"]]
    qadr = m.jnt_qposadr[jids]
    dadr = m.jnt_dofadr[jids]
    limited = m.jnt_limited[jids].astype(bool)
    lo = np.where(limited, m.jnt_range[jids, 0], -np.inf)
    hi = np.where(limited, m.jnt_range[jids, 1], np.inf)
    stands = STANDS[robot]
    cases = []
    for i in range(targets):
        _, base, surface = stands[i % len(stands)]
        q = sample_configurations(scene, prospection, data, arm, base, surface, 1, rng)[0]
        data.qpos[qadr] = q
        mujoco.mj_kinematics(m, data)
        quat = np.zeros(4)
        mujoco.mju_mat2Quat(quat, data.site_xmat[site])
        cases.append((base, data.site_xpos[site].copy(), quat))
    out = {}
    for label, avoid in (("mink", False), ("mink+collision", True)):
        ok = free = 0
        t0 = time.perf_counter()
        for base, p, quat in cases:
            r = prospection.solve_ik(arm, (tuple(p), tuple(quat)), base, avoid_collisions=avoid)
            if r:
                ok += 1
                free += prospection.arm_configuration_free(arm, r.positions, base)
        out[label] = (ok, free, (time.perf_counter() - t0) / len(cases) * 1e3)
    # DLS with the seeds of solve_ik: current, named configurations, 4 random ones
    scratch = mujoco.MjData(m)
    named = [np.asarray(c, float) for n, c in desc.ARM_CONFIGURATIONS[arm].items() if n not in NOT_IK_SEEDS]
    seed_rng = np.random.default_rng(0)
    randoms = [seed_rng.uniform(np.where(limited, lo, -np.pi), np.where(limited, hi, np.pi)) for _ in range(4)]
    ok = free = 0
    t0 = time.perf_counter()
    for base, p, quat in cases:
        scratch.qpos[:] = data.qpos
        for joint, v in zip(BASE_JOINTS, base):
            scratch.qpos[scene.joint_qpos(joint)] = v
        current = np.array([desc.INITIAL_CONFIGURATION[j] for j in desc.ARMS[arm]["joints"]])
        for s in [current, *named, *randoms]:
            sol, converged = dls_ik(
                m,
                scratch,
                site,
                qadr,
                dadr,
                lo,
                hi,
                p,
                quat,
                s,
                100,
                position_tolerance=1e-3,
                orientation_tolerance=1e-2,
            )
            if converged:
                ok += 1
                free += prospection.arm_configuration_free(arm, sol.positions, base)
                break
    out["dls"] = (ok, free, (time.perf_counter() - t0) / len(cases) * 1e3)
    return out


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--robots", nargs="+", default=["pr2", "tiago"])
    parser.add_argument("--queries", type=int, default=200, help="plans per robot")
    parser.add_argument("--ik-targets", type=int, default=100, help="IK targets per robot")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--slowest", action="store_true", help="list the slowest 10 %% of the plans")
    args = parser.parse_args()
    for robot in args.robots:
        scene, prospection, data = build(robot)
        t0 = time.perf_counter()
        r = bench_planning(robot, scene, prospection, data, args.queries, args.seed)
        spent = time.perf_counter() - t0
        kinds = ", ".join(f"{k} {v}" for k, v in sorted(r["kinds"].items()))
        reasons = ", ".join(f"{k} {v}" for k, v in sorted(r["reasons"].items())) or "none"
        print(
            f"{robot}: planning: p50 {r['p50']:.1f} ms, p95 {r['p95']:.1f} ms, max {r['max']:.0f} ms "
            f"over {r['n']} plans; "
            f"success {r['ok']}/{r['n']} ({kinds}; failures: {reasons}); "
            f"{r['checks']:.0f} checks per plan, {r['check_us']:.0f} us per check; "
            f"dense re-check failures {r['dense_bad']} ({spent:.0f} s)"
        )
        if r["searched"]:
            vertices, length, duration = (statistics.mean(v) for v in zip(*r["searched"]))
            print(
                f"{robot}: searched paths: {vertices:.1f} vertices, {length:.2f} rad long, "
                f"{duration:.2f} s at half speed (means over {len(r['searched'])})"
            )
        if args.slowest:
            for ms, stand, n, us, distance in r["slowest"]:
                print(f"  {ms:7.1f} ms  {stand:13s} {n:6d} checks  {us:5.1f} us/check  {distance:.2f} rad apart")
        if args.ik_targets:
            ik = bench_ik(robot, scene, prospection, data, args.ik_targets, args.seed)
            for label, (ok, free, ms) in ik.items():
                print(
                    f"{robot}: IK {label}: solved {ok}/{args.ik_targets}, collision-free {free}/{args.ik_targets}, "
                    f"{ms:.1f} ms per target"
                )
    return 0


if __name__ == "__main__":
    sys.exit(main())
