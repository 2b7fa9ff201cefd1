"""The thesis' ``Designator`` API (ch. 3.3) and the lazy, cached resolution shared by all kinds.

A designator is an immutable list of ``(key, value)`` properties describing an entity (a motion,
an object, a location, an action). Designators describing the same entity over time are *equated*
into a chain (``first`` ... ``current``); resolving (``reference``) yields a concrete solution.

Guarantees
----------
- Properties are validated on construction: anything that is not a sequence of pairs raises
  :class:`PropertyError`. They never change afterwards (``copy`` makes a new designator).
- ``reference()`` is thread-safe: concurrent callers on one designator run ``_reference`` once;
  the others wait (evaporably, through the runtime's ``wait_until`` when available) and receive
  the same solution. Repeated calls return the same solution.
- Resolution is lazy: resolvers and generators are advanced only as far as the solutions
  requested so far (:class:`GeneratorList`).
- A broken resolver (raises, returns a non-iterable, a mapping, or ``None`` as a solution)
  surfaces as :class:`ResolverError` naming the designator and the resolver, never as a silent
  empty or wrong result; a designator without solutions raises :class:`NoSolutionError` naming
  its properties and the resolvers tried.
- A resolver that knows *why* a designator has no solution raises
  ``NoSolutionError(reason, designator=d)`` itself: it reaches the caller unchanged and ends the
  resolution (no later resolver is asked). Likewise a :class:`DesignatorError` a resolver raises
  about ``d`` itself (``error.designator is d``, e.g. an invalid property) is not wrapped.
- Malformed constraints given to ``check_constraints`` / ``make_dictionary`` (a tuple that is not
  a pair) raise :class:`PropertyError`.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from inspect import isgenerator, isgeneratorfunction
from typing import Any

from pycram.core.runtime.lockstep import Condition

__all__ = [
    "Designator",
    "DesignatorError",
    "PropertyError",
    "ResolverError",
    "NoSolutionError",
    "UnknownKindError",
    "GeneratorList",
    "LazyDesignator",
    "Property",
]

logger = logging.getLogger("pycram.designator")

#: One designator property: a ``(key, value)`` pair.
Property = tuple[Any, Any]


# --------------------------------------------------------------------------- errors


class DesignatorError(Exception):
    """Base class of all designator errors (thesis name); also "not resolvable"."""


class PropertyError(DesignatorError, ValueError):
    """The properties given to a designator are malformed (not a sequence of pairs...)."""


class UnknownKindError(DesignatorError, TypeError):
    """An object was used as a designator of a kind the operation does not know."""


class ResolverError(DesignatorError):
    """A resolver (or generator, validator) failed: it raised or returned something unusable.

    Attributes: ``designator``, ``resolver`` and ``cause`` (also chained as ``__cause__``).
    """

    def __init__(
        self, message: str, designator: Any = None, resolver: Any = None, cause: BaseException | None = None
    ) -> None:
        super().__init__(message)
        self.designator = designator
        self.resolver = resolver
        self.cause = cause


class NoSolutionError(DesignatorError):
    """The designator has no (more) solutions. Attributes: ``designator``, ``resolvers``."""

    def __init__(self, message: str, designator: Any = None, resolvers: Sequence[Any] = ()) -> None:
        super().__init__(message)
        self.designator = designator
        self.resolvers = list(resolvers)


def callable_name(f: Any) -> str:
    """A readable name for a resolver, generator or validator in error messages."""
    module = getattr(f, "__module__", None)
    name = getattr(f, "__qualname__", None) or getattr(f, "__name__", None)
    if name is None:
        return repr(f)
    return f"{module}.{name}" if module and module != "builtins" else name


# --------------------------------------------------------------------------- helpers


def _now() -> float:
    """Current time [s] of the active pycram clock."""
    from pycram.core.runtime import current_clock

    return current_clock().now()


def _wait(condition: threading.Condition, predicate: Callable[[], bool]) -> None:
    """Block on ``condition`` until ``predicate()`` (evaluated with it held); evaporable."""
    from pycram.core.runtime import wait_until

    wait_until(condition, predicate)


def normalize_properties(properties: Any, kwargs: Mapping[str, Any], owner: str) -> list[Property]:
    """Validate and normalize ``properties`` (pairs, or a mapping) plus keyword properties.

    Keyword properties are appended after positional ones; a keyword repeating a key of
    ``properties`` overwrites it (same rule as :meth:`Designator.copy`).
    """
    result: list[Property] = []
    if properties is None:
        pass
    elif isinstance(properties, Mapping):
        result.extend(properties.items())
    elif isinstance(properties, (str, bytes)) or not isinstance(properties, Iterable):
        raise PropertyError(f"{owner}: properties must be a list of (key, value) pairs, got {properties!r}")
    else:
        for index, prop in enumerate(properties):
            if not isinstance(prop, (tuple, list)) or len(prop) != 2:
                raise PropertyError(f"{owner}: property #{index} {prop!r} is not a (key, value) pair in {properties!r}")
            if isinstance(prop[0], (list, dict, set)):
                raise PropertyError(f"{owner}: property key {prop[0]!r} is not hashable")
            result.append((prop[0], prop[1]))
    for key, value in kwargs.items():
        _merge(result, key, value)
    return result


def _merge(properties: list[Property], key: Any, value: Any) -> None:
    replaced = False
    for i, (k, _) in enumerate(properties):
        if k == key:
            properties[i] = (key, value)
            replaced = True
    if not replaced:
        properties.append((key, value))


def known_solution(designator: Any) -> Any:
    """The solution of ``designator`` if it was already resolved (is effective), else ``None``.

    Never resolves and never blocks (for reporting, e.g. :mod:`pycram.core.events`).
    """
    if isinstance(designator, Designator) and designator._effective:
        return designator._data
    return None


def _short(value: Any, limit: int = 60) -> str:
    text = repr(value)
    return text if len(text) <= limit else text[: limit - 3] + "..."


# --------------------------------------------------------------------------- Designator


class Designator:
    """A symbolic description of an entity as ``(key, value)`` pairs (thesis ch. 3.3).

    ``Designator(properties, parent=None)`` with ``properties`` a list of pairs; keyword
    properties are a convenience: ``Designator(shape='round')`` equals
    ``Designator([('shape', 'round')])``. ``parent`` equates the new designator to an existing one.

    Only ``timestamp`` is a public attribute; everything else is reached through methods.
    Subclasses implement resolution by overriding ``_reference`` (called serialized by
    :meth:`reference`) and ``next_solution``.
    """

    def __init__(self, properties: Any = None, parent: Designator | None = None, **kwargs: Any) -> None:
        self._mutex = Condition(threading.RLock())
        self._resolving: int | None = None  # ident of the thread running _reference
        self._parent: Designator | None = None
        self._successor: Designator | None = None
        self._effective = False
        self._data: Any = None
        self.timestamp: float | None = None
        self._properties: list[Property] = normalize_properties(properties, kwargs, type(self).__name__)
        if parent is not None:
            if not isinstance(parent, Designator):
                raise UnknownKindError(f"{type(self).__name__}: parent must be a Designator, got {parent!r}")
            self.equate(parent)

    # -- chain ----------------------------------------------------------------------------

    def equate(self, parent: Designator) -> None:
        """Equate this designator with ``parent``: both describe the same entity afterwards.

        This designator (with any ancestors it already has) is appended after the most recent
        designator of ``parent``'s chain. Does nothing if they are already equal.
        """
        if not isinstance(parent, Designator):
            raise UnknownKindError(f"cannot equate {self!r} with non-designator {parent!r}")
        with _chain_lock:
            if self.equal(parent):
                return
            youngest_parent = parent.current()
            first_parent = parent.first()
            if self._parent is not None:
                # Splice parent's chain between our former parent and us (thesis semantics).
                first_parent._parent = self._parent
                first_parent._parent._successor = first_parent
            self._parent = youngest_parent
            youngest_parent._successor = self

    def equal(self, other: Designator) -> bool:
        """``True`` iff both designators are in the same chain (same first ancestor)."""
        return other.first() is self.first()

    def first(self) -> Designator:
        """The first ancestor of the chain of equated designators."""
        desig = self
        while desig._parent is not None:
            desig = desig._parent
        return desig

    def current(self) -> Designator:
        """The most recent designator of the chain of equated designators."""
        desig = self
        while desig._successor is not None:
            desig = desig._successor
        return desig

    def newest_effective(self) -> Designator | None:
        """The most recent effective designator of the chain, or ``None`` if there is none."""
        desig: Designator | None = self.current()
        while desig is not None and not desig._effective:
            desig = desig._parent
        return desig

    # -- properties -----------------------------------------------------------------------

    @property
    def properties(self) -> list[Property]:
        """A copy of the properties as a list of ``(key, value)`` pairs."""
        return list(self._properties)

    def prop_value(self, key: Any) -> Any:
        """The value of the first property with ``key``, or ``None``."""
        for k, v in self._properties:
            if k == key:
                return v
        return None

    def check_constraints(self, properties: Iterable[Any]) -> bool:
        """``True`` iff every constraint holds.

        A tuple ``(key, value)`` requires the property to equal ``value``; any other element is a
        key whose value must not be ``None``. A tuple of another length raises
        :class:`PropertyError`.
        """
        for prop in properties:
            if type(prop) == tuple:  # noqa: E721 - thesis semantics: only tuples are pairs
                key, value = self._constraint_pair(prop, "check_constraints")
                if self.prop_value(key) != value:
                    return False
            elif self.prop_value(prop) is None:
                return False
        return True

    def _constraint_pair(self, prop: tuple[Any, ...], caller: str) -> tuple[Any, Any]:
        if len(prop) != 2:
            raise PropertyError(f"{caller} on {self!r}: {_short(prop)} is neither a key nor a (key, value) pair")
        return prop

    def make_dictionary(self, properties: Iterable[Any]) -> dict[Any, Any]:
        """A dict of the listed properties: tuples are taken literally, keys are looked up."""
        dictionary: dict[Any, Any] = {}
        for prop in properties:
            if type(prop) == tuple:  # noqa: E721
                key, value = self._constraint_pair(prop, "make_dictionary")
                dictionary[key] = value
            else:
                dictionary[prop] = self.prop_value(prop)
        return dictionary

    # -- new designators ------------------------------------------------------------------

    def copy(self, new_properties: Any = None, **kwargs: Any) -> Designator:
        """A new, unequated designator of the same class with the same properties.

        ``new_properties`` (pairs) and keyword properties are dominant: an existing key is
        overwritten, a new key appended.
        """
        properties = list(self._properties)
        for key, value in normalize_properties(new_properties, kwargs, type(self).__name__):
            _merge(properties, key, value)
        return self.__class__(properties)

    def make_effective(self, properties: Any = None, data: Any = None, timestamp: float | None = None) -> Designator:
        """A new effective designator of the same class holding the low-level ``data``.

        Properties default to this designator's; the timestamp to the active clock's now.
        Like the thesis, the new designator is not equated to this one.
        """
        if properties is None:
            properties = self._properties
        desig = self.__class__(properties)
        desig._effective = True
        desig._data = data
        desig.timestamp = _now() if timestamp is None else timestamp
        return desig

    # -- resolution -----------------------------------------------------------------------

    def _reference(self) -> Any:
        """Resolve; override in subclasses. Default: the data of an effective designator."""
        if self._effective:
            return self._data
        raise DesignatorError(f"{self!r} is not effective and {type(self).__name__} has no resolution")

    def reference(self) -> Any:
        """Resolve this designator to its low-level solution (always the same one).

        Thread-safe: ``_reference`` runs in one thread at a time; concurrent callers wait
        (evaporable) and then get the cached solution. A resolver that calls ``reference`` on the
        designator it is resolving gets a :class:`ResolverError` instead of a deadlock.
        Raises :class:`DesignatorError` (or a subclass) when it cannot be resolved.
        """
        me = threading.get_ident()
        with self._mutex:
            if self._resolving == me:
                raise ResolverError(
                    f"{self!r}: a resolver called reference() on the designator it is resolving", designator=self
                )

        def claim() -> bool:  # evaluated under self._mutex: atomic check-and-set
            if self._resolving is None:
                self._resolving = me
                return True
            return False

        _wait(self._mutex, claim)
        try:
            ret = self._reference()
        finally:
            with self._mutex:
                self._resolving = None
                self._mutex.notify_all()
        self._effective = True
        if self.timestamp is None:
            self.timestamp = _now()
        return ret

    def next_solution(self) -> Designator | None:
        """A new designator equated to this one for the next solution, or ``None``."""
        return None

    def solutions(self, from_root: Any = None) -> Iterator[Any]:
        """Generator of all solutions of this designator (from the chain's first if
        ``from_root`` is not ``None``), following ``next_solution``.

        Designators that cannot be referenced are skipped (thesis); a broken resolver
        (:class:`ResolverError`) propagates.
        """
        desig: Designator | None = self.first() if from_root is not None else self

        def generator(desig: Designator | None) -> Iterator[Any]:
            while desig is not None:
                try:
                    yield desig.reference()
                except ResolverError:
                    raise
                except DesignatorError:
                    pass
                desig = desig.next_solution()

        return generator(desig)

    # -- display --------------------------------------------------------------------------

    def __repr__(self) -> str:
        props = ", ".join(f"({_short(k)}, {_short(v)})" for k, v in self._properties)
        return f"{type(self).__name__}([{props}])"


_chain_lock = threading.RLock()  # serializes equate() so concurrent chain edits stay consistent


# --------------------------------------------------------------------------- lazy solutions


class GeneratorList:
    """A list filled on demand from a generator (thesis helper), safe for concurrent use.

    ``get(i)`` advances the generator until ``i`` elements exist and raises ``StopIteration``
    when it is exhausted first. An exception raised by the generator is remembered and re-raised
    by every later ``get`` beyond the cached elements (a generator cannot be resumed after
    raising). An interruption by a ``BaseException`` (e.g. evaporation) sets ``interrupted``;
    later ``get`` beyond the cached elements raise :class:`DesignatorError` (a
    :class:`LazyDesignator` then starts a fresh resolution instead).
    """

    def __init__(self, generator: Any) -> None:
        if isgeneratorfunction(generator):
            generator = generator()
        self._generator = generator
        self._generated: list[Any] = []
        self._lock = threading.RLock()
        self._done = False
        self._error: BaseException | None = None
        self._advancing = False
        self.interrupted = False

    def get(self, index: int = 0) -> Any:
        with self._lock:
            while len(self._generated) <= index:
                if self._error is not None:
                    raise self._error
                if self.interrupted:
                    raise DesignatorError("resolution was interrupted (evaporated)")
                if self._done:
                    raise StopIteration
                if self._advancing:
                    raise ResolverError("a resolver re-entered the resolution it is part of")
                self._advancing = True
                try:
                    self._generated.append(next(self._generator))
                except StopIteration:
                    self._done = True
                    raise
                except Exception as e:
                    self._error = e
                    raise
                except BaseException:
                    self.interrupted = True
                    raise
                finally:
                    self._advancing = False
            return self._generated[index]

    def has(self, index: int) -> bool:
        """``True`` iff an element exists at ``index`` (generating up to it)."""
        try:
            self.get(index)
            return True
        except StopIteration:
            return False

    def cached(self, index: int) -> bool:
        """``True`` iff the element at ``index`` was already generated."""
        with self._lock:
            return index < len(self._generated)

    @property
    def generated(self) -> list[Any]:
        """The elements generated so far (a copy)."""
        with self._lock:
            return list(self._generated)


def expand_solutions(designator: Any, resolver: Any, result: Any) -> Iterator[Any]:
    """Yield the solutions in a resolver's ``result``: items may be plain solutions,
    generators or generator functions (thesis).

    Failures become :class:`ResolverError`: a resolver that raises, a result that is not a list
    of solutions (a non-iterable, a string, a mapping -- whose iteration would yield its keys),
    and a ``None`` solution. A :class:`DesignatorError` about ``designator`` itself (e.g. a
    :class:`NoSolutionError` saying why there is none) passes unchanged.
    """
    name = callable_name(resolver)
    if result is None:
        return
    if isgeneratorfunction(result):
        result = result()
    if isinstance(result, (str, bytes, Mapping)) or not isinstance(result, Iterable):
        kind = "a mapping" if isinstance(result, Mapping) else "a non-iterable"
        raise ResolverError(
            f"resolver {name} returned {kind} {_short(result)} for {designator!r}; "
            f"resolvers must return a list of solutions (wrap a single solution in a list)",
            designator=designator,
            resolver=resolver,
        )
    iterator = iter(result)
    while True:
        try:
            solution = next(iterator)
        except StopIteration:
            return
        except Exception as e:
            _reraise_own(designator, e)
            raise ResolverError(
                f"resolver {name} failed while resolving {designator!r}: {e!r}",
                designator=designator,
                resolver=resolver,
                cause=e,
            ) from e
        if isgeneratorfunction(solution):
            solution = solution()
        if isgenerator(solution):
            while True:
                try:
                    item = next(solution)
                except StopIteration:
                    break
                except Exception as e:
                    _reraise_own(designator, e)
                    raise ResolverError(
                        f"a solution generator of resolver {name} failed while resolving {designator!r}: {e!r}",
                        designator=designator,
                        resolver=resolver,
                        cause=e,
                    ) from e
                yield _not_none(designator, resolver, item)
        else:
            yield _not_none(designator, resolver, solution)


def _not_none(designator: Any, resolver: Any, solution: Any) -> Any:
    if solution is None:
        raise ResolverError(
            f"resolver {callable_name(resolver)} gave None as a solution of {designator!r}; "
            f"a resolver with nothing to offer returns None or an empty list",
            designator=designator,
            resolver=resolver,
        )
    return solution


def _reraise_own(designator: Any, error: BaseException) -> None:
    """Re-raise ``error`` if it is a designator error about ``designator`` itself (a resolver
    that says why there is no solution, or which property is wrong): it needs no wrapping."""
    if isinstance(error, DesignatorError) and getattr(error, "designator", None) is designator:
        raise error


def call_resolver(designator: Any, resolver: Any, *args: Any) -> Any:
    """Call ``resolver(designator, *args)``, turning an exception into :class:`ResolverError`.

    A :class:`DesignatorError` whose ``designator`` is ``designator`` (a resolver's own
    :class:`NoSolutionError` or property error about it) passes unchanged.
    """
    try:
        return resolver(designator, *args)
    except Exception as e:
        _reraise_own(designator, e)
        raise ResolverError(
            f"resolver {callable_name(resolver)} failed while resolving {designator!r}: {e!r}",
            designator=designator,
            resolver=resolver,
            cause=e,
        ) from e


class LazyDesignator(Designator):
    """A designator whose solutions come lazily from :meth:`_generate` (thesis' motion
    designator resolution, generalized to every kind).

    Subclasses implement ``_generate()`` (a generator of solutions) and may override
    ``_resolvers_for_message()``. Solutions are cached in a :class:`GeneratorList` shared by all
    designators of one ``next_solution`` chain; each designator holds the index of its solution.
    """

    #: Noun used in error messages, e.g. "motion designator".
    kind_name = "designator"

    def __init__(self, properties: Any = None, parent: Designator | None = None, **kwargs: Any) -> None:
        self._solutions: GeneratorList | None = None
        self._index = 0
        super().__init__(properties, parent, **kwargs)

    def _generate(self) -> Iterator[Any]:
        raise NotImplementedError

    def _resolvers_for_message(self) -> list[Any]:
        return []

    def _no_solution_message(self) -> str:
        names = [callable_name(r) for r in self._resolvers_for_message()]
        from pycram.designators.resolvers import describe_active_robot

        which = "no" if self._index == 0 else f"no solution #{self._index} (only {self._index})"
        return (
            f"Cannot resolve {self.kind_name} {self!r}: {which} solutions "
            f"from resolvers {names} ({describe_active_robot()})"
        )

    def _reference(self) -> Any:
        if self._effective and self._solutions is None:
            return self._data  # made effective by hand (make_effective)
        if self._solutions is None or (self._solutions.interrupted and not self._solutions.cached(self._index)):
            # first resolution, or the previous one was evaporated midway: resolve afresh
            self._solutions = GeneratorList(self._generate)
        if self._effective:
            return self._data
        try:
            self._data = self._solutions.get(self._index)
        except StopIteration:
            raise NoSolutionError(
                self._no_solution_message(), designator=self, resolvers=self._resolvers_for_message()
            ) from None
        return self._data

    def next_solution(self) -> LazyDesignator | None:
        """A new designator, equated to this one, for the next solution; ``None`` if none.

        Raises :class:`ResolverError` when a resolver fails while looking for the next solution.
        """
        try:
            self.reference()
        except ResolverError:
            raise
        except DesignatorError:
            pass
        try:
            more = self._solutions is not None and self._solutions.has(self._index + 1)
        except NoSolutionError:  # a resolver said there are no more, and why
            return None
        if more:
            desig = self.__class__(self._properties, self)
            desig._solutions = self._solutions
            desig._index = self._index + 1
            return desig
        return None
