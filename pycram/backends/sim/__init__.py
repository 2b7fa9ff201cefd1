"""The simulator backend: a MuJoCo environment with a robot whose sensors feed fluents.

Import this package only when a simulation is wanted: it imports numpy and mujoco (and chooses
a headless OpenGL backend first when no display is set). Quick start::

    from pycram.backends.sim import World
    with World("pr2") as world:
        world.drive_to(*world.description.KITCHEN_BASE_POSES["cooker #2"]).wait(30)
        world.snapshot("kitchen.png")

May import: the layers above it (core to actions); never the ROS backend, except that the ROS
bridge tool (:mod:`pycram.backends.sim.ros_bridge`) uses its message interfaces. Users import it
as :mod:`pycram.sim`.
"""

from ._gl import configure_gl

configure_gl()

from pycram.world.types import GripperState, JointStates, Outcome, Pose, Pose2D, VisibleItem, yaw_to_quat  # noqa: E402

from .camera import FollowView  # noqa: E402
from .errors import CommandFailed, SimulationError, UnknownNameError, WorldClosedError  # noqa: E402
from .handle import CommandHandle  # noqa: E402
from .items import DEFAULT_ITEMS, ItemSpec  # noqa: E402
from .robot_model import HEAD_CAMERA, ROBOTS  # noqa: E402
from .scene import Scene, build_scene  # noqa: E402
from .world import World  # noqa: E402

__all__ = [
    "World",
    "CommandHandle",
    "Outcome",
    "Pose",
    "Pose2D",
    "VisibleItem",
    "GripperState",
    "JointStates",
    "ItemSpec",
    "DEFAULT_ITEMS",
    "HEAD_CAMERA",
    "ROBOTS",
    "Scene",
    "build_scene",
    "yaw_to_quat",
    "FollowView",
    "SimulationError",
    "UnknownNameError",
    "WorldClosedError",
    "CommandFailed",
]
