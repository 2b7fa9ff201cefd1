"""What every robot shares: the process modules that drive a simulated world
(:mod:`~pycram.robots.common.sim_modules`), the designator resolvers built from a robot
description (:mod:`~pycram.robots.common.sim_resolvers`), the motion vocabulary
(:mod:`~pycram.robots.common.sim_vocabulary`) and a robot reached over ROS
(:mod:`~pycram.robots.common.ros_robot`).
"""
