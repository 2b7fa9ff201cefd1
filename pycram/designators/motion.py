"""Motion designators (thesis ch. 3.3): descriptions of motions for process modules."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from typing import Any, ClassVar

from pycram.designators.core import LazyDesignator, call_resolver, expand_solutions
from pycram.designators.motion_types import active_motion_types, check_motion, describe_known_types

__all__ = ["MotionDesignator"]


class MotionDesignator(LazyDesignator):
    """A motion, e.g. ``MotionDesignator([('type', 'moving'), ('pose', p)])``.

    ``MotionDesignator.resolvers`` is the thesis' global list of resolvers: functions
    ``f(designator) -> list`` whose items are solutions, generators or generator functions
    producing solutions. The active robot's ``motion_resolvers`` (then the active world's) are
    asked before the global list (see :mod:`pycram.robot`); the set is fixed at the first
    ``reference()``. Solutions are produced lazily and cached; ``reference()`` always returns the
    same solution, ``next_solution()`` an equated designator for the next one.

    When the active robot declares its ``motion_types``, resolution first checks the designator
    against them (:func:`pycram.designators.motion_types.check_motion`): a missing, misspelled or
    invalid key raises :class:`~pycram.designators.motion_types.MotionPropertyError`.
    """

    resolvers: ClassVar[list[Callable[[MotionDesignator], Any]]] = []
    kind_name = "motion designator"

    def _resolvers_for_message(self) -> list[Any]:
        return getattr(self, "_used_resolvers", None) or self._current_resolvers()

    def _current_resolvers(self) -> list[Any]:
        from pycram.designators.resolvers import gather

        return gather("motion_resolvers", MotionDesignator.resolvers)

    def _no_solution_message(self) -> str:
        message = super()._no_solution_message()
        types = active_motion_types()
        if types and str(self.prop_value("type")) not in {str(t) for t in types}:
            message += f"; {describe_known_types(types, self.prop_value('type'))}"
        return message

    def _generate(self) -> Iterator[Any]:
        check_motion(self)  # the active vocabulary, at resolution time (raises PropertyError)
        self._used_resolvers = resolvers = self._current_resolvers()
        for resolver in resolvers:
            result = call_resolver(self, resolver)
            yield from expand_solutions(self, resolver, result)
