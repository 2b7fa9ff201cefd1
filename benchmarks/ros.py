"""ROS backend benchmark (issue 19): the thesis demo over ROS vs in-process, and the round trip of
a fluent update through a topic.

    .venv/bin/python benchmarks/ros.py [--robot pr2|tiago] [--runs N] [--samples N]

Figures:

* demo wall time: `run_demo` with `backend="sim"` (process modules call the simulator in this
  process) and `backend="ros"` (plan -> ROS process modules -> roscore on 127.0.0.1 -> a
  `pycram sim-ros-bridge` subprocess -> MuJoCo). Both without animation and trace recording.
  "plan" is the wall time the plan ran, "run" the whole run (world/connection, plan, end
  pictures), "sim" the simulated time the plan took; the bridge's start-up (a fresh kitchen per
  run) is printed separately. Median over `--runs`.
* fluent round trip: time from just before `publish()` of a `std_msgs/Float64` on a topic of
  this process's node, through rospy (TCP on loopback) into a `Fluent` set by the transport's
  subscription callback, to just after a thread blocked in `wait_for()` on a fluent network over
  it (`value == i`) returned. p50/p90/p99 over `--samples` updates, one at a time.

Needs ROS 1 (scripts/install_ros.sh). Prints its figures; asserts nothing.
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import threading
import time
from pathlib import Path
from tempfile import TemporaryDirectory

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
os.environ.setdefault("MUJOCO_GL", "egl")


def demo_figures(robot: str, backend: str, runs: int, master_uri: str = "") -> dict[str, float]:
    from pycram.apps.demos.kitchen import DemoOptions, run_demo
    from pycram.backends.ros.launch import BridgeProcess

    plan, run, sim, startup = [], [], [], []
    for _ in range(runs):
        bridge = None
        if backend == "ros":  # a fresh simulated kitchen per run, served by its own bridge
            started = time.monotonic()
            bridge = BridgeProcess(robot, master_uri)
            startup.append(time.monotonic() - started)
        try:
            with TemporaryDirectory() as output:
                result = run_demo(
                    DemoOptions(
                        robot=robot, backend=backend, output=Path(output), record=False, quiet=True, animation=False
                    )
                )
        finally:
            if bridge is not None:
                bridge.stop()
        if result.exit_code != 0:
            raise SystemExit(f"the demo failed over {backend}: {result.message}")
        plan.append(result.plan_wall_time)
        run.append(result.wall_time)
        sim.append(result.sim_time)
    return {
        "plan": statistics.median(plan),
        "run": statistics.median(run),
        "sim": statistics.median(sim),
        "startup": statistics.median(startup) if startup else 0.0,
    }


def round_trip(samples: int) -> list[float]:
    """Latencies [s] of publish -> fluent -> waiter wakes, one update at a time."""
    import rospy
    from std_msgs.msg import Float64

    from pycram.backends.ros.ros1 import ros1_transport
    from pycram.fluent import Fluent

    transport = ros1_transport()
    value = Fluent(None, name="benchmark value")
    subscription = transport.subscribe(
        "/pycram_benchmark/value", "std_msgs/Float64", lambda message: value.set_value(message.data)
    )
    publisher = rospy.Publisher("/pycram_benchmark/value", Float64, queue_size=10)
    latencies: list[float] = []
    sent = [0.0]
    woke = threading.Event()
    target = [0.0]
    arrived = Fluent(lambda: True if value.get_value() == target[0] else None)
    value.add_child(arrived)

    def waiter() -> None:
        for i in range(-1, samples):
            target[0] = float(i)
            ready.set()
            arrived.wait_for(10.0)
            if i >= 0:
                latencies.append(time.perf_counter() - sent[0])
            woke.set()

    ready = threading.Event()
    thread = threading.Thread(target=waiter, daemon=True)
    thread.start()
    # warm-up: publish -1 until the subscriber is connected (a latched first message would do too)
    ready.wait(10.0)
    ready.clear()
    deadline = time.monotonic() + 10.0
    while not woke.wait(0.05) and time.monotonic() < deadline:
        publisher.publish(Float64(-1.0))
    for i in range(samples):
        ready.wait(10.0)
        ready.clear()
        woke.clear()
        sent[0] = time.perf_counter()
        publisher.publish(Float64(float(i)))
        if not woke.wait(10.0):
            raise SystemExit(f"update {i} never arrived")
    thread.join(10.0)
    publisher.unregister()
    subscription.close()
    return latencies


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robot", default="pr2", choices=("pr2", "tiago"))
    parser.add_argument("--runs", type=int, default=1, help="demo runs per backend (median)")
    parser.add_argument("--samples", type=int, default=500, help="fluent round trips")
    args = parser.parse_args()

    from pycram.backends.ros.launch import RosMaster

    print(f"thesis demo, {args.robot}, median of {args.runs} run(s) [s of wall time]:")
    sim = demo_figures(args.robot, "sim", args.runs)
    print(f"  in-process      plan {sim['plan']:6.2f}   run {sim['run']:6.2f}   (simulated {sim['sim']:.1f} s)")
    # one roscore on loopback for this process (rospy cannot move its node to another master)
    with RosMaster() as master:
        os.environ.update(ROS_MASTER_URI=master.uri, ROS_IP="127.0.0.1", ROS_HOSTNAME="127.0.0.1")
        ros = demo_figures(args.robot, "ros", args.runs, master.uri)
        print(
            f"  over ROS 1      plan {ros['plan']:6.2f}   run {ros['run']:6.2f}   (simulated {ros['sim']:.1f} s; "
            f"bridge start-up {ros['startup']:.2f} s not included)"
        )
        print(f"  ROS / in-process: plan x{ros['plan'] / sim['plan']:.2f}, run x{ros['run'] / sim['run']:.2f}")
        latencies = sorted(round_trip(args.samples))
    q = statistics.quantiles(latencies, n=100)
    print(f"fluent round trip through a topic (publish -> fluent -> wait_for wakes), {len(latencies)} samples:")
    print(f"  p50 {q[49] * 1e3:.2f} ms   p90 {q[89] * 1e3:.2f} ms   p99 {q[98] * 1e3:.2f} ms")


if __name__ == "__main__":
    main()
