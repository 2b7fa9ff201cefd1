"""Grasps for any pose (issue 32, point 3): objects in poses the per-type grasp tables are not
tuned for -- a milk carton lying on its side, a cereal box turned 60 deg -- are picked up with
grasps planned from their measured shape and pose (`pycram.reasoning.grasps`).

The plans know the world only through perception; the tests set the scene with the simulator
(`World.move_item` with an orientation) and judge with its truth.
"""

from __future__ import annotations

import math

import pytest
from action_helpers import COUNTER, apartment_with, holding
from sim_helpers import ok, tilt

from pycram.actions import MoveTorso, ParkArms, PickUp, Place, Transport
from pycram.designator import LocationDesignator, ObjectDesignator, perform
from pycram.world.objects import object_type


def ready() -> None:
    perform(ParkArms())
    perform(MoveTorso("up"))


def lying_quat(direction: float) -> tuple[float, float, float, float]:
    """Orientation (w, x, y, z) of a box lying on its own x face with its long (z) axis along
    `direction` [rad]: 90 deg about y (z to x), then `direction` about the vertical."""
    cz, sz, r = math.cos(direction / 2), math.sin(direction / 2), math.sqrt(0.5)
    # q = qz(direction) * qy(90 deg)
    return (cz * r, -sz * r, cz * r, sz * r)


def lay_down(world, name: str, surface: str, xy: tuple[float, float], direction: float) -> None:
    """Lay `name` (a box type) on its side on `surface` at `xy`, its long axis along `direction`."""
    z = world.environment.surface(surface).height + object_type(name).size[0] + 0.002
    ok(world.move_item(name, (xy[0], xy[1], z), lying_quat(direction)))


def lies_on(world, name: str, surface: str) -> bool:
    """True when `name` lies on its side on `surface` (simulator truth): its z axis within 20 deg
    of horizontal, its centre at its lying half height above the surface."""
    pose = world.item_poses.get_value()[name]
    x, y, z = pose.position
    env_surface = world.environment.surface(surface)
    half = object_type(name).size[0]
    return (
        env_surface.contains(x, y, 0.0)
        and abs(z - half - env_surface.height) < 0.03
        and abs(tilt(pose.orientation) - math.pi / 2) < math.radians(20)
    )


@pytest.mark.parametrize(("robot_name", "direction_deg"), [("pr2", 0), ("pr2", 35), ("tiago", 0)])
def test_a_milk_carton_lying_on_its_side_is_picked_up(robot_name, direction_deg):
    # the milk's own grasps are all horizontal, at 10 cm above its bottom: lying (7 cm tall)
    # they pass over it -- only a planned grasp (across its body, from the top) picks it up
    with apartment_with(robot_name, {"milk": COUNTER}) as (world, robot):
        lay_down(world, "milk", "counter", COUNTER[1], math.radians(direction_deg))
        ready()
        held = perform(PickUp(ObjectDesignator(type="milk")))
        assert holding(world) == {"milk"}
        assert held.object.lying_axis is not None  # believed lying, from its measured shape
        assert held.grasp not in object_type("milk").grasps  # a planned grasp
        assert held.grasp.opening == pytest.approx(0.07)  # across its 7 cm, not along its 20 cm
        milk = world.item_poses.get_value()["milk"]
        assert milk.position[2] > world.environment.surface("counter").height + 0.1  # lifted


def test_a_milk_carton_picked_up_lying_is_put_down_lying():
    with apartment_with("pr2", {"milk": COUNTER}) as (world, robot):
        lay_down(world, "milk", "counter", COUNTER[1], 0.0)
        ready()
        held = perform(PickUp(ObjectDesignator(type="milk")))
        obj = perform(Place(held, "table"))
        assert holding(world) == set()
        assert lies_on(world, "milk", "table")
        assert math.dist(world.item_poses.get_value()["milk"].position[:2], obj.pose[:2]) < 0.05


@pytest.mark.parametrize("robot_name", ["pr2", "tiago"])
def test_a_cereal_box_turned_60_degrees_is_picked_up(robot_name):
    # its ends (where the 9 cm gripper closes round its 7 cm) face 150 and -30 deg: from the
    # counter's front the robot grasps it turned, not squarely
    yaw = math.radians(60)
    with apartment_with(robot_name, {"cereal": COUNTER}) as (world, robot):
        x, y = COUNTER[1]
        z = world.environment.surface("counter").height + object_type("cereal").half_height + 0.002
        ok(world.move_item("cereal", (x, y, z), (math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2))))
        ready()
        held = perform(PickUp(ObjectDesignator(type="cereal")))
        assert holding(world) == {"cereal"}
        assert abs((held.object.yaw - yaw + math.pi / 2) % math.pi - math.pi / 2) < math.radians(10)
        assert held.grasp.opening == pytest.approx(0.07)  # across its narrow side
        box = world.item_poses.get_value()["cereal"]
        assert tilt(box.orientation) < math.radians(20)  # held upright
        assert math.dist(box.position[:2], (x, y)) > 0.15  # carried away from where it stood


def test_a_square_carton_turned_45_degrees_goes_into_the_fridge_held_by_its_faces():
    # Its sides' direction is measured (a square top has no longer axis); across its diagonal
    # (9.9 cm) the fingers could not close. Into the fridge `Transport` takes it from the side:
    # a hand holding it from the top finds no way in under the shelf above (before: a planned top
    # grasp, then "no standing pose" to place it on any shelf).
    yaw = math.radians(45)
    with apartment_with("pr2", {"milk": COUNTER}) as (world, robot):
        x, y = COUNTER[1]
        z = world.environment.surface("counter").height + object_type("milk").half_height + 0.002
        ok(world.move_item("milk", (x, y, z), (math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2))))
        ready()
        widths: list[float] = []
        world.gripper_states["left"].on_change(lambda s: s.holding and widths.append(s.opening))
        world.gripper_states["right"].on_change(lambda s: s.holding and widths.append(s.opening))
        placed = perform(Transport(ObjectDesignator(type="milk"), LocationDesignator([("in", "fridge")])))
        assert widths and max(widths) < 0.08  # held across two faces (7 cm), never the diagonal
        milk = world.item_poses.get_value()["milk"]
        assert placed.properties["in"] == "fridge"
        assert any(s.contains(*milk.position[:2], 0.0) for s in world.environment.container("fridge").interior)
        assert tilt(milk.orientation) < math.radians(20)
        assert not holding(world)


def test_into_a_door_container_the_grasp_is_from_the_side_only_for_types_that_have_one():
    # a bowl, a plate or a spoon is held by its rim or body from the top: asking for a side grasp
    # failed at once with "no_executable_grasp" (actions benchmark, eval seeds 32007-32009)
    from pycram.actions.transport import _grasp_for

    with apartment_with("pr2", {"cup": COUNTER}):
        assert [_grasp_for("fridge", t) for t in ("milk", "cereal", "cup")] == ["side"] * 3
        assert [_grasp_for("cupboard", t) for t in ("bowl", "plate", "spoon")] == [None] * 3
        assert _grasp_for("drawer 2", "milk") is None and _grasp_for(None, "milk") is None
