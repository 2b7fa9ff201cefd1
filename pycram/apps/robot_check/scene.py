"""The fixed scene of a conformance run: the apartment, one test object, the robot at the start.

Every world of `pycram robot check` is this scene, fresh: the apartment
(:mod:`pycram.environments.apartment`) with a cup standing on the kitchen counter at
`TEST_OBJECT_SPOT` and the robot at `START` -- open floor, facing the counter 2.9 m ahead, with
at least 0.9 m free in front of it and to either side (the motions and the reach envelope are
checked there, and the camera check puts the cup on the floor ahead). `VIEWPOINT` is the
apartment's place in front of the counter, where the navigating action drives. The action checks
use the counter, the dining table (`PLACE_TARGET`) and the drawer cabinet's third drawer
(`CONTAINER`).

The simulator sets the scene up (as a test fixture does); the robot knows nothing of it but what
its camera tells it. Judging uses the simulator's truth (`holding`, `rests_on`), never given to
the plans.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

__all__ = [
    "ENVIRONMENT",
    "START",
    "TEST_OBJECT",
    "TEST_OBJECT_SPOT",
    "VIEWPOINT",
    "PLACE_TARGET",
    "TRANSPORT_TARGET",
    "CONTAINER",
    "SETUP_TIMEOUT",
    "CheckScene",
    "holding",
    "rests_on",
]

#: The environment of every check.
ENVIRONMENT = "apartment"
#: Where the robot starts (x [m], y [m], yaw [rad], map): the apartment's start, facing north.
START = (2.0, 1.5, math.pi / 2)
#: The test object's type (and its name in the simulator).
TEST_OBJECT = "cup"
#: Where the test object stands: (surface, (x [m], y [m])), upright.
TEST_OBJECT_SPOT = ("counter", (1.0, 4.55))
#: The apartment's place in front of the counter (the navigating action drives there).
VIEWPOINT = "kitchen"
#: Where the place check puts the object down (a surface's name).
PLACE_TARGET = "table"
#: Where the transport check brings the object (a surface's name).
TRANSPORT_TARGET = "counter"
#: The container the open and close checks open and close.
CONTAINER = "drawer 3"
#: Longest wait [s, simulated] for setting the scene up (a command of the simulator).
SETUP_TIMEOUT = 30.0


@dataclass
class CheckScene:
    """A running world of the scene with the robot loaded (not yet active: ``with scene.robot``).

    `world` is the :class:`pycram.sim.World`, `robot` the robot of its registered package
    (`pycram.robots.load`), `description` its validated description. Close it with `close`.
    """

    world: Any
    robot: Any
    description: Any

    @classmethod
    def open(cls, robot_name: str) -> CheckScene:
        """The scene with `robot_name` at `START` (see the module docstring). Raises what building
        the world or loading the robot raises (the world is closed again then)."""
        from pycram import robots
        from pycram.sim import World
        from pycram.world.objects import object_type

        world = World(robot_name, environment=ENVIRONMENT, objects=[TEST_OBJECT], seed=1, base_pose=START)
        try:
            surface, (x, y) = TEST_OBJECT_SPOT
            z = world.environment.surface(surface).height + object_type(TEST_OBJECT).half_height + 0.002
            outcome = world.move_item(TEST_OBJECT, (x, y, z)).wait(SETUP_TIMEOUT)
            if outcome is None or not outcome.succeeded:
                raise RuntimeError(f"could not stand the test {TEST_OBJECT} on the {surface}: {outcome}")
            robot = robots.load(robot_name, world)
        except BaseException:
            world.close()
            raise
        return cls(world, robot, world.description)

    def sim_time(self) -> float:
        """The world's simulated time now [s]."""
        return float(self.world.sim_time.get_value())

    def close(self) -> None:
        """Shut the robot's process modules down and close the world."""
        try:
            self.robot.shutdown()
        finally:
            self.world.close()


def holding(world: Any) -> set[str]:
    """The items the robot's grippers hold (simulator truth)."""
    return {s.holding for s in (f.get_value() for f in world.gripper_states.values()) if s and s.holding}


def rests_on(world: Any, item: str, surface: str) -> tuple[bool, str]:
    """Whether `item` stands upright (< 20 deg) on `surface` (simulator truth), and where it is."""
    from pycram.world.objects import object_type

    pose = world.item_poses.get_value()[item]
    x, y, z = pose.position
    w, qx, qy, qz = pose.orientation
    tilt = math.degrees(math.acos(max(-1.0, min(1.0, 1.0 - 2.0 * (qx * qx + qy * qy)))))
    env_surface = world.environment.surface(surface)
    bottom = z - object_type(item).half_height
    ok = env_surface.contains(x, y, 0.0) and abs(bottom - env_surface.height) < 0.03 and tilt < 20.0
    return ok, f"({x:.2f}, {y:.2f}, {z:.2f}) m, tilted {tilt:.0f} deg"
