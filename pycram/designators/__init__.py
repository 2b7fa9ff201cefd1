"""The designators layer: symbolic descriptions of motions, objects, locations and actions,
resolved lazily into solutions (thesis ch. 3.3), one module per kind, and the resolver sets that
say which resolvers are active (:mod:`pycram.designators.resolvers`).

May import: :mod:`pycram.core` and the standard library. Performing a designator is execution's
(:func:`pycram.execution.perform.perform`); :mod:`pycram.designator` is the thesis' import path
for both.
"""

from pycram.designators.action import ActionDesignator, plan_for
from pycram.designators.core import (
    Designator,
    DesignatorError,
    GeneratorList,
    LazyDesignator,
    NoSolutionError,
    PropertyError,
    ResolverError,
    UnknownKindError,
)
from pycram.designators.location import LocationDesignator
from pycram.designators.motion import MotionDesignator
from pycram.designators.motion_types import GoalOutsideEnvironment, MotionKey, MotionPropertyError, MotionType
from pycram.designators.object import Belief, BelievedObject, ObjectDesignator

__all__ = [
    "ActionDesignator",
    "Belief",
    "BelievedObject",
    "Designator",
    "DesignatorError",
    "GeneratorList",
    "GoalOutsideEnvironment",
    "LazyDesignator",
    "LocationDesignator",
    "MotionDesignator",
    "MotionKey",
    "MotionPropertyError",
    "MotionType",
    "NoSolutionError",
    "ObjectDesignator",
    "PropertyError",
    "ResolverError",
    "UnknownKindError",
    "plan_for",
]
