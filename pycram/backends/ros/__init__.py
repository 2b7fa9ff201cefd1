"""The ROS backend: process modules and sensors over ROS 1 (the thesis ran on a real PR2 this way).

Layout (one concept per module; ``rospy`` is imported only by :mod:`pycram.backends.ros.ros1` and
:mod:`pycram.backends.sim.ros_bridge`, so ``import pycram.ros`` works without ROS):

* :mod:`pycram.backends.ros.transport` -- the small interface the process modules talk through (actions,
  topics, messages); a ROS 2 transport can be added beside the ROS 1 one.
* :mod:`pycram.backends.ros.ros1` -- that interface over rospy/actionlib, with a liveness watchdog.
* :mod:`pycram.backends.ros.config` -- per-robot interface names (PR2's real names, TIAGo's), as data.
* :mod:`pycram.backends.ros.modules` -- the process modules (navigation, head, torso, arms, grippers,
  perception) and the sensor fluents.
* :mod:`pycram.backends.ros.detections` -- perception reports as detections messages and back (the
  ROS perception module folds them into the robot's belief).
* :mod:`pycram.robots.common.ros_robot` -- :func:`~pycram.robots.common.ros_robot.make_ros_robot` (with a belief state).
* :mod:`pycram.backends.sim.ros_bridge` -- ``pycram sim-ros-bridge``: the simulator served over ROS.
* :mod:`pycram.backends.ros.launch` -- roscore and the bridge as subprocesses, on loopback.
* :mod:`pycram.apps.demos.ros_kitchen_world` -- the demo's simulated environment (items, the helper's
  hands) reached through the bridge.

Set-up: ``scripts/install_ros.sh`` (Debian's ROS 1 packages + generated messages).

May import: the layers above it (core to actions); never the simulator (:mod:`pycram.backends.sim`)
and never a robot package. Users import it as :mod:`pycram.ros`.
"""

__all__: list[str] = []
