"""How fast location designators resolve: first and next solution, against the analytic generator.

Issue 14 asks for the first solution of ``('to_reach', object)`` for an object on a counter or
the table of the apartment, PR2 and TIAGo, 50 random scenes: p50 <= 0.2 s, p95 <= 0.5 s on this
2-core machine; the next solution <= 0.1 s p50. Beside it: the analytic generator (fixed
stand-offs in front of the counter edge, `make_to_reach_generator`) -- its time and how often none
of its poses works (checked with the same prospection questions as the reasoning: base and
raised arm collision-free, the IK sequence reachable). Then ``to_see`` the same object,
``to_open`` a container of the apartment and ``on`` its surface, in the same form.

    MUJOCO_GL=egl .venv/bin/python benchmarks/locations.py [--scenes 50] [--robots pr2,tiago]

The last line reads ``first solution: p50 X s, p95 Y s over N queries`` (to_reach, all robots).
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
os.environ.setdefault("MUJOCO_GL", "egl")

import numpy as np  # noqa: E402

from pycram import robots  # noqa: E402
from pycram.designator import LocationDesignator  # noqa: E402
from pycram.designators.core import DesignatorError  # noqa: E402
from pycram.environments import load  # noqa: E402
from pycram.locations import KnownObject, RobotGeometry, grasp_sequence  # noqa: E402
from pycram.robots.common.sim_resolvers import make_to_reach_generator  # noqa: E402
from pycram.sim import World  # noqa: E402
from pycram.world.scenes import random_scene  # noqa: E402

OBJECTS = ["cup", "milk", "cereal"]


def scenes(count: int) -> list[tuple[int, str]]:
    """(seed, object name) of the first `count` seeds with an object on a counter or the table."""
    env, out, seed = load("apartment"), [], 0
    while len(out) < count:
        placed = [p for p in random_scene(env, OBJECTS, seed) if p.support in ("counter", "table")]
        if placed:
            out.append((seed, placed[0].name))
        seed += 1
    return out


def timed(fn):
    t = time.perf_counter()
    try:
        value, error = fn(), None
    except DesignatorError as e:
        value, error = None, e
    return time.perf_counter() - t, value, error


def analytic_works(world, description, prospection, target, point) -> tuple[float, bool]:
    """Time of the analytic generator and whether one of its poses passes the reasoning's checks."""
    geometry = RobotGeometry.from_description(description)
    generator = make_to_reach_generator(world, description)
    t = time.perf_counter()
    try:
        poses = generator(LocationDesignator([("to_reach", point)]))
    except DesignatorError:
        return time.perf_counter() - t, False
    elapsed = time.perf_counter() - t
    arm = geometry.default_arm
    for pose in poses:
        if prospection.in_collision(pose, geometry.raised(arm)):
            continue
        sequence = grasp_sequence(geometry, point, pose.yaw, "side")
        if prospection.reachable(arm, sequence, pose, geometry.raised(arm)):
            return elapsed, True
    return elapsed, False


def _xyz(p) -> str:
    return "(" + ", ".join(f"{v:.2f}" for v in p) + ")"


def pct(values: list[float], q: float) -> float:
    return float(np.percentile(values, q)) if values else float("nan")


def line(name: str, times: list[float], failures: int, total: int) -> str:
    return f"  {name:<22} first p50 {pct(times, 50):.3f} s, p95 {pct(times, 95):.3f} s, failed {failures}/{total}"


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--scenes", type=int, default=50)
    parser.add_argument("--robots", default="pr2,tiago")
    parser.add_argument("--explain", action="store_true", help="print why each failed to_reach query failed")
    args = parser.parse_args()
    chosen = scenes(args.scenes)
    first_all: list[float] = []
    for robot_name in args.robots.split(","):
        stats: dict[str, list[float]] = {k: [] for k in ("to_reach", "next", "analytic", "to_see", "to_open", "on")}
        fails = dict.fromkeys(stats, 0)
        for seed, name in chosen:
            world = World(robot_name, environment="apartment", seed=seed, objects=OBJECTS)
            robot = robots.load(robot_name, world)
            try:
                with robot:
                    world.set_torso(robot.description.TORSO_POSITIONS["up"]).wait(30.0)
                    prospection = world.prospection()
                    pose = world.item_poses.get_value()[name]
                    target = KnownObject(name, world.scene.item(name).type, tuple(pose.position))
                    placement = next(p for p in world.placements if p.name == name)
                    designator = LocationDesignator([("to_reach", target)])
                    dt, first, error = timed(designator.reference)
                    stats["to_reach"].append(dt)
                    if error is not None:
                        fails["to_reach"] += 1
                        if args.explain:
                            print(f"  {robot_name} seed {seed}, {name} at {_xyz(pose.position)}: {error}")
                    else:
                        dt, nxt, error = timed(designator.next_solution)
                        stats["next"].append(dt)
                        fails["next"] += nxt is None
                    point = (pose.position[0], pose.position[1], pose.position[2])
                    dt, works = analytic_works(world, robot.description, prospection, target, point)
                    stats["analytic"].append(dt)
                    fails["analytic"] += not works
                    for kind, props in (
                        ("to_see", [("to_see", target)]),
                        ("to_open", [("to_open", world.environment.containers[seed % 4].name)]),
                        ("on", [("on", placement.support), ("for", "cup")]),
                    ):
                        dt, _, error = timed(LocationDesignator(props).reference)
                        stats[kind].append(dt)
                        fails[kind] += error is not None
            finally:
                robot.shutdown()
                world.close()
        n = len(chosen)
        print(f"{robot_name}: {n} scenes of the apartment, an object on a counter or the table")
        print(line("to_reach (reasoning)", stats["to_reach"], fails["to_reach"], n))
        print(
            f"  {'to_reach next':<22} p50 {pct(stats['next'], 50):.3f} s, p95 {pct(stats['next'], 95):.3f} s, "
            f"none {fails['next']}/{len(stats['next'])}"
        )
        print(
            line("to_reach (analytic)", stats["analytic"], fails["analytic"], n)
            + "  (failed: none of its poses passes the checks)"
        )
        for kind in ("to_see", "to_open", "on"):
            print(line(kind, stats[kind], fails[kind], n))
        first_all += stats["to_reach"]
    print(
        f"first solution: p50 {pct(first_all, 50):.3f} s, p95 {pct(first_all, 95):.3f} s over {len(first_all)} queries"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
