"""Physics faults (issue 33, section 3): an object leaving the world, flying or sinking into the
furniture ends the run with a named `SimulationFault` at once -- never a search for an object
that is no longer in the world -- and experiment reports count it under its own name.

The faults are made with the world's interventions (`move_item`: teleported) and
`physics_faults.fling` (an absurd velocity, as a glitch of the contact solver gives one).
"""

from __future__ import annotations

import math
import threading

import pytest
from action_helpers import COUNTER, apartment_with
from sim_helpers import ok

from pycram.actions import Navigate, ParkArms
from pycram.backends.sim.physics_faults import CHECK_PERIOD, FAST_CHECKS, SPEED_LIMIT, fling, world_bounds
from pycram.designator import perform
from pycram.failures import PlanFailure, SimulationFault
from pycram.sim import World

T = 30.0


def _wait_sim(world: World, seconds: float) -> None:
    """Let `seconds` [s] of simulated time pass (the test thread waits on the world's clock)."""
    from pycram.fluent import Fluent

    until = world.sim_time.get_value() + seconds
    reached = Fluent(lambda: True if world.sim_time.get_value() >= until else None)
    world.sim_time.add_child(reached)
    assert reached.wait_for(T)


def _fault(world: World, timeout: float = 2.0) -> SimulationFault:
    assert world.physics_fault.wait_for(timeout), "no physics fault was noticed"
    fault = world.physics_fault.get_value()
    assert isinstance(fault, SimulationFault)
    return fault


def test_a_settled_scene_has_no_physics_fault():
    # every breakfast object, some inside closed containers, standing where the scene put them
    objects = ["cup", "bowl", "spoon", "cereal", "milk", "plate", "mug"]
    with World("pr2", environment="apartment", objects=objects, seed=3) as world:
        _wait_sim(world, 3.0)
        assert world.physics_fault.get_value() is None


def test_an_absurd_velocity_is_a_named_fault_at_once():
    with World("pr2", environment="apartment", objects=["cup"], seed=1) as world:
        _wait_sim(world, 0.5)
        flung_at = world.sim_time.get_value()
        ok(fling(world, "cup", (0.0, 0.0, 12.0)))  # up: still in the world after the checks
        fault = _fault(world)
        assert (fault.object, fault.reason) == ("cup", "too_fast")
        assert fault.speed > SPEED_LIMIT
        # noticed within the checks it takes, in simulated time
        assert flung_at <= fault.sim_time <= flung_at + (FAST_CHECKS + 1) * CHECK_PERIOD + 0.02
        assert "cup moved faster than" in str(fault) and f"t={fault.sim_time:.2f} s" in str(fault)
        assert not isinstance(fault, PlanFailure)  # no plan recovery may handle it


@pytest.mark.parametrize(
    ("where", "reason", "says"),
    [
        ((-97.9, -138.8, 0.5), "left_world", "outside the world"),
        ((3.0, 1.0, -0.5), "below_floor", "below the floor"),
        ((1.3, 4.7, 0.45), "sunk", "inside 'counter'"),  # the middle of the kitchen counter
    ],
)
def test_teleported_objects_are_named_faults(where, reason, says):
    with World("pr2", environment="apartment", objects=["cup"], seed=1) as world:
        ok(world.move_item("cup", where))
        fault = _fault(world)
        assert (fault.object, fault.reason) == ("cup", reason)
        assert says in str(fault)
        assert math.dist(fault.position, where) < 0.1


def test_world_bounds_hold_the_environment_and_the_place_aside():
    from pycram.environments import ENVIRONMENT_NAMES
    from pycram.environments import load as load_environment

    for name in ENVIRONMENT_NAMES:
        env = load_environment(name)
        low, high = world_bounds(env, items=6)
        x0, y0, x1, y1 = env.plan_bounds
        assert low[0] < x0 and low[1] < y0 and high[0] > x1 + 1.5 and high[1] > y1
        assert low[2] < 0.0 < high[2]


def test_a_plan_ends_with_the_simulation_fault_quickly():
    """The robot drives; meanwhile the cup is flung out of the kitchen. The drive -- and every
    motion after it -- raises `SimulationFault` (Navigate's recovery lets it pass)."""
    with apartment_with("pr2", {"cup": COUNTER}) as (world, robot):
        start = world.base_pose.get_value()
        flung: list[float] = []

        def glitch() -> None:  # a "person" thread: waits on fluents only
            from pycram.fluent import Fluent

            moved = Fluent(
                lambda: (
                    True
                    if math.hypot(world.base_pose.get_value().x - start.x, world.base_pose.get_value().y - start.y)
                    > 0.3
                    else None
                )
            )
            world.base_pose.add_child(moved)
            if moved.wait_for(60.0):
                flung.append(world.sim_time.get_value())
                ok(fling(world, "cup", (-60.0, -80.0, 5.0)))

        person = threading.Thread(target=glitch, daemon=True)
        person.start()
        with pytest.raises(SimulationFault) as caught:
            perform(Navigate((4.5, 1.0, 0.0)))  # 2.5 m: the glitch comes while it drives
        person.join(10.0)
        assert flung, "the cup was never flung"
        fault = caught.value
        assert fault.object == "cup" and fault.reason in ("too_fast", "left_world")
        assert world.sim_time.get_value() - flung[0] < 1.0  # ended at once, not after a search
        with pytest.raises(SimulationFault):  # sticky: every later motion raises it too
            perform(ParkArms())


def test_an_experiment_counts_the_simulation_fault_by_name():
    """A set-table run whose cup is flung at the start ends with `SimulationFault`; its result
    and an experiment report over it name the fault."""
    from pycram.apps.experiments import report
    from pycram.apps.experiments.store import RunRecord
    from pycram.apps.scenarios.set_table.driver import run_scenario

    done = threading.Event()

    def progress(world, plan, injector) -> None:
        if not done.is_set() and world.sim_time.get_value() > 0.5:
            done.set()
            ok(fling(world, "cup", (0.0, 0.0, 50.0)))

    result, _task = run_scenario("pr2", 1, progress=progress)
    assert done.is_set()
    assert result.error is not None and result.error.startswith("SimulationFault: cup")
    assert "SimulationFault" in result.failure_causes
    assert result.sim_time < 30.0  # the run ended at once
    as_dict = result.as_dict()
    record = RunRecord("pr2", 1, "none", "done", as_dict["success"], as_dict["failure_causes"], result.sim_time, 1.0)
    (group,) = report.summarize([record])
    assert group.causes["SimulationFault"] == 1
