"""Regrasping (issue 33): an object held with a grasp no standing pose puts at the target, but
another grasp of its type does, is put down within reach and taken again with that grasp.

Measured on the evaluation worlds of set-table-anywhere: the PR2 took a cereal box from the top
where it stood and could not put it at its setting, 0.45 m in on the table, that way (six of
twenty worlds); from the side it reaches there. Set up here in the apartment and judged with
the simulator's truth.
"""

from __future__ import annotations

import math

import pytest
from action_helpers import TABLE, apartment_with, holding, run_as_task, tasks_named
from sim_helpers import tilt

from pycram.actions import MoveTorso, ParkArms, PickUp, Place
from pycram.apps.scenarios.set_table.scene import place_settings
from pycram.designator import ObjectDesignator, perform
from pycram.execution.failures import ObjectOutOfReach


def test_a_cereal_box_held_from_the_top_is_put_down_and_taken_from_the_side_to_reach_far_in():
    with apartment_with("pr2", {"cereal": TABLE}) as (world, robot):
        setting = next(s for s in place_settings(world.environment, objects=("cereal",)) if s.type == "cereal")
        perform(ParkArms())
        perform(MoveTorso("up"))
        held = perform(PickUp(ObjectDesignator(type="cereal"), grasp="top"))
        assert held.grasp.approach == "top" and holding(world) == {"cereal"}
        # without regrasping: out of reach with this grasp, and still in the hand
        with pytest.raises(ObjectOutOfReach, match="grasp', 'top'"):
            perform(Place(held, setting.point, regrasp=False))
        assert holding(world) == {"cereal"}

        placed, task = run_as_task(lambda: perform(Place(held, setting.point)))

        pose = world.item_poses.get_value()["cereal"]
        assert math.dist(pose.position[:2], setting.point[:2]) < 0.05, pose
        assert tilt(pose.orientation) < math.radians(10), pose  # put down and set again upright
        assert holding(world) == set() and placed.name == held.object.name
        picks = tasks_named(task, "perform picking_up")
        assert len(picks) == 1  # taken again once, from the side this time
        names = [str(t.name) for t in picks[0].walk()]
        assert any(g in n for n in names for g in ("side grasp", "+y grasp", "-y grasp")), names
