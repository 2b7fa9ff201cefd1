"""Failures with meaning, after CRAM's taxonomy: what went wrong, about which designator, why.

Plans catch these by kind (``except ManipulationFailure``, ``except ObjectNotFound``); each
carries the designator it is about (``designator``) and the reason as data (``reason``, a short
machine-readable word such as ``'no_path'`` or ``'closed_on_nothing'``). Stdlib only.

::

    PlanFailure
    ├── MotionFailure              a process module could not execute a motion
    ├── NavigationFailure          the base cannot get where it should
    │   ├── GoalUnreachable        no path, goal occupied, no standing pose
    │   └── PathBlocked            the way is blocked and no other way was found
    ├── ManipulationFailure
    │   ├── ObjectOutOfReach       no standing pose from which an arm reaches the object
    │   ├── GraspFailed            the gripper closed on nothing
    │   ├── ObjectSlipped          the object left the gripper while carried
    │   ├── GripperEmpty           placing, but the gripper holds nothing
    │   └── PlacingFailed          the object does not rest where it was put
    ├── PerceptionFailure
    │   ├── ObjectNotFound         a search did not find it
    │   └── ObjectNotVisible       it should be visible from here but is not
    └── ContainerFailure           a drawer or door
        ├── ContainerStuck         does not move when pulled
        └── HandleMissed           the gripper did not get the handle

An action that gives up after its bounded attempts raises the failure of its last attempt;
``attempts`` lists what every attempt ran into (strings, oldest first).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

__all__ = [
    "PlanFailure",
    "MotionFailure",
    "NavigationFailure",
    "GoalUnreachable",
    "PathBlocked",
    "ManipulationFailure",
    "ObjectOutOfReach",
    "GraspFailed",
    "ObjectSlipped",
    "GripperEmpty",
    "PlacingFailed",
    "PerceptionFailure",
    "ObjectNotFound",
    "ObjectNotVisible",
    "ContainerFailure",
    "ContainerStuck",
    "HandleMissed",
]


class PlanFailure(Exception):
    """Base class of the failures plans raise and handle.

    ``designator``: what it is about (or None); ``reason``: a short word saying why (the class'
    default when not given); ``attempts``: what earlier attempts ran into (oldest first).
    """

    #: The reason when none is given.
    default_reason = "failed"

    def __init__(
        self, message: str, designator: Any = None, reason: str | None = None, attempts: Sequence[str] = ()
    ) -> None:
        super().__init__(message)
        self.designator = designator
        self.reason = reason if reason is not None else self.default_reason
        self.attempts = list(attempts)


class MotionFailure(PlanFailure):
    """A process module could not execute a motion designator (the backend's reason)."""

    default_reason = "motion_failed"


class NavigationFailure(PlanFailure):
    """The base cannot get where it was asked to go."""

    default_reason = "navigation_failed"


class GoalUnreachable(NavigationFailure):
    """No way to the goal: no path, the goal occupied, or no standing pose found."""

    default_reason = "unreachable"


class PathBlocked(NavigationFailure):
    """The way was blocked while driving and no other way got through."""

    default_reason = "blocked"


class ManipulationFailure(PlanFailure):
    """Grasping, holding or putting down an object went wrong."""

    default_reason = "manipulation_failed"


class ObjectOutOfReach(ManipulationFailure):
    """No standing pose from which an arm reaches the object (or the spot to place it)."""

    default_reason = "out_of_reach"


class GraspFailed(ManipulationFailure):
    """The gripper closed on nothing (or could not get into position to grasp)."""

    default_reason = "closed_on_nothing"


class ObjectSlipped(ManipulationFailure):
    """The object left the gripper while it was carried."""

    default_reason = "slipped"


class GripperEmpty(ManipulationFailure):
    """An action needed an object in the gripper, and the gripper holds nothing."""

    default_reason = "gripper_empty"


class PlacingFailed(ManipulationFailure):
    """The object was let go but does not rest where it was put."""

    default_reason = "not_at_target"


class PerceptionFailure(PlanFailure):
    """Perception did not deliver what the plan needed."""

    default_reason = "perception_failed"


class ObjectNotVisible(PerceptionFailure):
    """The object should be visible from where the robot looks, but is not seen."""

    default_reason = "not_visible"


class ObjectNotFound(PerceptionFailure):
    """A search did not find an object matching ``designator``; ``looked`` names every place it
    looked at (in order) and ``skipped`` the places it could not look into, with the reason."""

    default_reason = "not_found"

    def __init__(self, designator: Any, looked: Sequence[str], skipped: Sequence[tuple[str, str]] = ()) -> None:
        self.looked = list(looked)
        self.skipped = list(skipped)
        message = f"no object matching {designator!r} found; looked at: {', '.join(self.looked) or 'nothing'}"
        if self.skipped:
            message += "; could not look into: " + ", ".join(f"{p} ({why})" for p, why in self.skipped)
        super().__init__(message, designator)


class ContainerFailure(PlanFailure):
    """Opening or closing a drawer or door went wrong; ``container`` names it."""

    default_reason = "container_failed"

    def __init__(
        self,
        message: str,
        container: str | None = None,
        designator: Any = None,
        reason: str | None = None,
        attempts: Sequence[str] = (),
    ) -> None:
        super().__init__(message, designator, reason, attempts)
        self.container = container


class ContainerStuck(ContainerFailure):
    """The drawer or door does not move when its handle is pulled."""

    default_reason = "stuck"


class HandleMissed(ContainerFailure):
    """The gripper closed beside the handle."""

    default_reason = "handle_missed"
