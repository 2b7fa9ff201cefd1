"""`pycram sim-ros-bridge`: serve the simulated robot over ROS 1."""

from __future__ import annotations

import logging
import math
import os
from typing import Any

import typer

from pycram.apps.cli.app import (
    LiveHelpOption,
    app,
    fail,
    robot_option_help,
)
from pycram.environments import DEFAULT_ENVIRONMENT, ENVIRONMENT_HELP
from pycram.world.robot_registry import DEFAULT_ROBOT, robot_choices, robot_description, robot_names

_log = logging.getLogger(__name__)


def _ros_robots_help() -> str:
    """The help text of `sim-ros-bridge --robot`: the registered robots whose description has a
    ROS interface (its ``ROS`` key), now. A description that does not load is left out (the
    help of every command is made on each `pycram` call; `pycram robot check` tells what is
    wrong with it)."""
    names = []
    for name in robot_names():
        try:
            if robot_description(name).ROS is not None:
                names.append(name)
        except Exception as error:  # any error of a robot package: its own check reports it
            _log.debug("robot %r left out of the help: %s", name, error)
    return robot_option_help(names)


#: `sim-ros-bridge --robot`: its help lists the robots with a ROS interface when the command runs.
_RosRobotOption: Any = LiveHelpOption(_ros_robots_help, default=DEFAULT_ROBOT, param_decls=("--robot",))


def object_items(values: list[str]) -> list:
    """The simulator items of ``--object`` values ``TYPE@X,Y`` or ``TYPE@X,Y,Z`` [m, map]: objects
    of known types (:data:`pycram.world.objects.OBJECT_TYPES`), named by their type (``cup``,
    ``cup-2``, ...); ``ValueError`` saying what is wrong with a value."""
    from pycram.backends.sim.items import ItemSpec
    from pycram.world.objects import OBJECT_TYPES

    items, counts = [], dict[str, int]()
    for value in values:
        type_name, at, where = value.partition("@")
        if not at or type_name not in OBJECT_TYPES:
            types = ", ".join(sorted(OBJECT_TYPES))
            raise ValueError(f"--object {value!r}: give TYPE@X,Y or TYPE@X,Y,Z [m] with TYPE one of {types}")
        try:
            numbers = [float(v) for v in where.split(",")]
        except ValueError:
            numbers = []
        if len(numbers) not in (2, 3) or not all(math.isfinite(v) for v in numbers):
            raise ValueError(f"--object {value!r}: the place is X,Y or X,Y,Z in [m], got {where!r}")
        counts[type_name] = counts.get(type_name, 0) + 1
        name = type_name if counts[type_name] == 1 else f"{type_name}-{counts[type_name]}"
        z = numbers[2] if len(numbers) == 3 else None
        items.append(ItemSpec.of(OBJECT_TYPES[type_name], name, (numbers[0], numbers[1], z)))
    return items


def _base_pose(value: str) -> tuple[float, float, float]:
    """``X,Y,YAW`` [m, m, rad] as numbers; ``ValueError`` saying what is wrong."""
    try:
        x, y, yaw = (float(v) for v in value.split(","))
    except ValueError:
        raise ValueError(f"--base-pose is X,Y,YAW in [m, m, rad], got {value!r}") from None
    if not all(math.isfinite(v) for v in (x, y, yaw)):
        raise ValueError(f"--base-pose must be finite, got {value!r}")
    return (x, y, yaw)


@app.command("sim-ros-bridge")
def sim_ros_bridge_command(
    robot: str = _RosRobotOption,
    item_at: int | None = typer.Option(
        None,
        "--item-at",
        min=0,
        max=3,
        help="Thesis kitchen: where the demo's mug starts, position 1, 2 or 3 (0: no item; default 1).",
    ),
    environment: str = typer.Option(
        DEFAULT_ENVIRONMENT,
        "--environment",
        "--env",
        help=f"The environment: {ENVIRONMENT_HELP}. The plan's robot must be configured for the same one.",
    ),
    base_pose: str | None = typer.Option(
        None,
        "--base-pose",
        help="Where the robot starts: X,Y,YAW (m, m, rad, map frame); default: the environment's start "
        "(the thesis kitchen: the demo's).",
    ),
    objects: list[str] | None = typer.Option(
        None,
        "--object",
        help="An object of a known type standing upright at x, y (m, map frame) on the highest surface there, "
        "or with its centre at x, y, z: TYPE@X,Y or TYPE@X,Y,Z (repeatable; named TYPE, TYPE-2, ...).",
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
    from pycram.backends.ros.config import ROBOT_CONFIGS

    if robot not in ROBOT_CONFIGS:  # the robots whose description has a ROS interface
        fail(f"--robot must be {robot_choices(sorted(ROBOT_CONFIGS))}, not {robot!r}", code=2)
    from pycram.apps.demos.ros_kitchen_world import bridge_environment

    try:
        environment = bridge_environment(environment)
    except KeyError as e:
        fail(f"--environment: {str(e).strip(chr(34) + chr(39))}", code=2)
    if item_at is not None and item_at != 0 and environment != DEFAULT_ENVIRONMENT:
        fail(f"--item-at places the demo's mug in the {DEFAULT_ENVIRONMENT}; use --object in the {environment}", code=2)
    try:
        placed = object_items(objects or [])
        start = None if base_pose is None else _base_pose(base_pose)
    except ValueError as e:
        fail(str(e), code=2)
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

    kitchen = environment == DEFAULT_ENVIRONMENT
    run_bridge(
        robot,
        (demo_items(1 if item_at is None else item_at) if kitchen else []) + placed,
        start if start is not None or not kitchen else START_POSE,
        environment=environment,
        realtime=realtime,
        publish_rate=publish_rate,
        perception_faults=PerceptionFaults(pose_noise, miss_probability, wrong_color_probability, perception_seed),
        ready=lambda: print(f"sim-ros-bridge ready: {robot} on {os.environ['ROS_MASTER_URI']}", flush=True),
    )
