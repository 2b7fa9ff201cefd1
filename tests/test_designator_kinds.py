"""Object, location and action designators in small worlds built here, and perform()."""

from __future__ import annotations

import math

import pytest

from pycram.designator import (
    ActionDesignator,
    Belief,
    BelievedObject,
    Designator,
    DesignatorError,
    LocationDesignator,
    MotionDesignator,
    NoSolutionError,
    ObjectDesignator,
    ResolverError,
    UnknownKindError,
    perform,
    plan_for,
)
from pycram.robot import ResolverSet, Robot, current_robot, current_world, use_robot, use_world
from pycram.runtime import current_task


@pytest.fixture(autouse=True)
def _clean_globals():
    lists = [
        MotionDesignator.resolvers,
        ObjectDesignator.resolvers,
        ActionDesignator.resolvers,
        LocationDesignator.generators,
        LocationDesignator.validators,
    ]
    saved = [list(x) for x in lists]
    for x in lists:
        x.clear()
    previous_robot, previous_world = use_robot(None), use_world(None)
    yield
    for x, s in zip(lists, saved):
        x[:] = s
    use_robot(previous_robot)
    use_world(previous_world)


# --------------------------------------------------------------------------- a small kitchen


def make_kitchen() -> tuple[ResolverSet, Belief]:
    """A world with a counter, a table and three cups; 'on' locations are world knowledge."""
    belief = Belief(
        [
            BelievedObject("counter", "counter", (1.0, 0.0, 0.9), {"extent": (0.4, 0.3)}),
            BelievedObject("table", "table", (-1.0, 0.0, 0.7), {"extent": (0.5, 0.5)}),
            BelievedObject("red_cup", "cup", (1.1, 0.1, 0.9), {"color": "red"}),
            BelievedObject("blue_cup", "cup", (-1.2, 0.1, 0.7), {"color": "blue"}),
            BelievedObject("green_cup", "cup", (0.9, -0.2, 0.9), {"color": "green"}),
        ]
    )
    world = ResolverSet("kitchen")
    world.object_resolvers.append(belief.resolver)

    def supporting(desig):
        support = desig.prop_value("on")
        if isinstance(support, Designator):
            support = support.reference()
        return support

    def on_generator(desig):
        if not desig.check_constraints(["on"]):
            return None
        support = supporting(desig)
        (x, y, z), (ex, ey) = support.pose, support.get("extent")

        def grid():
            for i in range(-2, 3):
                for j in range(-2, 3):
                    yield (x + ex * i / 2, y + ey * j / 2, z)

        return [grid]

    def on_validator(desig, pose):
        if not desig.check_constraints(["on"]):
            return None
        support = supporting(desig)
        (x, y, z), (ex, ey) = support.pose, support.get("extent")
        return abs(pose[0] - x) <= ex and abs(pose[1] - y) <= ey and abs(pose[2] - z) < 0.05

    world.location_generators.append(on_generator)
    world.location_validators.append(on_validator)
    return world, belief


def to_reach_generator(desig):
    """Eight base poses around the object, 0.6 m away (a robot-independent generator)."""
    if not desig.check_constraints(["to_reach"]):
        return None
    target = desig.prop_value("to_reach").reference()
    x, y, _ = target.pose
    return [
        ((round(x + 0.6 * math.cos(a * math.pi / 4), 3), round(y + 0.6 * math.sin(a * math.pi / 4), 3), 0.0))
        for a in range(8)
    ]


def make_robot(name: str, reach_side: str) -> Robot:
    """A robot whose validator only accepts base poses on one side (its arm side)."""
    robot = Robot(name)
    robot.location_generators.append(to_reach_generator)

    def reachable(desig, pose):
        if not desig.check_constraints(["to_reach"]):
            return None
        target = desig.prop_value("to_reach").reference()
        dy = pose[1] - target.pose[1]
        return dy < -1e-6 if reach_side == "right" else dy > 1e-6

    robot.location_validators.append(reachable)
    return robot


# --------------------------------------------------------------------------- object designators


def test_object_designator_resolves_against_beliefs_in_stable_order():
    world, _ = make_kitchen()
    with world:
        cups = ObjectDesignator([("type", "cup")])
        assert [o.name for o in cups.solutions()] == ["red_cup", "blue_cup", "green_cup"]
        second = cups.next_solution()
        assert second.reference().name == "blue_cup" and second.equal(cups)
        third = second.next_solution()
        assert third.reference().name == "green_cup" and third.first() is cups
        assert third.next_solution() is None  # walked them all
        assert cups.current() is third
        assert ObjectDesignator(type="cup", color="green").reference().name == "green_cup"
        assert [o.name for o in ObjectDesignator(type="cup").solutions()] == [
            "red_cup",
            "blue_cup",
            "green_cup",
        ]  # same order on every resolution


def test_object_at_location_designator():
    world, _ = make_kitchen()
    with world:
        counter = ObjectDesignator(name="counter")
        on_counter = LocationDesignator([("on", counter)])
        cups = ObjectDesignator([("type", "cup"), ("at", on_counter)])
        assert [o.name for o in cups.solutions()] == ["red_cup", "green_cup"]
        on_table = LocationDesignator([("on", ObjectDesignator(name="table"))])
        assert ObjectDesignator([("type", "cup"), ("at", on_table)]).reference().name == "blue_cup"


def test_object_at_location_without_applicable_validator_is_an_error_not_a_match():
    world, _ = make_kitchen()
    with world:
        somewhere = LocationDesignator([("near", "window")])  # no validator knows 'near'
        cups = ObjectDesignator([("type", "cup"), ("at", somewhere)])
        with pytest.raises(DesignatorError, match="no location validator applies") as info:
            cups.reference()
        assert "('near', 'window')" in str(info.value)


def test_object_designator_predicates_and_missing_properties():
    world, _ = make_kitchen()
    with world:
        high = ObjectDesignator([("type", "cup"), ("pose", lambda p: p[2] > 0.8)])
        assert [o.name for o in high.solutions()] == ["red_cup", "green_cup"]
        with pytest.raises(NoSolutionError, match="'weight'"):
            ObjectDesignator(weight=3).reference()


def test_belief_changes_are_seen_by_new_designators_only():
    world, belief = make_kitchen()
    with world:
        mugs = ObjectDesignator(type="mug")
        with pytest.raises(NoSolutionError):
            mugs.reference()
        belief.add(BelievedObject("mug1", "mug", (0, 0, 0)))
        assert ObjectDesignator(type="mug").reference().name == "mug1"


def test_perceiving_makes_effective_designator_equated_to_description():
    world, belief = make_kitchen()
    description = ObjectDesignator([("type", "cup"), ("color", "red")])
    perceived_cup = BelievedObject("red_cup", "cup", (1.12, 0.1, 0.9), {"color": "red"})
    effective = description.perceived(perceived_cup)
    assert effective.equal(description)
    assert description.newest_effective() is effective
    assert description.current() is effective
    assert effective.reference() is perceived_cup
    assert effective.timestamp is not None
    assert effective.properties == description.properties


def test_global_object_resolvers_still_work():
    _, belief = make_kitchen()
    ObjectDesignator.resolvers.append(belief.resolver)
    assert ObjectDesignator(name="table").reference().type == "table"


# --------------------------------------------------------------------------- location designators


def test_location_generators_and_validators_registered_per_world():
    world, _ = make_kitchen()
    with world:
        on_counter = LocationDesignator([("on", ObjectDesignator(name="counter"))])
        poses = list(on_counter.solutions())
        assert len(poses) == 25 and poses[0] == (0.6, -0.3, 0.9)
        assert on_counter.accepts((1.0, 0.0, 0.9))
        assert not on_counter.accepts((3.0, 0.0, 0.9))


def test_same_location_resolves_differently_on_two_robots():
    world, _ = make_kitchen()
    lefty, righty = make_robot("lefty", "left"), make_robot("righty", "right")
    with world:
        with lefty:
            left_poses = list(LocationDesignator([("to_reach", ObjectDesignator(name="red_cup"))]).solutions())
        with righty:
            right_poses = list(LocationDesignator([("to_reach", ObjectDesignator(name="red_cup"))]).solutions())
    assert len(left_poses) == 3 and len(right_poses) == 3
    assert all(p[1] > 0.1 for p in left_poses) and all(p[1] < 0.1 for p in right_poses)


def to_see_generator(distance):
    """Four base poses ``distance`` [m] around the object (a robot's camera decides how far)."""

    def generator(desig):
        if not desig.check_constraints(["to_see"]):
            return None
        x, y, _ = desig.prop_value("to_see").reference().pose
        return [
            (round(x + dx * distance, 3), round(y + dy * distance, 3), 0.0)
            for dx, dy in ((-1, 0), (0, 1), (1, 0), (0, -1))
        ]

    return generator


def test_to_see_location_per_robot_filtered_by_world_validator():
    world, _ = make_kitchen()

    def inside_walls(desig, pose):  # world knowledge: the kitchen ends at x = 2.0
        return pose[0] < 2.0

    world.location_validators.append(inside_walls)
    short, tall = Robot("short"), Robot("tall")
    short.location_generators.append(to_see_generator(1.0))
    tall.location_generators.append(to_see_generator(2.0))
    with world:
        cup = ObjectDesignator(name="red_cup")  # at (1.1, 0.1)
        with short:
            short_poses = list(LocationDesignator([("to_see", cup)]).solutions())
        with tall:
            tall_poses = list(LocationDesignator([("to_see", cup)]).solutions())
    # one generator per robot, one validator for the world: (2.1, 0.1) / (3.1, 0.1) lie
    # outside the walls
    assert short_poses == [(0.1, 0.1, 0.0), (1.1, 1.1, 0.0), (1.1, -0.9, 0.0)]
    assert tall_poses == [(-0.9, 0.1, 0.0), (1.1, 2.1, 0.0), (1.1, -1.9, 0.0)]


def test_location_without_generator_and_with_all_candidates_rejected():
    with pytest.raises(NoSolutionError, match="location designator"):
        LocationDesignator([("on", "nothing")]).reference()

    def everywhere(desig):
        def forever():
            i = 0
            while True:
                i += 1
                yield (i, 0, 0)

        return [forever]

    LocationDesignator.generators.append(everywhere)
    LocationDesignator.validators.append(lambda d, pose: False)
    old = LocationDesignator.max_rejected
    LocationDesignator.max_rejected = 500
    try:
        with pytest.raises(NoSolutionError, match="gave up after 500"):
            LocationDesignator([("anywhere", True)]).reference()
    finally:
        LocationDesignator.max_rejected = old


def test_location_validator_that_raises_is_named():
    def broken_validator(desig, pose):
        raise ValueError("no map")

    LocationDesignator.generators.append(lambda d: [(0, 0, 0)])
    LocationDesignator.validators.append(broken_validator)
    with pytest.raises(ResolverError, match="broken_validator"):
        LocationDesignator([("x", 1)]).reference()


def test_infinite_generator_is_lazy():
    advanced = []

    def forever(desig):
        def gen():
            i = 0
            while True:
                advanced.append(i)
                yield i
                i += 1

        return [gen]

    LocationDesignator.generators.append(forever)
    LocationDesignator.validators.append(lambda d, pose: pose % 2 == 0)
    d = LocationDesignator([("even", True)])
    assert d.reference() == 0 and len(advanced) == 1
    assert d.next_solution().reference() == 2 and len(advanced) == 3


# --------------------------------------------------------------------------- action designators


def test_action_designator_resolves_to_plan_run_as_task():
    seen = {}

    def fetch(designator):
        task = current_task()
        seen["task"] = task
        seen["object"] = designator.prop_value("object")
        return "fetched"

    ActionDesignator.resolvers.append(plan_for("fetching", fetch))
    parent = current_task()
    assert perform(ActionDesignator([("type", "fetching"), ("object", "cup")])) == "fetched"
    assert seen["object"] == "cup"
    assert seen["task"].name == "perform fetching"
    assert seen["task"].parent is parent
    assert seen["task"].status.get_value().name == "SUCCEEDED"


def test_action_plan_failure_propagates_unchanged_and_task_failed():
    class GraspFailed(Exception):
        pass

    tasks = []

    def grasp(designator):
        tasks.append(current_task())
        raise GraspFailed("slipped")

    robot = Robot("r")
    robot.action_resolvers.append(plan_for("grasping", grasp))
    with robot, pytest.raises(GraspFailed):
        perform(ActionDesignator(type="grasping"))
    assert tasks[0].status.get_value().name == "FAILED"


def test_action_resolution_depends_on_active_robot_and_next_solution_gives_alternatives():
    r1, r2 = Robot("one"), Robot("two")
    r1.action_resolvers.append(lambda d: [lambda d: "one-a", lambda d: "one-b"])
    r2.action_resolvers.append(plan_for("waving", lambda d: "two"))
    with r1:
        d = ActionDesignator(type="waving")
        assert perform(d) == "one-a"
        assert perform(d.next_solution()) == "one-b"
    with r2:
        assert perform(ActionDesignator(type="waving")) == "two"


def _register(kind, resolver):
    {
        "object": ObjectDesignator.resolvers,
        "location": LocationDesignator.generators,
        "action": ActionDesignator.resolvers,
        "motion": MotionDesignator.resolvers,
    }[kind].append(resolver)


def _resolve(kind):
    designator = {
        "object": ObjectDesignator,
        "location": LocationDesignator,
        "action": ActionDesignator,
        "motion": MotionDesignator,
    }[kind]([("type", "x")])
    return designator, (lambda: perform(designator)) if kind == "action" else designator.reference


@pytest.mark.parametrize("kind", ["object", "location", "action", "motion"])
def test_raising_resolver_of_every_kind_names_designator_and_resolver(kind):
    def exploding_resolver(d):
        raise RuntimeError("no map")

    _register(kind, exploding_resolver)
    designator, resolve = _resolve(kind)
    with pytest.raises(ResolverError) as info:
        resolve()
    message = str(info.value)
    assert "exploding_resolver" in message and "('type', 'x')" in message
    assert type(designator).__name__ in message and "no map" in message
    assert info.value.designator is designator and info.value.resolver is exploding_resolver
    assert isinstance(info.value, DesignatorError)


@pytest.mark.parametrize("kind", ["object", "location", "action", "motion"])
def test_non_iterable_from_resolver_of_every_kind_names_designator_and_resolver(kind):
    def number_resolver(d):
        return 42

    _register(kind, number_resolver)
    designator, resolve = _resolve(kind)
    with pytest.raises(ResolverError, match="number_resolver.*non-iterable") as info:
        resolve()
    assert f"{type(designator).__name__}([('type', 'x')])" in str(info.value)


def test_performed_actions_are_published_as_events():
    from pycram.core import events

    def wave(designator):
        return "waved"

    def fall(designator):
        raise RuntimeError("fell over")

    ActionDesignator.resolvers.extend([plan_for("waving", wave), plan_for("falling", fall)])
    performed = []
    unsubscribe = events.subscribe(events.DESIGNATOR_PERFORMED, lambda **kw: performed.append(kw))
    try:
        perform(ActionDesignator(type="waving"))
        with pytest.raises(RuntimeError):
            perform(ActionDesignator(type="falling"))
        with pytest.raises(NoSolutionError):
            perform(ActionDesignator(type="flying"))
    finally:
        unsubscribe()
    assert [(p["designator"].prop_value("type"), p["solution"], type(p["error"]).__name__) for p in performed] == [
        ("waving", wave, "NoneType"),
        ("falling", fall, "RuntimeError"),
        ("flying", None, "NoSolutionError"),
    ]


def test_action_resolver_returning_non_plan():
    def silly(d):
        return [42]

    ActionDesignator.resolvers.append(silly)
    with pytest.raises(ResolverError, match="silly"):
        perform(ActionDesignator(type="x"))


def test_action_without_plan():
    with pytest.raises(NoSolutionError, match="action designator.*'dancing'"):
        perform(ActionDesignator(type="dancing"))


def test_perform_unknown_kind():
    with pytest.raises(UnknownKindError, match="ObjectDesignator"):
        perform(ObjectDesignator(type="cup"))
    with pytest.raises(UnknownKindError):
        perform([("type", "moving")])
    assert issubclass(UnknownKindError, DesignatorError)


# --------------------------------------------------------------------------- robot activation


def test_robot_activation_nests_and_restores():
    a, b = Robot("a"), Robot("b")
    assert current_robot() is None
    with a:
        assert current_robot() is a
        with b:
            assert current_robot() is b
        assert current_robot() is a
    assert current_robot() is None
    assert use_robot(a) is None and use_robot(None) is a
    world = ResolverSet("w")
    with world:
        assert current_world() is world
    assert current_world() is None
    with pytest.raises(TypeError):
        use_robot("pr2")


def test_motion_resolvers_robot_first_then_world_then_global():
    robot, world = Robot("r"), ResolverSet("w")
    robot.motion_resolvers.append(lambda d: ["robot"])
    world.motion_resolvers.append(lambda d: ["world"])
    MotionDesignator.resolvers.append(lambda d: ["global"])
    assert list(MotionDesignator(type="x").solutions()) == ["global"]
    with robot, world:
        assert list(MotionDesignator(type="x").solutions()) == ["robot", "world", "global"]


def test_public_surface():
    import pycram
    import pycram.designator as designator_module

    for name in designator_module.__all__:
        assert hasattr(designator_module, name), name
    assert pycram.perform is perform
