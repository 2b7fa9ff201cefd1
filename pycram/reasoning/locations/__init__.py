"""Location reasoning: where to stand to reach, see or open something, and where to put things.

`LocationReasoner` resolves the location vocabulary (``to_reach``, ``to_see``, ``to_open``,
``on``, ``in``) for any robot in any environment: costmap layers over the floor, ranked
best-first, each candidate validated with prospection. Robot numbers come from the robot's
description (`RobotGeometry`), environment facts from the environment's description. One module
per vocabulary: `reach` (``to_reach``), `see` (``to_see``), `opening` (``to_open``), `spots`
(``on``, ``in``), on the shared search (`search`, `standing`); `reasoner` combines them. This
package is reasoning: it asks `pycram.world.prospection`, never a simulator.
"""

from .costmap import Costmap, FloorGrid
from .grasps import grasp_sequence
from .reasoner import VOCABULARY, LocationReasoner
from .robot_geometry import RobotGeometry
from .solutions import BaseLocation, Spot
from .targets import KnownObject, Target, as_target

__all__ = [
    "LocationReasoner",
    "RobotGeometry",
    "BaseLocation",
    "Spot",
    "Target",
    "KnownObject",
    "as_target",
    "Costmap",
    "FloorGrid",
    "VOCABULARY",
    "grasp_sequence",
]
