"""Object designators: objects described by properties, resolved against beliefs/perception.

``ObjectDesignator([('type', 'cup'), ('color', 'red'), ('at', location)])`` describes every red
cup at ``location``. It resolves through object resolvers -- the active robot's
``object_resolvers``, the active world's, then the global ``ObjectDesignator.resolvers`` -- each a
function ``f(designator) -> iterable of candidate objects``. Candidates are filtered with
:meth:`ObjectDesignator.matches`, so a resolver may simply return everything it believes in.

:class:`Belief` is a small thread-safe belief state (what the robot currently believes is in the
world) whose :meth:`Belief.resolver` plugs into those lists.

Guarantees: matches come in the order the resolvers produce them (insertion order for a
``Belief``), the same objects in the same order on every resolution of an equal description;
``next_solution()`` walks them; :meth:`ObjectDesignator.perceived` creates an effective designator
equated to the description.
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass, field
from typing import Any, ClassVar

from pycram.designators.core import Designator, LazyDesignator, _now, call_resolver, expand_solutions

__all__ = ["ObjectDesignator", "BelievedObject", "Belief"]

_MISSING = object()


@dataclass(eq=False)
class BelievedObject:
    """An object the robot believes in: a ``name``, a ``type``, a ``pose`` and free properties.

    ``get(key)`` reads ``name``/``type``/``pose`` or a free property (``None`` if absent).
    Compared by identity; the pose may be updated in place by perception.
    """

    name: str
    type: str
    pose: Any = None
    properties: dict[str, Any] = field(default_factory=dict)

    def get(self, key: str, default: Any = None) -> Any:
        if key in ("name", "type", "pose"):
            return getattr(self, key)
        return self.properties.get(key, default)


class Belief:
    """A thread-safe, insertion-ordered set of :class:`BelievedObject` (the robot's beliefs)."""

    def __init__(self, objects: Iterable[BelievedObject] = ()) -> None:
        self._lock = threading.Lock()
        self._objects: dict[str, BelievedObject] = {}
        for obj in objects:
            self.add(obj)

    def add(self, obj: BelievedObject) -> BelievedObject:
        """Add (or replace, keeping its position) the object with ``obj.name``; returns it."""
        with self._lock:
            self._objects[obj.name] = obj
        return obj

    def remove(self, name: str) -> None:
        with self._lock:
            self._objects.pop(name, None)

    def objects(self) -> list[BelievedObject]:
        """A snapshot of the believed objects in insertion order."""
        with self._lock:
            return list(self._objects.values())

    def resolver(self, designator: ObjectDesignator) -> list[BelievedObject]:
        """Object resolver: every believed object (the designator filters them)."""
        return self.objects()


def _object_value(obj: Any, key: Any) -> Any:
    """The value of property ``key`` of a candidate object (``_MISSING`` when it has none)."""
    if isinstance(obj, BelievedObject):
        if key in ("name", "type", "pose"):
            return getattr(obj, key)
        return obj.properties.get(key, _MISSING)
    if isinstance(obj, dict):
        return obj.get(key, _MISSING)
    return getattr(obj, key, _MISSING)


def _name_of(value: Any) -> Any:
    """The ``name`` of a described thing (a surface, a container...), or ``_MISSING``."""
    name = getattr(value, "name", _MISSING)
    return name if isinstance(name, str) else _MISSING


class ObjectDesignator(LazyDesignator):
    """An object described by properties (``type``, ``color``, ``name``, ``at`` a location...).

    A candidate object matches when, for every property ``(key, value)``:

    - ``value`` is a :class:`LocationDesignator` (e.g. ``('at', loc)``): the object's pose lies
      in it, ``value.contains(pose)`` (a validator affirms it and none rejects it; when no
      validator applies to the location this raises :class:`DesignatorError` rather than
      matching every object);
    - ``value`` is another designator: the object's property ``key`` is that designator's
      resolved solution (or the designator itself);
    - ``value`` is callable: ``value(object_value)`` is true (predicates, e.g. on size);
    - otherwise the object's property ``key`` equals ``value``, or names it: ``('on', surface)``
      matches an object whose ``'on'`` is ``surface.name`` (a surface or container of an
      environment description given instead of its name).

    The simulated robots resolve object designators against their belief
    (:class:`pycram.world.belief.BeliefState`): ``type``, ``name`` (the belief's name),
    ``color``, ``on`` (a surface), ``in`` (a container), ``size`` and ``pose`` of what they
    perceived, best match first.
    """

    resolvers: ClassVar[list[Callable[[ObjectDesignator], Any]]] = []
    kind_name = "object designator"

    def _current_resolvers(self) -> list[Any]:
        from pycram.designators.resolvers import gather

        return gather("object_resolvers", ObjectDesignator.resolvers)

    def _resolvers_for_message(self) -> list[Any]:
        return self._current_resolvers()

    def matches(self, obj: Any) -> bool:
        """``True`` iff the candidate ``obj`` satisfies every property of this designator."""
        from pycram.designators.location import LocationDesignator

        for key, value in self._properties:
            if isinstance(value, LocationDesignator):
                pose = _object_value(obj, "pose")
                if pose is _MISSING or not value.contains(pose):
                    return False
                continue
            actual = _object_value(obj, key)
            if actual is _MISSING:
                return False
            if isinstance(value, Designator):
                if actual is value:
                    continue
                if value.current().reference() is not actual:
                    return False
            elif callable(value) and not callable(actual):
                if not value(actual):
                    return False
            elif actual != value and not (isinstance(actual, str) and _name_of(value) == actual):
                return False
        return True

    def _generate(self) -> Iterator[Any]:
        seen: set[int] = set()
        for resolver in self._current_resolvers():
            result = call_resolver(self, resolver)
            for obj in expand_solutions(self, resolver, result):
                if id(obj) in seen or not self.matches(obj):
                    continue
                seen.add(id(obj))
                yield obj

    def perceived(self, data: Any, properties: Any = None, timestamp: float | None = None) -> ObjectDesignator:
        """Record that ``data`` (a perceived object) is the object this describes.

        Returns a new effective designator holding ``data``, equated to this description (so
        ``description.newest_effective()`` and ``description.current()`` return it).
        """
        desig = self.make_effective(properties, data, _now() if timestamp is None else timestamp)
        desig.equate(self)
        return desig  # type: ignore[return-value]
