"""Action designators: high-level actions that resolve to plans.

``ActionDesignator([('type', 'fetching'), ('object', cup)])`` resolves through action resolvers --
the active robot's ``action_resolvers``, the active world's, then the global
``ActionDesignator.resolvers`` -- each ``f(designator) -> plan | iterable of plans | None``. A plan
is a function ``plan(designator)``; :func:`pycram.designator.perform` runs it as a task of the
task tree and returns its result.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from typing import Any, ClassVar

from pycram.designators.core import (
    LazyDesignator,
    ResolverError,
    _short,
    call_resolver,
    callable_name,
    expand_solutions,
)

__all__ = ["ActionDesignator", "plan_for"]


class ActionDesignator(LazyDesignator):
    """An action such as fetching or placing; its solutions are plan functions."""

    resolvers: ClassVar[list[Callable[[ActionDesignator], Any]]] = []
    kind_name = "action designator"

    def _current_resolvers(self) -> list[Any]:
        from pycram.designators.resolvers import gather

        return gather("action_resolvers", ActionDesignator.resolvers)

    def _resolvers_for_message(self) -> list[Any]:
        return self._current_resolvers()

    def _generate(self) -> Iterator[Any]:
        for resolver in self._current_resolvers():
            result = call_resolver(self, resolver)
            if callable(result):
                result = [result]
            for plan in expand_solutions(self, resolver, result):
                if not callable(plan):
                    raise ResolverError(
                        f"action resolver {callable_name(resolver)} produced {_short(plan)} for "
                        f"{self!r}; plans must be callables plan(designator)",
                        designator=self,
                        resolver=resolver,
                    )
                yield plan


def plan_for(action_type: str, plan: Callable[[ActionDesignator], Any]) -> Callable[[ActionDesignator], Any]:
    """An action resolver returning ``plan`` for designators with ``('type', action_type)``.

    Example: ``robot.action_resolvers.append(plan_for('fetching', fetch))``.
    """

    def resolver(designator: ActionDesignator) -> Any:
        if designator.check_constraints([("type", action_type)]):
            return plan
        return None

    resolver.__qualname__ = f"plan_for({action_type!r}, {callable_name(plan)})"
    return resolver
