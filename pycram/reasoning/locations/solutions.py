"""What location designators resolve to: base poses that say how, and spots for objects."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

__all__ = ["BaseLocation", "Spot"]


@dataclass(frozen=True)
class BaseLocation:
    """A base pose (map frame: x [m], y [m], yaw [rad]) found for a location designator.

    Usable wherever a base pose is (``('moving', pose=...)`` reads x, y, yaw). `arm` and `grasp`
    say which arm and which grasp (approach, see `pycram.world.objects.APPROACHES`) the
    solution was validated for (None where they do not apply); `joints` the arm's joint
    solutions of the validated sequence; `cost` its rank in the costmap (lower is better);
    `visible` the fraction of the target the head camera sees (``to_see``); `tool_poses` the
    validated tool poses of the sequence (position [m], orientation (w, x, y, z)), in order;
    `torso` the named torso position the solution needs (None: the torso as it is; the actions
    carry objects with the torso up afterwards, `pycram.actions.pick_up.CARRY_TORSO`);
    `push` the face of a door the hand pushes from there (``'inside'``/``'outside'``; None: not
    a push); `grasp_candidate` the planned grasp (`pycram.reasoning.grasps.GraspCandidate`) the
    solution was validated for, when it was not one of the object type's grasps (then `grasp`
    is its approach, ``'side'`` or ``'top'``, and `tool_poses` hold the orientations to reach);
    `arrival` the joint positions [rad] `arm` must hold to come to this pose (an object held
    lifted clear of the furniture there; empty: as the arm is).
    """

    x: float
    y: float
    yaw: float
    arm: str | None = None
    grasp: str | None = None
    cost: float = 0.0
    visible: float | None = None
    joints: tuple = field(default=(), repr=False, compare=False)
    tool_poses: tuple = field(default=(), repr=False, compare=False)
    torso: str | None = None
    push: str | None = None
    grasp_candidate: Any = field(default=None, repr=False, compare=False)
    arrival: tuple = field(default=(), repr=False, compare=False)

    def __iter__(self) -> Any:  # (x, y, yaw) like any base pose
        return iter((self.x, self.y, self.yaw))


class Spot(tuple):
    """A point (x, y, z) [m, map] where an object can be put: its centre when it stands there.

    Unpacks as a 3-tuple; `surface` names the surface, `container` the container it lies in
    (or None), `type` the object type it was found for (or None), `cost` its rank.
    """

    surface: str
    container: str | None
    type: str | None
    cost: float

    def __new__(
        cls,
        x: float,
        y: float,
        z: float,
        surface: str,
        container: str | None = None,
        type: str | None = None,
        cost: float = 0.0,
    ) -> Spot:
        spot = super().__new__(cls, (float(x), float(y), float(z)))
        spot.surface, spot.container, spot.type, spot.cost = surface, container, type, cost
        return spot

    @property
    def position(self) -> tuple[float, float, float]:
        return (self[0], self[1], self[2])

    def __repr__(self) -> str:
        return f"Spot(({self[0]:.3f}, {self[1]:.3f}, {self[2]:.3f}) on {self.surface!r})"
