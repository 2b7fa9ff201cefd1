"""How fast the headless simulation loads and runs (issue 6: load < 3 s, >= 5x real time for the
PR2 kitchen on a 2-core machine).

Measures, in one process:
- the import of `pycram.sim` (numpy, mujoco, GL selection) [s of wall time];
- scene loads: `World(robot)` constructed and closed `--loads` times [s of wall time each];
- the real-time factor (simulated time / wall time) of a busy world: a drive across the kitchen
  with the head tracking a point and an arm moving, followed by idling, for `seconds` of
  simulated time. Sensors publish at the default 50 Hz throughout.

    MUJOCO_GL=egl .venv/bin/python benchmarks/sim_speed.py [pr2|tiago] [seconds] [--loads N]

Numbers depend on the machine's load; run it on an otherwise idle machine for the record.
"""

from __future__ import annotations

import argparse
import os
import time


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("robot", nargs="?", default="pr2", choices=("pr2", "tiago"))
    parser.add_argument("seconds", nargs="?", type=float, default=20.0, help="simulated seconds to run")
    parser.add_argument("--loads", type=int, default=3, help="how many times to build a world")
    args = parser.parse_args()

    t0 = time.perf_counter()
    from pycram.sim import World

    imported = time.perf_counter() - t0
    loads = []
    for _ in range(args.loads):
        t0 = time.perf_counter()
        world = World(args.robot)
        loads.append(time.perf_counter() - t0)
        world.close()

    world = World(args.robot)
    try:
        s0, w0 = world.sim_time.get_value(), time.perf_counter()
        track = world.track_point((0.1, -1.2, 0.95))
        drive = world.drive_to(*world.description.KITCHEN_BASE_POSES["cooker #1"])
        arm = world.move_arm_to(world.description.DEFAULT_ARM, "carry")
        drive.wait(args.seconds)
        arm.wait(args.seconds)
        (world.sim_time >= s0 + args.seconds).wait_for(args.seconds + 1.0)
        wall = time.perf_counter() - w0
        sim = world.sim_time.get_value() - s0
        track.cancel()
    finally:
        world.close()
    reasons = ", ".join(f"{name}: {h.outcome.reason if h.outcome else '?'}" for name, h in (("drive", drive), ("arm", arm)))
    print(f"{args.robot}: import pycram.sim {imported:.2f} s; scene load (World) "
          + ", ".join(f"{t:.2f}" for t in loads) + " s")
    print(f"{args.robot}: simulated {sim:.1f} s in {wall:.2f} s wall -> {sim / wall:.1f}x real time "
          f"({reasons}; MUJOCO_GL={os.environ.get('MUJOCO_GL')}, load average "
          f"{os.getloadavg()[0]:.1f} on {os.cpu_count()} cores)")


if __name__ == "__main__":
    main()
