"""Generated apartments (`procedural:SEED`) in the simulator: they build, their drawers and doors
move physically when pulled at their handles and stay shut otherwise, the PR2 opens and closes
them with its actions, and it transports a cup from the counter to the table. Judged with the
simulator's truth."""

from __future__ import annotations

import math

import pytest
from action_helpers import holding, put, rests_upright_at, run_as_task
from sim_helpers import ok

from pycram import robots
from pycram.actions import Close, MoveTorso, Open, ParkArms, Transport
from pycram.designator import ObjectDesignator, perform
from pycram.environments import load
from pycram.sim import World

#: Seeds built in the simulator: seed 1 has walls north and west, an L-shaped counter with the
#: stove on its side and two drawers; seed 3 is mirrored (walls north and east) with four
#: drawers sliding out west.
SEEDS = (1, 3)


def _wait(world: World, seconds: float) -> None:
    """Let `seconds` of simulated time pass."""
    t = world.sim_time.get_value() + seconds
    assert (world.sim_time >= t).wait_for(seconds + 10.0)


def _q(world: World, name: str) -> float:
    return world.container_states.get_value()[name]


def test_the_seeds_cover_both_orientations_and_drawer_counts():
    first, mirrored = load("procedural:1"), load("procedural:3")
    assert "walls north and east" not in first.title and "walls north and east" in mirrored.title
    assert first.container("drawer 1").opening_direction == (1.0, 0.0)
    assert mirrored.container("drawer 1").opening_direction == (-1.0, 0.0)
    drawers = lambda env: sorted(c.name for c in env.containers if c.kind == "drawer")  # noqa: E731
    assert drawers(first) == ["drawer 1", "drawer 2"]
    assert drawers(mirrored) == ["drawer 1", "drawer 2", "drawer 3", "drawer 4"]


@pytest.mark.parametrize("seed", SEEDS)
def test_containers_stay_shut_and_open_when_pulled_at_their_handles(seed):
    name = f"procedural:{seed}"
    with World("pr2", [], environment=name) as world:
        env = world.environment
        assert env is load(name)
        _wait(world, 1.0)  # gravity, the robot standing by: nothing opens
        assert all(abs(q) < 1e-3 for q in world.container_states.get_value().values())
        for container in env.containers:
            dx, dy = container.opening_direction
            drawer = container.kind == "drawer"
            force = 40.0 if drawer else 25.0
            ok(world.push_container(container.name, (force * dx, force * dy, 0.0), 0.4 if drawer else 0.5))
            _wait(world, 1.0)
            opened = _q(world, container.name)
            least = 0.15 if drawer else math.radians(30)
            assert least < opened <= container.limits[1] + 1e-3, f"{name}: {container.name} opened {opened:.3f}"
            _wait(world, 1.0)  # damped: it stays where it was left
            assert abs(_q(world, container.name) - opened) < 0.005
        # every container out at once: none is in another's way
        assert all(q > 0.1 for q in world.container_states.get_value().values())


@pytest.fixture(scope="module")
def pr2_in_procedural_3():
    """The PR2 in the mirrored generated apartment 3, with a cup on the counter."""
    name = "procedural:3"
    env = load(name)
    kitchen = env.place("kitchen").pose
    counter = env.surface("counter")
    front = counter.bounds[1]  # the counter runs along the north wall: its front edge is its south
    spot = (kitchen[0], front + 0.15)
    world = World("pr2", environment=name, objects=["cup"], seed=1)
    try:
        put(world, "cup", "counter", spot)
        robot = robots.load("pr2", world)
        try:
            with robot:
                perform(ParkArms())
                perform(MoveTorso("up"))
                yield world, robot
        finally:
            robot.shutdown()
    finally:
        world.close()


@pytest.mark.parametrize("container", ["drawer 2", "cupboard"])
def test_the_pr2_opens_and_closes_a_drawer_and_a_hinged_door(pr2_in_procedural_3, container):
    world, robot = pr2_in_procedural_3
    drawer = world.environment.container(container).kind == "drawer"
    opened, closed = (0.15, 0.03) if drawer else (math.radians(60), math.radians(4))
    assert _q(world, container) < closed
    measured = perform(Open(container))
    assert _q(world, container) >= opened, f"{container} opened only {_q(world, container):.3f}"
    assert abs(measured - _q(world, container)) < (0.01 if drawer else math.radians(1))  # perceived
    perform(Close(container))
    assert _q(world, container) < closed, f"{container} still open {_q(world, container):.3f}"
    assert not holding(world)


def test_the_pr2_transports_a_cup_from_the_counter_to_the_table(pr2_in_procedural_3):
    world, robot = pr2_in_procedural_3
    perform(ParkArms())
    obj, task = run_as_task(lambda: perform(Transport(ObjectDesignator(type="cup"), "table")))
    assert rests_upright_at(world, "cup", "table", obj.pose[:2])
    assert holding(world) == set()
