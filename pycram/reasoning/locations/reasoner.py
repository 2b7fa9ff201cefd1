"""Location reasoning: costmaps ranked best-first, candidates validated by prospection.

`LocationReasoner` (this module) resolves the robot- and environment-agnostic location vocabulary:

===================================  ===========================================================
designator                           solutions
===================================  ===========================================================
``('to_reach', t)`` [``('arm', a)``,  `BaseLocation` from which the arm executes the whole grasp
``('grasp', g)``, ``('action',        sequence (pre_grasp, grasp, lift; with ``('action',
'place')``]                           'place')``: pre_place, place, retreat) without collision; it
                                     names the arm and grasp found
``('to_see', t)``                    `BaseLocation` from which the head camera sees ``t``
                                     (at least half of it, unoccluded)
``('to_open', c)`` [``('arm', a)``,   `BaseLocation` from which the arm grasps the handle of the
``('opening', q)``]                   drawer or door ``c`` and follows its opening trajectory
``('to_open', door), ('pushing', s)``  `BaseLocation` from which the hand pushes the door's face
[``('opening', q)``, ``('arm', a)``]  ``s`` (``'inside'``/``'outside'``) along its arc to ``q``
                                     (`pycram.reasoning.locations.doors`; ``push`` names the side)
``('on', s)`` [``('near', o)``,       `Spot`: a free spot on surface ``s`` where an object of that
``('for', type/object)``]             type fits without touching the known objects
``('in', c)`` [same options]         `Spot` inside container ``c`` (its interior surfaces)
===================================  ===========================================================

A target ``t`` is an object designator, a believed object, a named place/surface/container or a
point (see `pycram.reasoning.locations.targets`). Designators with other properties are not ours
(``None``: other generators answer them, e.g. a world's named places).

How: layers over the floor (`pycram.reasoning.locations.costmap`) -- occupancy from the environment's
description inflated by the robot's inscribed radius, a Gaussian reachability ring around the
target from the arm's comfortable reach (robot description), a preference for facing the
furniture squarely, and for ``to_see`` a viewing ring -- are summed, and cells are taken
cheapest first, lazily. Each candidate is checked with prospection (`Prospection.in_collision`,
`reachable` for the IK sequence, `visible`) in the world as it is now; solutions keep
`SPACING` apart, so the next solution is a different place, never a repeat.

Bounded: at most `MAX_CANDIDATES` candidates are checked per designator. When none passes,
`NoSolutionError` says how many were tried and what ruled them out, e.g. ``312 candidates: 280
in collision, 32 unreachable for arm 'left' (out_of_reach 20, collision 12)``.

One module per vocabulary holds its methods (`pycram.reasoning.locations.reach`, ``see``,
``opening``, ``spots``), on the shared search (`pycram.reasoning.locations.search`, ``standing``);
`LocationReasoner` combines them and dispatches a designator to the one that answers it.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Mapping, Sequence
from typing import Any

from pycram.world.environment import Environment

from .opening import OpenVocabulary
from .reach import ReachVocabulary
from .robot_geometry import RobotGeometry
from .search import MAX_CANDIDATES
from .see import SeeVocabulary
from .spots import SpotVocabulary
from .targets import KnownObject

__all__ = ["LocationReasoner", "VOCABULARY"]

#: The keys location reasoning understands; a designator with any other key is left to others.
VOCABULARY = frozenset(
    {"to_reach", "to_see", "to_open", "on", "in", "arm", "grasp", "near", "for", "action", "opening", "pushing"}
)


class LocationReasoner(ReachVocabulary, SeeVocabulary, OpenVocabulary, SpotVocabulary):
    """Resolves the location vocabulary for one robot (see the module docstring).

    `environment()` returns the environment's description, `prospection()` the robot's
    `Prospection` in the current world, `known_objects()` the objects believed to be around
    (`KnownObject`s; used for free spots and to look up targets by name), `container_states()`
    how far each container is believed open (``to_open`` moves the handle on from there). All are
    called at
    resolution time, so answers reflect the world as it is then. `last_costmaps` holds the
    costmaps of the latest base-pose resolution by name (for pictures; not for reasoning).
    """

    def __init__(
        self,
        geometry: RobotGeometry,
        environment: Callable[[], Environment],
        prospection: Callable[[], Any],
        known_objects: Callable[[], Sequence[KnownObject]] = lambda: (),
        max_candidates: int = MAX_CANDIDATES,
        container_states: Callable[[], Mapping[str, float]] = dict,
        holding: Callable[[], Mapping[str, str]] = dict,
    ) -> None:
        self.geometry = geometry
        self.environment = environment
        self.prospection = prospection
        self.known_objects = known_objects
        #: How far each container is believed open [m or rad] (perceived; missing: closed).
        self.container_states = container_states
        #: The objects the robot's grippers hold now (believed), arm -> object name: those arms
        #: arrive at a base pose as they are, with the objects (`arrival_configuration`, `carried`).
        self.holding = holding
        self.max_candidates = max_candidates

    # ------------------------------------------------------------------ entry point
    def generator(self, desig: Any) -> Iterator[Any] | None:
        """The location generator: an iterator of solutions, or None when `desig` is not ours."""
        keys = [k for k, _ in desig.properties]
        if not keys or any(k not in VOCABULARY for k in keys):
            return None
        for key, method in (
            ("to_reach", self.to_reach),
            ("to_see", self.to_see),
            ("to_open", self.to_open),
            ("on", self.on),
            ("in", self.inside),
        ):
            if desig.prop_value(key) is not None:
                return method(desig)
        return None
