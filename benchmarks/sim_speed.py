"""How much faster than real time the headless simulation runs (PR2 in the kitchen).

Runs a drive with head tracking and an arm motion, then idles, and prints the factor
simulated time / wall time. Issue 6 asks for >= 5x on a 2-core machine.

    MUJOCO_GL=egl .venv/bin/python benchmarks/sim_speed.py [pr2|tiago] [seconds]
"""

from __future__ import annotations

import sys
import time


def main() -> None:
    robot = sys.argv[1] if len(sys.argv) > 1 else "pr2"
    sim_seconds = float(sys.argv[2]) if len(sys.argv) > 2 else 20.0
    from pycram.sim import World

    t0 = time.perf_counter()
    world = World(robot)
    load = time.perf_counter() - t0
    try:
        s0, w0 = world.sim_time.get_value(), time.perf_counter()
        track = world.track_point((0.1, -1.2, 0.95))
        drive = world.drive_to(*world.description.KITCHEN_BASE_POSES["cooker #1"])
        arm = world.move_arm_to(world.description.DEFAULT_ARM, "carry")
        drive.wait(sim_seconds)
        arm.wait(sim_seconds)
        (world.sim_time >= s0 + sim_seconds).wait_for()
        wall = time.perf_counter() - w0
        sim = world.sim_time.get_value() - s0
        track.cancel()
    finally:
        world.close()
    print(f"{robot}: scene load {load:.2f} s; simulated {sim:.1f} s in {wall:.2f} s wall "
          f"-> {sim / wall:.1f}x real time (drive: {drive.outcome.reason}, arm: {arm.outcome.reason})")


if __name__ == "__main__":
    main()
