"""Environments as data: the registry, the description types, and the layering rules
(descriptions are read, never their modules' constants; the world model knows no simulator)."""

from __future__ import annotations

import ast
import math
from pathlib import Path

import pytest

from pycram import environments
from pycram.world.environment import Box, Container, Surface
from pycram.world.errors import UnknownNameError

PACKAGE = Path(__file__).resolve().parents[2] / "pycram"


def test_registry_looks_environments_up_by_name_and_lists_valid_names():
    assert set(environments.ENVIRONMENT_NAMES) >= {"thesis-kitchen", "apartment"}
    for name in environments.ENVIRONMENT_NAMES:
        env = environments.load(name)
        assert env.name == name
        assert environments.load(env) is env
    with pytest.raises(
        UnknownNameError, match="environment 'kitchen2' does not exist. Available: apartment, thesis-kitchen"
    ):
        environments.load("kitchen2")
    with pytest.raises(KeyError):  # a plain KeyError for callers that catch that
        environments.load("kitchen2")


def test_unknown_parts_name_the_valid_choices():
    kitchen = environments.load("thesis-kitchen")
    with pytest.raises(
        UnknownNameError,
        match="surface 'sink' does not exist. Available: cooker #1, cooker #2, counter_back, counter_left",
    ):
        kitchen.surface("sink")
    with pytest.raises(UnknownNameError, match="container 'drawer'"):
        kitchen.container("drawer")
    with pytest.raises(UnknownNameError, match="place 'nowhere' does not exist. Available: start"):
        kitchen.place("nowhere")


def test_thesis_kitchen_keeps_the_thesis_layout():
    kitchen = environments.load("thesis-kitchen")
    assert kitchen.start_pose == (0.8, 0.6, 0.0)
    assert [s.name for s in kitchen.surfaces_of_kind("cooker")] == ["cooker #1", "cooker #2"]
    cooker_1, cooker_2 = kitchen.surface("cooker #1"), kitchen.surface("cooker #2")
    assert cooker_1.centroid == pytest.approx((-0.72, 1.9, 0.9))
    assert cooker_2.centroid == pytest.approx((0.1, -1.2, 0.9))
    assert kitchen.surface("counter_left").contains(-0.72, 1.9)  # cooker #1 on the left counter
    assert kitchen.surface("counter_back").contains(0.1, -1.2)
    assert kitchen.support_height(0.1, -1.15) == pytest.approx(0.9)
    assert kitchen.support_height(0.8, 0.6) == 0.0  # the floor
    assert kitchen.is_free_floor(0.8, 0.6)
    assert not kitchen.is_free_floor(0.1, -1.2)  # on the back counter
    assert not kitchen.is_free_floor(1.75, -1.25)  # inside the fridge
    assert not kitchen.is_free_floor(-3.0, 0.0)  # behind the wall
    assert kitchen.containers == ()


def test_surface_polygons_are_convex_and_counter_clockwise():
    square = Surface.rectangle("s", (0.0, 0.0, 1.0, 2.0), 0.5)
    assert square.area == pytest.approx(2.0)
    assert square.contains(0.5, 1.0, margin=0.4) and not square.contains(0.5, 1.0, margin=0.6)
    assert square.edge_distance(2.0, 1.0) == pytest.approx(-1.0)
    with pytest.raises(ValueError, match="convex and counter-clockwise"):
        Surface("cw", ((0, 0), (0, 1), (1, 1), (1, 0)), 0.5)
    with pytest.raises(ValueError, match="convex"):
        Surface("dent", ((0, 0), (2, 0), (1, 0.2), (2, 2), (0, 2)), 0.5)


def test_container_handle_follows_the_opening_trajectory():
    drawer = Container(
        "d", "drawer", Box("d", (0.3, 1.0, 0.5), (0.25, 0.2, 0.1)), (0.6, 1.0, 0.55), (1.0, 0.0), (0.0, 0.4)
    )
    assert drawer.joint == "slide" and drawer.handle_position(0.3) == pytest.approx((0.9, 1.0, 0.55))
    door = Container(
        "f",
        "door",
        Box("f", (1.0, 0.0, 0.8), (0.02, 0.3, 0.8)),
        (1.05, 0.25, 1.0),
        (1.0, 0.0),
        (0.0, 2.0),
        hinge=(1.02, -0.3),
    )
    assert door.joint == "hinge"
    opened = door.handle_position(math.pi / 2)  # a quarter turn: the handle swings out in front
    assert opened[0] > 1.5 and opened[1] == pytest.approx(-0.3, abs=0.05)
    # the door's faces: the outside one (with the handle) on the hinge line, the inside 4 cm behind
    assert door.door_width == pytest.approx(0.6)
    point, along, normal = door.door_face(0.0, 0.5, "outside")
    assert (
        point == pytest.approx((1.02, 0.2)) and along == pytest.approx((0.0, 1.0)) and normal == pytest.approx((1, 0))
    )
    point, along, normal = door.door_face(0.0, 0.5, "inside")
    assert point == pytest.approx((0.98, 0.2)) and normal == pytest.approx((-1.0, 0.0))
    point, along, normal = door.door_face(math.pi / 2, 0.5, "outside")  # turned with the handle
    assert point == pytest.approx((1.52, -0.3)) and along == pytest.approx((1.0, 0.0), abs=1e-9)
    assert normal == pytest.approx((0.0, -1.0), abs=1e-9)
    assert door.door_face(math.pi / 2, 0.5, "inside")[0] == pytest.approx((1.52, -0.26))
    with pytest.raises(ValueError, match="faces 'outside' and 'inside'"):
        door.door_face(0.0, 0.5, "top")
    with pytest.raises(ValueError, match="is a drawer, not a door"):
        drawer.door_face(0.0, 0.1, "outside")
    with pytest.raises(ValueError, match="needs a hinge"):
        Container("x", "door", door.body, door.handle, (1.0, 0.0), (0.0, 1.0))
    with pytest.raises(ValueError, match="kind must be"):
        Container("x", "lid", door.body, door.handle, (1.0, 0.0), (0.0, 1.0))


def _imports(path: Path) -> set[str]:
    tree = ast.parse(path.read_text())
    names = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module:
            names.add(node.module)
            names.update(f"{node.module}.{a.name}" for a in node.names)
    return names


def test_no_module_imports_an_environment_module_but_the_registry():
    env_modules = {
        f"pycram.environments.{p.stem}" for p in (PACKAGE / "environments").glob("*.py") if p.stem != "__init__"
    }
    assert "pycram.environments.thesis_kitchen" in env_modules
    offenders = []
    for path in PACKAGE.rglob("*.py"):
        if path.parent.name == "environments":
            continue
        hits = _imports(path) & env_modules
        if hits:
            offenders.append(f"{path.relative_to(PACKAGE)}: {sorted(hits)}")
    assert offenders == []


def test_the_world_model_and_environments_know_no_simulator():
    for folder in ("world", "environments"):
        for path in (PACKAGE / folder).glob("*.py"):
            bad = {
                n
                for n in _imports(path)
                if n.split(".")[0] == "mujoco" or n.startswith("pycram.sim") or n.startswith("pycram.robots")
            }
            assert not bad, f"{path.name} imports {sorted(bad)}"
