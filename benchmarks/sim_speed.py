"""How fast the headless simulation loads and runs (issue 6: load < 3 s, >= 5x real time for the
PR2 kitchen on a 2-core machine), and what recording an animation costs.

Measures, in one process:
- the import of `pycram.sim` (numpy, mujoco, GL selection) [s of wall time];
- scene loads: `World(robot)` constructed and closed `--loads` times [s of wall time each];
- the real-time factor (simulated time / wall time) of a busy world: a drive across the kitchen
  with the head tracking a point and an arm moving, followed by idling, for `seconds` of
  simulated time. Sensors publish at the default 50 Hz throughout.
- with `--record FPS`: the same run again while recording the overview camera (`--size`), then
  how long `stop_recording` waited for the recorder thread, and how long writing the GIF takes:
  the recorded frames (encoded while recording), the same frames as a plain list (encoded by
  `write_animation`) and, for reference, imageio's GIF writer (how it was done before).
- with `--demo`: the kitchen demo (`pycram demo`, PR2, no database) with the animation on and
  off: simulated time, plan wall time, their factor, and the wall time of the whole run.

    MUJOCO_GL=egl .venv/bin/python benchmarks/sim_speed.py [pr2|tiago] [seconds] [--loads N]
        [--record FPS] [--size 480x360] [--demo]

Numbers depend on the machine's load; run it on an otherwise idle machine for the record.
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time
from pathlib import Path


def busy_run(world, seconds: float) -> tuple[float, float, str]:
    """Drive, track and move an arm for `seconds` of simulated time; (sim [s], wall [s], reasons)."""
    s0, w0 = world.sim_time.get_value(), time.perf_counter()
    track = world.track_point((0.1, -1.2, 0.95))
    drive = world.drive_to(*world.description.KITCHEN_BASE_POSES["cooker #1"])
    arm = world.move_arm_to(world.description.DEFAULT_ARM, "carry")
    drive.wait(seconds)
    arm.wait(seconds)
    (world.sim_time >= s0 + seconds).wait_for(seconds + 1.0)
    wall = time.perf_counter() - w0
    sim = world.sim_time.get_value() - s0
    track.cancel()
    reasons = ", ".join(
        f"{name}: {h.outcome.reason if h.outcome else '?'}" for name, h in (("drive", drive), ("arm", arm))
    )
    return sim, wall, reasons


def record_run(robot: str, seconds: float, fps: float, size: tuple[int, int]) -> None:
    from pycram.backends.sim.render import write_animation
    from pycram.sim import World

    world = World(robot)
    try:
        world.start_recording("overview", fps=fps, width=size[0], height=size[1]).wait(10.0)
        sim, wall, reasons = busy_run(world, seconds)
        t0 = time.perf_counter()
        frames = world.stop_recording()
        waited = time.perf_counter() - t0
    finally:
        world.close()
    print(
        f"{robot} recording {fps:g} fps at {size[0]}x{size[1]}: simulated {sim:.1f} s in {wall:.2f} s wall "
        f"-> {sim / wall:.1f}x real time ({reasons}); stop_recording waited {waited:.2f} s for the recorder; "
        f"{len(frames)} frames, {frames.dropped} dropped"
    )
    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        write_animation(Path(tmp) / "recorded.gif", frames, fps)
        recorded = time.perf_counter() - t0
        t0 = time.perf_counter()
        write_animation(Path(tmp) / "plain.gif", list(frames), fps)
        plain = time.perf_counter() - t0
        import imageio.v3 as iio
        import numpy as np

        t0 = time.perf_counter()
        iio.imwrite(Path(tmp) / "imageio.gif", np.stack(frames), duration=1000.0 / fps, loop=0)
        reference = time.perf_counter() - t0
        sizes = {p.name: p.stat().st_size // 1024 for p in Path(tmp).iterdir()}
    print(
        f"{robot} GIF of {len(frames)} frames: recorded frames written in {recorded:.3f} s, plain list encoded "
        f"in {plain:.2f} s, imageio (reference) {reference:.2f} s; sizes [kB] {sizes}"
    )


def demo_runs() -> None:
    from pycram.apps.demos.kitchen import DemoOptions, run_demo

    with tempfile.TemporaryDirectory() as tmp:
        for animation in (True, False):
            r = run_demo(DemoOptions(output=Path(tmp) / str(animation), quiet=True, record=False, animation=animation))
            print(
                f"demo pr2, animation {'on ' if animation else 'off'}: exit {r.exit_code}, simulated "
                f"{r.sim_time:.1f} s, "
                f"plan {r.plan_wall_time:.1f} s wall -> {r.speed_factor:.1f}x real time; whole run "
                f"{r.wall_time:.1f} s (load average {os.getloadavg()[0]:.1f})",
                flush=True,
            )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("robot", nargs="?", default="pr2", choices=("pr2", "tiago"))
    parser.add_argument("seconds", nargs="?", type=float, default=20.0, help="simulated seconds to run")
    parser.add_argument("--loads", type=int, default=3, help="how many times to build a world")
    parser.add_argument("--record", type=float, metavar="FPS", help="also run while recording at FPS")
    parser.add_argument("--size", default="480x360", help="frame size of --record, WIDTHxHEIGHT [px]")
    parser.add_argument("--demo", action="store_true", help="also run the kitchen demo with animation on and off")
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
        sim, wall, reasons = busy_run(world, args.seconds)
    finally:
        world.close()
    print(
        f"{args.robot}: import pycram.sim {imported:.2f} s; scene load (World) "
        + ", ".join(f"{t:.2f}" for t in loads)
        + " s"
    )
    print(
        f"{args.robot}: simulated {sim:.1f} s in {wall:.2f} s wall -> {sim / wall:.1f}x real time "
        f"({reasons}; MUJOCO_GL={os.environ.get('MUJOCO_GL')}, load average "
        f"{os.getloadavg()[0]:.1f} on {os.cpu_count()} cores)",
        flush=True,
    )
    if args.record:
        width, height = (int(v) for v in args.size.lower().split("x"))
        record_run(args.robot, args.seconds, args.record, (width, height))
    if args.demo:
        demo_runs()


if __name__ == "__main__":
    main()
