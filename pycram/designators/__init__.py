"""Designators by kind; :mod:`pycram.designator` is the thesis-compatible import path."""

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
from pycram.designators.perform import perform

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
    "perform",
    "plan_for",
]
