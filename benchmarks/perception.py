"""How long one object detection takes (issue 15: p50 <= 30 ms at 320 x 240).

The PR2 stands south of the apartment's table with all six object types on it and looks at them.
Measured over `--looks` looks (after one warm-up look that creates the renderers):

- in the simulation thread: the two renders (segmentation with its depth buffer, colour) and the
  measurement of the detections (`World._detect`) [ms of wall time];
- the belief update of the caller (`BeliefState.update`) [ms];
- one detection as a plan sees it: `World.detect()` sent, waited for, and folded into the
  belief (includes waiting for the simulation thread to pick up the command) [ms].

    MUJOCO_GL=egl .venv/bin/python benchmarks/perception.py [--looks 100] [--size 320x240]

Numbers depend on the machine's load; run it on an otherwise idle machine for the record.
"""

from __future__ import annotations

import argparse
import math
import statistics
import time


def percentiles(values: list[float]) -> str:
    ordered = sorted(values)
    p = lambda q: ordered[min(len(ordered) - 1, int(q * len(ordered)))]  # noqa: E731
    return f"p50 {statistics.median(values):6.1f} ms   p95 {p(0.95):6.1f} ms   max {ordered[-1]:6.1f} ms"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--looks", type=int, default=100)
    parser.add_argument("--size", default="320x240", help="image width x height [px]")
    args = parser.parse_args()
    width, height = (int(v) for v in args.size.split("x"))

    from pycram.backends.sim.perception import MAX_RANGE, MIN_PIXELS
    from pycram.sim import World
    from pycram.world.belief import BeliefState
    from pycram.world.objects import OBJECT_TYPES, object_type

    types = list(OBJECT_TYPES)
    world = World("pr2", environment="apartment", objects=types, seed=1, base_pose=(4.3, 0.9, math.pi / 2))
    try:
        table = world.environment.surface("table")
        for i, name in enumerate(types):
            x = 3.8 + 0.2 * i
            y = 1.85 if i % 2 else 2.2
            world.move_item(name, (x, y, table.height + object_type(name).half_height + 0.002)).wait(10.0)
        world.point_head((4.3, 2.0, 0.8)).wait(10.0)
        belief = BeliefState(world.environment)
        world.detect(width, height).wait(30.0)  # warm-up: creates the renderers

        in_thread, updates, round_trips, counts = [], [], [], []
        for _ in range(args.looks):
            handle = world._call("bench", lambda eng: _timed(world, eng, width, height, MIN_PIXELS, MAX_RANGE))
            report, seconds = handle.wait(30.0).value
            in_thread.append(1000 * seconds)
            t0 = time.perf_counter()
            belief.update(report)
            updates.append(1000 * (time.perf_counter() - t0))
            t0 = time.perf_counter()
            belief.update(world.detect(width, height).wait(30.0).value)
            round_trips.append(1000 * (time.perf_counter() - t0))
            counts.append(len(report.detections))
        print(
            f"one detection at {width} x {height} px, {args.looks} looks, "
            f"{statistics.median(counts):.0f} of {len(types)} objects detected per look"
        )
        print(f"  2 renders + measure (sim thread)   {percentiles(in_thread)}")
        print(f"  belief update                      {percentiles(updates)}")
        print(f"  detect() round trip + update       {percentiles(round_trips)}")
        target = statistics.median(in_thread) + statistics.median(updates)
        print(f"  render + segmentation + belief update p50: {target:.1f} ms (target <= 30 ms)")
    finally:
        world.close()


def _timed(world, eng, width, height, min_pixels, max_range):
    t0 = time.perf_counter()
    report = world._detect(eng, width, height, min_pixels, max_range)
    return report, time.perf_counter() - t0


if __name__ == "__main__":
    main()
