"""The demo's simulated environment reached over ROS: what the kitchen demo needs of its world
when the world runs inside ``pycram sim-ros-bridge`` (another process).

The *plan* only uses the robot (:func:`pycram.robots.common.ros_robot.make_ros_robot`). The demo's
environment -- the helper who hands the item back, the thief, the judge who checks that the item
ended on cooker #1 -- acts on the simulator through the bridge's simulator-only interfaces
(``<sim_namespace>/items``, ``<sim_namespace>/command``): :class:`RosSimEnvironment` offers the
same attributes and commands as :class:`pycram.sim.World` for them (``sim_time``, ``base_pose``,
``gripper_openings``, ``gripper_states``, ``item_poses``, ``take_item``, ``give_item``,
``snapshot``). A real robot has no such interfaces: this is for the simulated robot only.

:func:`open_ros_world` connects (starting ``roscore`` and the bridge on loopback when no
``ROS_MASTER_URI`` is set) and activates a clock that follows the bridge's ``/clock``, as ROS'
``use_sim_time`` does; :meth:`RosSimEnvironment.close` undoes all of it.
"""

from __future__ import annotations

import logging
import os
from pathlib import Path
from typing import Any

from pycram.core.fluent import Fluent
from pycram.core.runtime.clock import set_clock
from pycram.world.types import GripperState, Outcome, Pose

__all__ = ["RosSimEnvironment", "open_ros_world", "bridge_environment"]

logger = logging.getLogger(__name__)


class _ServiceCall:
    """A simulator command sent when waited for: ``wait(timeout)`` -> ``Outcome`` or ``None``
    while still running after ``timeout`` [s of simulated time]."""

    def __init__(self, environment: RosSimEnvironment, **request: Any) -> None:
        self._environment, self._request = environment, request

    def wait(self, timeout: float | None = None) -> Outcome | None:
        return self._environment._command(wait=float(timeout or 0.0), **self._request)


class RosSimEnvironment:
    """The bridge's world, seen from the plan's process (see the module docstring)."""

    def __init__(self, transport: Any, robot: Any, clock: Any, processes: tuple = ()) -> None:
        self.transport, self.ros_robot, self.clock = transport, robot, clock
        self.robot = robot.name
        config = robot.config
        self.base_pose = robot.state.base_pose
        self.gripper_openings = robot.state.gripper_openings
        self.gripper_states = {
            g: Fluent(GripperState(f.get_value()), name=f"{g}_gripper_state") for g, f in self.gripper_openings.items()
        }
        self.item_poses = Fluent({}, name="item_poses")
        self.sim_time = Fluent(clock.now(), name="sim_time")
        self._processes = list(processes)
        self._previous_clock: Any = None
        self._subscriptions = [
            transport.subscribe(f"{config.sim_namespace}/items", "pycram_msgs/ItemStates", self._on_items),
            transport.subscribe(
                config.clock_topic, "rosgraph_msgs/Clock", lambda m: self.sim_time.set_value(m.clock.to_sec())
            ),
        ]
        self._service = transport.service(f"{config.sim_namespace}/command", "pycram_msgs/SimCommand")

    def _on_items(self, message: Any) -> None:
        poses, holding = {}, {}
        for item in message.items:
            p, q = item.pose.position, item.pose.orientation
            poses[item.name] = Pose((p.x, p.y, p.z), (q.w, q.x, q.y, q.z))
            if item.held_by:
                holding[item.held_by] = item.name
        self.item_poses.set_value(poses)
        for gripper, state in self.gripper_states.items():
            opening = self.gripper_openings[gripper].get_value()
            state.set_value(GripperState(float(opening or 0.0), holding.get(gripper)))

    def _command(self, **request: Any) -> Outcome | None:
        try:
            response = self._service(**request)
        except Exception as e:  # the bridge went away
            return Outcome(False, "error", f"{request.get('command')}: {e}")
        if response.reason == "running":
            return None
        return Outcome(response.success, response.reason, response.message, response.value or None)

    # -- the World's environment commands --------------------------------------------------------
    def take_item(self, gripper: str | None = None, item: str | None = None) -> _ServiceCall:
        return _ServiceCall(self, command="take_item", gripper=gripper or "", item=item or "")

    def give_item(self, item: str, gripper: str, close: bool = True, timeout: float = 5.0) -> _ServiceCall:
        return _ServiceCall(self, command="give_item", item=item, gripper=gripper, close=close, timeout=float(timeout))

    def snapshot(self, path: str | Path, *args: Any, **kwargs: Any) -> None:
        """The bridge renders the overview camera into ``path`` (same machine: loopback)."""
        outcome = self._command(command="snapshot", item=str(Path(path).resolve()), wait=0.0)
        if outcome is None or not outcome.succeeded:
            logger.warning("no snapshot %s: %s", path, outcome)

    def start_recording(self, *args: Any, **kwargs: Any) -> None:
        """No animation over ROS (frames would have to cross the process boundary)."""

    def stop_recording(self, *args: Any, **kwargs: Any) -> list:
        return []

    def activate_clock(self) -> None:
        self._previous_clock = set_clock(self.clock)

    def close(self) -> None:
        """Shut the robot's modules, stop following the bridge, restore the clock, stop what
        :func:`open_ros_world` started (idempotent)."""
        self.ros_robot.shutdown()
        for subscription in self._subscriptions:
            subscription.close()
        self._subscriptions.clear()
        if self._previous_clock is not None:
            set_clock(self._previous_clock)
            self._previous_clock = None
        for process in reversed(self._processes):
            process.stop()
        self._processes.clear()

    def __repr__(self) -> str:
        return f"RosSimEnvironment({self.robot!r})"


def bridge_environment(name: str) -> str:
    """The environment ``--environment`` names, as the bridge and the plan's robot both load it: a
    hand-made one, ``procedural:SEED`` or ``file:PATH`` (made absolute, so that a process in
    another folder finds the same file). Raises `pycram.environments.EnvironmentNameError` (a
    `KeyError` naming the valid names) for a name `pycram.environments.load` cannot read."""
    from pathlib import Path

    from pycram.environments import FILE_PREFIX, check_name

    text = check_name(name)
    if text.startswith(FILE_PREFIX):
        return FILE_PREFIX + str(Path(text[len(FILE_PREFIX) :]).expanduser().resolve())
    return text


def open_ros_world(
    robot: str,
    item_at: int = 1,
    realtime: bool = False,
    master_uri: str | None = None,
    environment: str | None = None,
) -> tuple[RosSimEnvironment, Any]:
    """Connect to the simulated ``robot`` over ROS; return ``(environment, robot)``.

    ``master_uri`` (default ``$ROS_MASTER_URI``): a master with ``pycram sim-ros-bridge`` already
    running. Without one, starts ``roscore`` on a free port of 127.0.0.1 and the bridge as
    subprocesses, stopped by ``environment.close()``. The clock that follows ``/clock`` is
    active until then. ``environment`` (None: the thesis kitchen) is the world the bridge
    simulates -- a name ``pycram.environments.load`` reads (``apartment``, ``procedural:SEED``,
    ``file:PATH.toml``): the bridge started here builds it (with the demo's mug at ``item_at``
    only in the thesis kitchen), and the robot is configured for it (its map and belief); a
    bridge already running must simulate the same one. Raises `KeyError` (naming the valid
    names) for an environment that cannot be loaded.
    """
    from pycram.backends.ros.config import robot_config
    from pycram.backends.ros.launch import BridgeProcess, RosMaster, check_master_uri
    from pycram.environments import DEFAULT_ENVIRONMENT

    world_name = bridge_environment(environment or DEFAULT_ENVIRONMENT)
    kitchen = world_name == DEFAULT_ENVIRONMENT
    processes: list = []
    master_uri = master_uri or os.environ.get("ROS_MASTER_URI")
    try:
        if master_uri is None:
            master = RosMaster()
            processes.append(master)
            master_uri = master.uri
            processes.append(
                BridgeProcess(
                    robot,
                    master_uri,
                    item_at=item_at if kitchen else None,
                    realtime=realtime,
                    environment=None if kitchen else world_name,
                )
            )
            logger.info("started roscore on %s and sim-ros-bridge for %s in %s", master_uri, robot, world_name)
        check_master_uri(master_uri, allow_remote=True)
        _use_master(master_uri)
        from pycram.backends.ros.ros1 import ros1_transport
        from pycram.robots.common.ros_robot import make_ros_robot

        transport = ros1_transport()
        config = robot_config(robot).replace(environment=world_name)
        clock = transport.sim_clock(config.clock_topic)
        ros_robot = make_ros_robot(robot, transport, config)
        world = RosSimEnvironment(transport, ros_robot, clock, tuple(processes))
    except BaseException:
        for process in reversed(processes):
            process.stop()
        raise
    world.activate_clock()
    return world, ros_robot


def robot_config_clock(robot: str) -> str:
    from pycram.backends.ros.config import robot_config

    return robot_config(robot).clock_topic


def _use_master(master_uri: str) -> None:
    """Point this process's ROS node at ``master_uri`` (before it is initialised; rospy cannot
    move a node to another master afterwards -- then a clear error)."""
    import rosgraph
    import rospy

    if rospy.core.is_initialized():
        current = rosgraph.get_master_uri()
        if current != master_uri:
            raise RuntimeError(
                f"this process's ROS node already talks to {current}; rospy cannot move "
                f"it to {master_uri} (run one ROS master per process)"
            )
        return
    os.environ["ROS_MASTER_URI"] = master_uri
    os.environ.setdefault("ROS_IP", "127.0.0.1")
    os.environ.setdefault("ROS_HOSTNAME", "127.0.0.1")
