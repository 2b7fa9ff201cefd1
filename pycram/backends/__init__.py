"""The backends: what process modules drive. :mod:`pycram.backends.sim` is the MuJoCo simulator
(physics, sensors, faults, prospection from the belief, and the tool that serves it over ROS);
:mod:`pycram.backends.ros` reaches a robot over ROS 1.

May import: every layer above (core, designators, execution, world, environments, reasoning,
actions). The two backends are independent: the ROS backend never imports the simulator; the
simulator's ROS bridge tool uses the ROS backend's message interfaces and nothing else of it.
"""
