"""The world model layer: what every layer may know and ask about the world, backend-neutral.

Modules here use the standard library and numpy only; a backend (``pycram.sim``, later ROS)
implements the interfaces. Reasoning code imports from here, never from a backend.

- :mod:`pycram.world.environment` -- environment descriptions as data (surfaces, containers, places).
- :mod:`pycram.world.objects` -- object types (shape, colour, grasps).
- :mod:`pycram.world.scenes` -- random scenes from a seed (which objects stand where).
- :mod:`pycram.world.prospection` -- "what if" questions without moving the robot.
- :mod:`pycram.world.navigation` -- occupancy grids and base path planning.
"""
