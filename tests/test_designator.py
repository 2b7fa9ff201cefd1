"""The thesis' Designator API (ch. 3.3) with its worked examples, and motion designators."""

from __future__ import annotations

import threading

import pytest

from pycram.designator import (
    Designator,
    DesignatorError,
    GeneratorList,
    MotionDesignator,
    NoSolutionError,
    PropertyError,
    ResolverError,
    UnknownKindError,
)
from pycram.testing import CountingGenerator


@pytest.fixture(autouse=True)
def _clean_global_resolvers():
    saved = list(MotionDesignator.resolvers)
    MotionDesignator.resolvers.clear()
    yield
    MotionDesignator.resolvers[:] = saved


location = object()


# --------------------------------------------------------------------------- thesis examples


def test_thesis_check_constraints_example():
    d = Designator([("shape", "round"), ("color", "yellow"), ("at", location)])
    assert d.check_constraints([("shape", "round"), "color"]) is True


def test_thesis_api_names_and_signatures():
    """The thesis' Designator API (ch. 3.3) under its names, with its parameters and defaults."""
    import inspect

    def params(f):
        return [
            (p.name, p.default)
            for p in inspect.signature(f).parameters.values()
            if p.kind is not inspect.Parameter.VAR_KEYWORD
        ]

    empty = inspect.Parameter.empty
    assert params(Designator.__init__) == [("self", empty), ("properties", None), ("parent", None)]
    assert params(Designator.copy) == [("self", empty), ("new_properties", None)]
    assert params(Designator.make_effective) == [
        ("self", empty),
        ("properties", None),
        ("data", None),
        ("timestamp", None),
    ]
    assert params(Designator.solutions) == [("self", empty), ("from_root", None)]
    for name in (
        "equate",
        "equal",
        "first",
        "current",
        "newest_effective",
        "prop_value",
        "check_constraints",
        "make_dictionary",
        "reference",
        "_reference",
        "next_solution",
    ):
        assert callable(getattr(Designator, name)), name
    assert Designator([("a", 1)]).timestamp is None
    assert issubclass(DesignatorError, Exception)
    assert isinstance(MotionDesignator.resolvers, list)
    assert MotionDesignator([("a", 1)]).next_solution() is None  # no resolvers: None, no error


def test_thesis_check_constraints_false_for_the_same_designator():
    d = Designator([("shape", "round"), ("color", "yellow"), ("at", location)])
    assert d.check_constraints([("shape", "square"), "color"]) is False
    assert d.check_constraints([("shape", "round"), "size"]) is False
    assert d.check_constraints([]) is True


def test_thesis_make_dictionary_example():
    d = Designator([("shape", "round"), ("color", "yellow"), ("at", location)])
    assert d.make_dictionary(["shape", ("color", "red"), ("foo", "bar"), "foobar"]) == {
        "shape": "round",
        "color": "red",
        "foo": "bar",
        "foobar": None,
    }


def test_check_constraints_false_cases_from_section_4_2_1():
    d = MotionDesignator([("type", "moving"), ("pose", "p")])
    assert not d.check_constraints([("frame", "map")])
    assert not d.check_constraints(["frame"])
    d2 = d.copy([("frame", "map")])
    assert d2.check_constraints([("frame", "map")])
    assert d2.check_constraints(["frame"])


def test_thesis_pr2_resolver_setting_gripper_solution():
    """Ch. 4.2.1: the PR2 resolver turns a setting_gripper designator into its solution."""

    def pr2_motion_designators(desig):
        solutions = []
        if desig.check_constraints([("type", "moving"), "pose"]):
            if desig.check_constraints(["frame"]):
                solutions.append(desig.make_dictionary([("cmd", "move"), "pose", ("wait", True), "frame"]))
            solutions.append(
                desig.make_dictionary([("cmd", "move"), "pose", ("wait", True), ("frame", "base_footprint")])
            )
        if desig.check_constraints([("type", "setting_gripper"), "gripper", "position"]):
            solutions.append(
                desig.make_dictionary([("cmd", "set_gripper"), "position", ("wait", True), ("max_effort", 25)])
            )
        return solutions

    MotionDesignator.resolvers.append(pr2_motion_designators)
    d = MotionDesignator([("type", "setting_gripper"), ("gripper", "0"), ("position", 1)])
    assert d.reference() == dict([("cmd", "set_gripper"), ("position", 1), ("wait", True), ("max_effort", 25)])
    moving = MotionDesignator([("type", "moving"), ("pose", "p0"), ("frame", "map")])
    assert list(moving.solutions()) == [
        {"cmd": "move", "pose": "p0", "wait": True, "frame": "map"},
        {"cmd": "move", "pose": "p0", "wait": True, "frame": "base_footprint"},
    ]


# --------------------------------------------------------------------------- chains


def test_equate_chain_of_three_generations():
    a = Designator([("type", "cup")])
    b = Designator([("type", "cup"), ("color", "red")], parent=a)
    c = b.make_effective(data="cup-1", timestamp=3.0)
    c.equate(b)
    for d in (a, b, c):
        assert d.first() is a
        assert d.current() is c
        assert d.newest_effective() is c
        assert d.equal(a) and a.equal(d)
    assert c.reference() == "cup-1"
    assert c.timestamp == 3.0
    assert not Designator([("type", "cup")]).equal(a)


def test_newest_effective_skips_later_non_effective_and_none_without_effective():
    a = Designator([("x", 1)])
    assert a.newest_effective() is None
    b = a.make_effective(data=1)
    b.equate(a)
    c = Designator([("x", 1)], parent=b)
    assert a.current() is c
    assert a.newest_effective() is b


def test_equate_is_idempotent_and_merges_chains():
    a = Designator([("k", 1)])
    b = Designator([("k", 2)], parent=a)
    b.equate(a)  # already equal: nothing changes
    assert a.current() is b and b.first() is a
    x = Designator([("k", 3)])
    y = Designator([("k", 4)], parent=x)
    y.equate(b)  # y (which has parent x) joins the chain a-b: x's chain is spliced in
    assert y.equal(a) and x.equal(a)
    assert a.current() is y


def test_copy_overwrites_and_appends_and_is_not_equated():
    d = Designator([("a", 1), ("b", 2)])
    c = d.copy([("b", 3), ("c", 4)])
    assert c.properties == [("a", 1), ("b", 3), ("c", 4)]
    assert d.properties == [("a", 1), ("b", 2)]
    assert type(c) is Designator and not c.equal(d)
    assert d.copy(b=5).properties == [("a", 1), ("b", 5)]


def test_make_effective_defaults():
    d = MotionDesignator([("type", "moving")])
    e = d.make_effective()
    assert isinstance(e, MotionDesignator)
    assert e.properties == d.properties
    assert e.timestamp is not None
    assert e.reference() is None  # effective with data None: no resolvers consulted
    e2 = d.make_effective([("type", "other")], data={"cmd": "x"})
    assert e2.prop_value("type") == "other" and e2.reference() == {"cmd": "x"}
    assert not e2.equal(d)


def test_prop_value_first_match_and_missing():
    d = Designator([("a", 1), ("a", 2)])
    assert d.prop_value("a") == 1
    assert d.prop_value("zzz") is None


def test_keyword_construction_equals_pair_list():
    p = (1.0, 2.0, 0.0)
    keyword, pairs = MotionDesignator(type="moving", pose=p), MotionDesignator([("type", "moving"), ("pose", p)])
    assert keyword.properties == pairs.properties
    assert repr(keyword) == repr(pairs)
    MotionDesignator.resolvers.append(
        lambda d: (
            [d.make_dictionary([("cmd", "move"), "pose"])] if d.check_constraints([("type", "moving"), "pose"]) else []
        )
    )
    assert keyword.reference() == pairs.reference() == {"cmd": "move", "pose": p}
    mixed = Designator([("type", "moving")], pose=p, type="navigating")
    assert mixed.properties == [("type", "navigating"), ("pose", p)]
    assert Designator({"a": 1}).properties == [("a", 1)]


def test_timestamp_set_by_reference():
    d = Designator([("x", 1)]).make_effective(data=5, timestamp=None)
    assert d.timestamp is not None
    plain = MotionDesignator([("x", 1)])
    MotionDesignator.resolvers.append(lambda desig: [7])
    assert plain.timestamp is None
    assert plain.reference() == 7
    assert plain.timestamp is not None


# --------------------------------------------------------------------------- resolution


def test_reference_returns_same_solution_and_next_solution_walks():
    MotionDesignator.resolvers.append(lambda d: [{"n": 1}, {"n": 2}])
    MotionDesignator.resolvers.append(lambda d: [{"n": 3}])
    d = MotionDesignator([("type", "x")])
    first = d.reference()
    assert d.reference() is first
    d2 = d.next_solution()
    assert d2 is not None and d2.equal(d) and d2.properties == d.properties
    assert d2.reference() == {"n": 2}
    d3 = d2.next_solution()
    assert d3.reference() == {"n": 3}
    assert d3.next_solution() is None
    assert d.current() is d3 and d3.first() is d
    assert list(d.solutions()) == [{"n": 1}, {"n": 2}, {"n": 3}]
    assert list(d3.solutions(from_root=True)) == [{"n": 1}, {"n": 2}, {"n": 3}]


def test_solutions_over_generators_generator_functions_and_plain_values():
    def gen_fn():
        yield "g1"
        yield "g2"

    MotionDesignator.resolvers.append(lambda d: ["plain", (x for x in ["gen1", "gen2"]), gen_fn, {"dict": 1}])
    d = MotionDesignator([("type", "x")])
    assert list(d.solutions()) == ["plain", "gen1", "gen2", "g1", "g2", {"dict": 1}]


def test_resolution_is_lazy():
    counter = CountingGenerator(range(100))
    calls = []

    def resolver(d):
        calls.append(d)
        return [counter.generator]

    MotionDesignator.resolvers.append(resolver)
    d = MotionDesignator([("type", "x")])
    assert calls == [] and counter.advanced == 0  # nothing happens before reference()
    assert d.reference() == 0
    assert counter.advanced == 1
    d.reference()
    assert counter.advanced == 1  # cached
    d2 = d.next_solution()  # looks one ahead only
    assert counter.advanced == 2 and d2.reference() == 1 and counter.advanced == 2
    d3 = d2.next_solution()
    assert d3.reference() == 2 and counter.advanced == 3
    solutions = d.solutions()
    assert [next(solutions) for _ in range(4)] == [0, 1, 2, 3]
    assert counter.advanced == 4  # exactly as far as the solutions taken, no further
    assert len(calls) == 1  # the resolver ran once for the whole chain


def test_generator_list_thesis_helper():
    gl = GeneratorList(lambda: (i for i in range(2)))  # not a generator function: a lambda

    # the thesis accepts a generator or a generator function
    def gen():
        yield from "ab"

    gl = GeneratorList(gen)
    assert gl.get(1) == "b" and gl.get(0) == "a"
    assert gl.has(1) and not gl.has(2)
    with pytest.raises(StopIteration):
        gl.get(5)
    gl2 = GeneratorList(x for x in [1])
    assert gl2.get() == 1


def test_no_solution_error_names_properties_and_resolvers():
    def pr2_resolver(d):
        return []

    MotionDesignator.resolvers.append(pr2_resolver)
    d = MotionDesignator([("type", "flying"), ("height", 3)])
    with pytest.raises(NoSolutionError) as info:
        d.reference()
    message = str(info.value)
    assert "('type', 'flying')" in message and "('height', 3)" in message
    assert "pr2_resolver" in message
    assert isinstance(info.value, DesignatorError)
    assert d.next_solution() is None
    assert list(d.solutions()) == []


def test_unresolvable_without_any_resolver():
    with pytest.raises(DesignatorError, match="Cannot resolve motion designator"):
        MotionDesignator([("type", "x")]).reference()


def test_base_designator_not_effective_raises():
    with pytest.raises(DesignatorError):
        Designator([("a", 1)]).reference()


# --------------------------------------------------------------------------- bad input


@pytest.mark.parametrize("bad", ["type", [("type",)], [("a", 1, 2)], ["ab"], 42, [42]])
def test_properties_that_are_not_pairs(bad):
    with pytest.raises(PropertyError) as info:
        MotionDesignator(bad)
    assert "MotionDesignator" in str(info.value)
    assert isinstance(info.value, DesignatorError)


def test_resolver_that_raises_is_named():
    def broken_resolver(d):
        raise KeyError("pose")

    MotionDesignator.resolvers.append(broken_resolver)
    d = MotionDesignator([("type", "moving")])
    with pytest.raises(ResolverError) as info:
        d.reference()
    assert "broken_resolver" in str(info.value) and "('type', 'moving')" in str(info.value)
    assert isinstance(info.value.cause, KeyError)
    assert info.value.designator is d and info.value.resolver is broken_resolver
    with pytest.raises(ResolverError):  # remembered, not silently empty
        d.reference()
    with pytest.raises(ResolverError):
        list(d.solutions())


@pytest.mark.parametrize("returned", [42, "abc", object()])
def test_resolver_returning_non_iterable_is_named(returned):
    def int_resolver(d):
        return returned

    MotionDesignator.resolvers.append(int_resolver)
    d = MotionDesignator([("type", "x")])
    with pytest.raises(ResolverError, match="int_resolver.*non-iterable") as info:
        d.reference()
    assert "MotionDesignator([('type', 'x')])" in str(info.value)
    assert info.value.designator is d and info.value.resolver is int_resolver


def test_resolver_returning_a_dict_is_refused_not_resolved_to_its_first_key():
    def dict_resolver(d):
        return {"cmd": "navigate", "pose": (1, 2, 0)}  # meant as one solution

    MotionDesignator.resolvers.append(dict_resolver)
    d = MotionDesignator([("type", "moving")])
    with pytest.raises(ResolverError, match="dict_resolver returned a mapping") as info:
        d.reference()
    assert "wrap a single solution in a list" in str(info.value)
    assert info.value.designator is d and info.value.resolver is dict_resolver


def _yields_none():
    yield None


@pytest.mark.parametrize("returned", [[None], [1, None], [_yields_none]])
def test_none_as_a_solution_is_refused(returned):
    def none_resolver(d):
        return returned

    MotionDesignator.resolvers.append(none_resolver)
    d = MotionDesignator([("type", "x")])
    solutions = []
    with pytest.raises(ResolverError, match="none_resolver gave None as a solution") as info:
        solutions = [d.reference()]
        solutions.append(d.next_solution().reference())
    assert None not in solutions
    assert info.value.resolver is none_resolver


@pytest.mark.parametrize("bad", [("type",), ("type", "moving", "extra"), ()])
def test_malformed_constraint_is_a_property_error(bad):
    d = Designator([("type", "moving")])
    with pytest.raises(PropertyError, match="neither a key nor a .key, value. pair") as info:
        d.check_constraints([bad])
    assert "Designator([('type', 'moving')])" in str(info.value)
    with pytest.raises(PropertyError):
        d.make_dictionary([bad])


def test_resolver_saying_why_there_is_no_solution_reaches_the_caller_unchanged():
    def first(d):
        return ["a"]

    def declining(d):
        raise NoSolutionError("nothing beyond a: the shelf is empty", designator=d)

    MotionDesignator.resolvers.extend([first, declining])
    d = MotionDesignator([("type", "x")])
    assert d.reference() == "a" and list(d.solutions()) == ["a"]
    assert d.next_solution() is None
    MotionDesignator.resolvers[:] = [declining]
    other = MotionDesignator([("type", "x")])
    with pytest.raises(NoSolutionError, match="the shelf is empty") as info:
        other.reference()
    assert not isinstance(info.value, ResolverError) and info.value.designator is other


def test_unknown_kinds_as_parent_or_equate_target():
    with pytest.raises(UnknownKindError, match="parent must be a Designator.*'cup'"):
        MotionDesignator([("type", "x")], parent="cup")
    d = Designator([("type", "x")])
    with pytest.raises(UnknownKindError, match="Designator.*'type', 'x'.*non-designator"):
        d.equate([("type", "x")])
    assert issubclass(UnknownKindError, DesignatorError)


def test_failing_solution_generator_is_named():
    def gen():
        yield 1
        raise RuntimeError("sensor down")

    def gen_resolver(d):
        return [gen]

    MotionDesignator.resolvers.append(gen_resolver)
    d = MotionDesignator([("type", "x")])
    assert d.reference() == 1
    with pytest.raises(ResolverError, match="gen_resolver.*sensor down"):
        d.next_solution()


def test_resolver_reentering_reference_does_not_hang():
    def reentrant(d):
        return [d.reference()]

    MotionDesignator.resolvers.append(reentrant)
    with pytest.raises(ResolverError):
        MotionDesignator([("type", "x")]).reference()


# --------------------------------------------------------------------------- threads


def test_concurrent_reference_resolves_once():
    """16 threads call reference() while the first one is inside the resolver: one resolution."""
    calls = []
    gate = threading.Event()
    entered = threading.Condition()
    callers = [0]

    class CountedDesignator(MotionDesignator):
        def reference(self):
            with entered:
                callers[0] += 1
                entered.notify_all()
            return super().reference()

    def slow_resolver(d):
        with entered:
            calls.append(threading.get_ident())
            entered.notify_all()
        assert gate.wait(5)
        return [object()]

    MotionDesignator.resolvers.append(slow_resolver)
    d = CountedDesignator([("type", "x")])
    results = []
    lock = threading.Lock()

    def worker():
        r = d.reference()
        with lock:
            results.append(r)

    threads = [threading.Thread(target=worker) for _ in range(16)]
    for t in threads:
        t.start()
    with entered:  # all callers are in reference() and one is inside the (held) resolver
        assert entered.wait_for(lambda: callers[0] == 16 and calls, 5)
    gate.set()
    for t in threads:
        t.join(5)
    assert len(calls) == 1
    assert len(results) == 16 and all(r is results[0] for r in results)


def test_concurrent_next_solution_chains_share_cache_safely():
    MotionDesignator.resolvers.append(lambda d: [(i for i in range(300))])
    d = MotionDesignator([("type", "x")])
    out = []

    def walk():
        out.append(list(d.solutions()))

    threads = [threading.Thread(target=walk) for _ in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(10)
    assert out == [list(range(300))] * 4


def test_resolution_interrupted_by_evaporation_restarts_on_next_reference():
    from pycram.fluent import Fluent
    from pycram.language import State, pursue

    ready = Fluent(None)
    entered = Fluent(None)

    def waiting_resolver(d):
        def gen():
            entered.set_value(True)
            ready.wait_for()  # evaporable wait inside resolution
            yield "solution"

        return [gen]

    MotionDesignator.resolvers.append(waiting_resolver)
    d = MotionDesignator([("type", "x")])
    state = pursue(d.reference, lambda: entered.wait_for(5))
    assert state.get_value() is State.SUCCEEDED  # the resolution was evaporated midway
    ready.set_value(True)
    assert d.reference() == "solution"
