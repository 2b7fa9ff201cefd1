"""The world model layer: what every layer may know and ask about the world, backend-neutral.

May import: :mod:`pycram.core`, :mod:`pycram.designators`, :mod:`pycram.execution` (typed
failures), the standard library and numpy -- never a backend or a robot. A backend
(:mod:`pycram.backends.sim`, :mod:`pycram.backends.ros`) implements the interfaces; reasoning
code imports from here, never from a backend.

- :mod:`pycram.world.environment` -- environment descriptions as data (surfaces, containers, places).
- :mod:`pycram.world.objects` -- object types (shape, colour, grasps).
- :mod:`pycram.world.scenes` -- random scenes from a seed (which objects stand where).
- :mod:`pycram.world.prospection` -- "what if" questions without moving the robot.
- :mod:`pycram.world.navigation` -- occupancy grids and base path planning.
- :mod:`pycram.world.types` -- poses, command outcomes, gripper and joint states.
- :mod:`pycram.world.robot_description` -- a robot's description as validated data.
- :mod:`pycram.world.robot_registry` -- the registered robots (``pycram.robots`` entry points).
"""
