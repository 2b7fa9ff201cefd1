"""`pycram sim-ros-bridge`: serve the simulated robot over ROS 1."""

from __future__ import annotations

import os

import typer

from pycram.apps.cli.app import (
    ROBOT_HELP,
    app,
    fail,
)
from pycram.world.robot_registry import DEFAULT_ROBOT, robot_choices, robot_names


@app.command("sim-ros-bridge")
def sim_ros_bridge_command(
    robot: str = typer.Option(DEFAULT_ROBOT, "--robot", help=ROBOT_HELP),
    item_at: int = typer.Option(
        1, "--item-at", min=0, max=3, help="Where the demo's mug starts: position 1, 2 or 3 (0: no item)."
    ),
    realtime: bool = typer.Option(
        False,
        "--realtime",
        help="Simulate at real-time speed (default: as fast as possible; /clock carries the simulation time).",
    ),
    publish_rate: float = typer.Option(
        50.0,
        "--publish-rate",
        min=1.0,
        help="Sensor topics and /clock per second of simulated time [Hz of simulated time].",
    ),
    host: str = typer.Option(
        "127.0.0.1",
        "--host",
        help="Address the node binds to and advertises (ROS_IP). "
        "Loopback by default: nothing outside this machine can command the robot.",
    ),
    allow_remote_master: bool = typer.Option(
        False, "--allow-remote-master", help="Accept a ROS_MASTER_URI that is not on loopback."
    ),
    pose_noise: float = typer.Option(
        0.0, "--pose-noise", min=0.0, help="Perception fault: std. dev. of the noise on measured centres [m]."
    ),
    miss_probability: float = typer.Option(
        0.0, "--miss-probability", min=0.0, max=1.0, help="Perception fault: probability that a seen object is missed."
    ),
    wrong_color_probability: float = typer.Option(
        0.0, "--wrong-color-probability", min=0.0, max=1.0, help="Perception fault: probability of a wrong colour."
    ),
    perception_seed: int = typer.Option(0, "--perception-seed", help="Seed of the perception faults."),
) -> None:
    """Serve the simulated robot over ROS 1 (move_base, PointHead, arm/torso trajectories, grippers,
    /amcl_pose, /joint_states, /clock, the head camera's detections), as a real robot's drivers
    would. Needs ROS_MASTER_URI."""
    if robot not in robot_names():
        fail(f"--robot must be {robot_choices()}, not {robot!r}", code=2)
    try:
        from pycram.backends.ros.launch import check_master_uri
    except ImportError as e:
        fail(f"sim-ros-bridge needs ROS 1 (run scripts/install_ros.sh): {e}")
    try:
        check_master_uri(os.environ.get("ROS_MASTER_URI"), allow_remote=allow_remote_master)
    except ValueError as e:
        fail(str(e), code=2)
    os.environ["ROS_IP"] = os.environ["ROS_HOSTNAME"] = host
    os.environ.setdefault("MUJOCO_GL", "egl")
    from pycram.apps.demos.kitchen_world import START_POSE, demo_items
    from pycram.backends.sim.perception import PerceptionFaults
    from pycram.backends.sim.ros_bridge import run_bridge

    run_bridge(
        robot,
        demo_items(item_at),
        START_POSE,
        realtime=realtime,
        publish_rate=publish_rate,
        perception_faults=PerceptionFaults(pose_noise, miss_probability, wrong_color_probability, perception_seed),
        ready=lambda: print(f"sim-ros-bridge ready: {robot} on {os.environ['ROS_MASTER_URI']}", flush=True),
    )
