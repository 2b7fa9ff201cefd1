"""Object types (semantic names, sizes, colours, grasps as data) and random scenes from a seed:
reproducible, plausible (on surfaces, inside containers, within their clearance) and never
overlapping — checked over 200 seeds without building a simulation."""

from __future__ import annotations

import math

import pytest

from pycram import environments
from pycram.world.errors import UnknownNameError
from pycram.world.objects import APPROACHES, OBJECT_TYPES, Grasp, object_type, shape_parts
from pycram.world.scenes import GAP, PlacementError, object_names, random_scene

BREAKFAST = ["cup", "bowl", "spoon", "cereal", "milk", "plate"]
MAX_GRIPPER_OPENING = 0.09  # [m] of the PR2's and TIAGo's grippers


def test_object_types_name_size_colour_and_grasps():
    assert set(OBJECT_TYPES) >= set(BREAKFAST)
    for t in OBJECT_TYPES.values():
        assert 0.005 < t.height < 0.4 and 0.01 < t.mass < 1.0 and len(t.rgba) == 4
        assert t.grasps, t.name
        for g in t.grasps:
            assert g.approach in APPROACHES
            assert 0.0 < g.opening < MAX_GRIPPER_OPENING, (t.name, g)  # every grasp fits a gripper
            assert 0.0 < g.height <= t.height, (t.name, g)
    assert object_type("cup").grasps[0].approach == "side"
    assert object_type("bowl").grasps[0].radius > 0.0  # a rim grasp
    assert {g.approach for g in object_type("milk").grasps} == {"+x", "-x", "+y", "-y"}
    with pytest.raises(UnknownNameError, match="object type 'fork' does not exist. Available: bowl, cereal"):
        object_type("fork")
    with pytest.raises(ValueError, match="approach 'below'"):
        Grasp("below", 0.05, 0.02)


def test_shapes_are_built_from_primitives_that_stay_inside_the_object():
    for t in OBJECT_TYPES.values():
        parts = t.parts()
        assert parts and parts[0].kind in ("box", "cylinder")
        for p in parts:
            half_z = p.size[2] if p.kind == "box" else p.size[1]
            assert abs(p.pos[2]) + half_z <= t.half_height + 1e-9, t.name
            assert math.hypot(p.pos[0], p.pos[1]) <= t.footprint_radius + 1e-9, t.name
    assert len(shape_parts("bowl", (0.07, 0.035, 0.008))) == 13  # a base and a wall of 12 boxes
    with pytest.raises(ValueError, match="shape 'torus'"):
        shape_parts("torus", (0.1, 0.1))


def test_object_names_count_repeats():
    assert object_names(["cup", "bowl", "cup", "cup"]) == ["cup", "bowl", "cup 2", "cup 3"]


def test_same_seed_gives_the_same_scene_and_seeds_differ():
    apartment = environments.load("apartment")
    a = random_scene(apartment, BREAKFAST, seed=7)
    assert a == random_scene(apartment, BREAKFAST, seed=7)
    assert a != random_scene(apartment, BREAKFAST, seed=8)
    assert [p.name for p in a] == BREAKFAST


def test_no_two_objects_overlap_and_all_rest_plausibly_over_200_seeds():
    apartment = environments.load("apartment")
    supports_used = set()
    for seed in range(200):
        scene = random_scene(apartment, BREAKFAST + ["cup", "bowl", "plate"], seed)
        for i, p in enumerate(scene):
            otype = object_type(p.type)
            surface = apartment.surface(p.support)
            supports_used.add(surface.kind)
            assert surface.kind in otype.found_on
            assert surface.contains(p.position[0], p.position[1], p.radius), (seed, p)  # fully on it
            assert p.z_range[0] == pytest.approx(surface.height, abs=0.002)  # standing on it
            assert otype.height < surface.clearance, (seed, p)  # fits inside a drawer, the cupboard or the fridge
            assert (p.container is None) == (surface.kind not in ("drawer", "cupboard", "shelf"))
            for q in scene[i + 1 :]:
                assert not p.overlaps(q, GAP), (seed, p, q)
    assert supports_used == {"counter", "table", "shelf", "drawer", "cupboard"}  # every kind of spot occurs


def test_impossible_requests_fail_with_a_named_reason():
    kitchen = environments.load("thesis-kitchen")
    with pytest.raises(PlacementError, match=r"no free spot for 'plate \d+' after 300 tries on counter_back"):
        random_scene(kitchen, ["plate"] * 40, seed=1, supports=["counter_back"])
    with pytest.raises(PlacementError, match="no surface of 'apartment' fits a 'cereal'"):
        random_scene(environments.load("apartment"), ["cereal"], seed=1, supports=["drawer 1 inside"])
    with pytest.raises(UnknownNameError, match="surface 'shelf 9'"):
        random_scene(kitchen, ["cup"], seed=1, supports=["shelf 9"])
