"""How often `Transport` succeeds, and how long it takes: per object type and robot, random scenes.

Issue 16 asks for the success rate and the simulated and wall time of ``transporting`` for each
object type and robot over >= 20 random apartment scenes each. Each scene: the object (and two
other objects in the way) starts at a random spot of an open surface (counter, cabinet top,
table, cookers; drawers and the fridge are left out: out of drawers only cups, mugs and bowls
are picked, see docs/actions.md, and tests/sim/test_actions_drawers.py covers them),
the robot starts at the apartment's start pose knowing nothing, and is asked to
``Transport(ObjectDesignator(type=T), "table")`` -- or to the counter for an object that starts
on the table. Success is judged with the simulator's truth: the object stands upright (< 20 deg)
on the target surface. Failures are counted by their typed failure and reason.

    MUJOCO_GL=egl .venv/bin/python benchmarks/actions.py [--scenes 20] [--robots pr2,tiago]
        [--types cup,mug,milk,cereal,bowl,plate,spoon]

The last line reads ``transporting: S/N succeeded (P %), sim p50 X s, wall p50 Y s``.
"""

from __future__ import annotations

import argparse
import logging
import math
import os
import sys
import time
from collections import Counter, defaultdict
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
os.environ.setdefault("MUJOCO_GL", "egl")

import numpy as np  # noqa: E402

from pycram import robots  # noqa: E402
from pycram.actions import MoveTorso, ParkArms, Transport  # noqa: E402
from pycram.designator import ObjectDesignator, perform  # noqa: E402
from pycram.sim import World  # noqa: E402
from pycram.world.objects import OBJECT_TYPES, object_type  # noqa: E402

OPEN_SURFACES = ["counter", "cabinet top", "table", "cooker #1", "cooker #2"]
DISTRACTORS = {"cup": ["bowl", "milk"], "default": ["cup", "bowl"]}


def tilt(orientation) -> float:
    w, x, y, z = orientation
    return math.acos(max(-1.0, min(1.0, 1.0 - 2.0 * (x * x + y * y))))


def run_one(robot_name: str, type_name: str, seed: int) -> tuple[bool, str, float, float]:
    """(succeeded, failure cause or "", simulated s, wall s) of one transport."""
    others = [t for t in DISTRACTORS.get(type_name, DISTRACTORS["default"]) if t != type_name][:2]
    world = World(robot_name, environment="apartment", objects=[type_name, *others], seed=seed, supports=OPEN_SURFACES)
    start = world.placements[0]
    target = "counter" if start.support == "table" else "table"
    robot = robots.load(robot_name, world)
    t0, s0 = time.perf_counter(), world.sim_time.get_value()
    cause = ""
    try:
        with robot:
            perform(ParkArms())
            perform(MoveTorso("up"))
            perform(Transport(ObjectDesignator(type=type_name), target))
    except Exception as error:  # the benchmark counts every failure by its kind
        cause = f"{type(error).__name__}: {getattr(error, 'reason', '')}"
    finally:
        wall, sim = time.perf_counter() - t0, world.sim_time.get_value() - s0
        pose = world.item_poses.get_value()[start.name]
        surface = world.environment.surface(target)
        x, y, z = pose.position
        ok = (
            surface.contains(x, y, 0.0)
            and abs(z - object_type(type_name).half_height - surface.height) < 0.03
            and tilt(pose.orientation) < math.radians(20)
        )
        robot.shutdown()
        world.close()
    if not ok and not cause:
        cause = "wrong result: not upright on the target"
    return ok and not cause, cause, sim, wall


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--scenes", type=int, default=20)
    parser.add_argument("--robots", default="pr2,tiago")
    parser.add_argument("--types", default=",".join(OBJECT_TYPES))
    args = parser.parse_args()
    logging.basicConfig(level=logging.ERROR)
    rows = []
    causes: dict[str, Counter] = defaultdict(Counter)
    all_sim, all_wall, total, succeeded = [], [], 0, 0
    for robot_name in args.robots.split(","):
        for type_name in args.types.split(","):
            results = [run_one(robot_name, type_name, seed) for seed in range(args.scenes)]
            ok = [r for r in results if r[0]]
            sims = [r[2] for r in ok] or [float("nan")]
            walls = [r[3] for r in ok] or [float("nan")]
            for r in results:
                if not r[0]:
                    causes[f"{robot_name} {type_name}"][r[1]] += 1
            rows.append((robot_name, type_name, len(ok), len(results), np.median(sims), np.median(walls)))
            all_sim += [r[2] for r in ok]
            all_wall += [r[3] for r in ok]
            total += len(results)
            succeeded += len(ok)
            print(
                f"{robot_name:6s} {type_name:7s} {len(ok):3d}/{len(results)} succeeded  "
                f"sim p50 {np.median(sims):6.1f} s  wall p50 {np.median(walls):5.1f} s  "
                f"(x{np.median(sims) / np.median(walls):.1f} real time)",
                flush=True,
            )
    print("\nfailures by cause:")
    for key, counter in causes.items():
        print(f"  {key}: " + ", ".join(f"{cause} x{n}" for cause, n in counter.most_common()))
    sim50 = float(np.median(all_sim)) if all_sim else float("nan")
    wall50 = float(np.median(all_wall)) if all_wall else float("nan")
    print(
        f"transporting: {succeeded}/{total} succeeded ({100.0 * succeeded / max(total, 1):.0f} %), "
        f"sim p50 {sim50:.1f} s, wall p50 {wall50:.1f} s"
    )


if __name__ == "__main__":
    main()
