"""The ``anywhere`` starts of the set-table scenario (issue 33, ``set-table-anywhere``): all six
breakfast types drawn over the whole worktops and inside the containers, kept where some standing
pose of the robot reaches them, and one end-to-end run on a development seed.

The scene draws ask the reachability filter (location reasoning in prospection, no simulation):
a draw takes 2-36 s of CPU (seeds 1-10, idle machine); the five the draw tests share about 35 s,
the end-to-end run about 1-2 min.
"""

from __future__ import annotations

import math

import pytest

from pycram.apps.scenarios.common.scene import reachability
from pycram.apps.scenarios.reachability import PERCEPTION_MARGIN, perceived_yaw
from pycram.apps.scenarios.set_table import ANYWHERE_OBJECTS, anywhere_scene, anywhere_sources, run_set_table
from pycram.environments import load as load_environment

#: Development seeds (0-999, `pycram.apps.experiments.splits`) whose scenes the draw tests read:
#: the five cheapest of seeds 1-10 to draw (seeds 1-10 all took ~160 s, over the suite's 120-s
#: limit on a loaded CI machine); between them objects on the counter's back half, in drawer 3 and
#: in the cupboard.
DRAW_SEEDS = (1, 3, 5, 9, 10)


@pytest.fixture(scope="module")
def scenes():
    env = load_environment("apartment")
    return env, {seed: anywhere_scene(env, seed, "pr2") for seed in DRAW_SEEDS}


def test_anywhere_starts_cover_the_whole_worktops_every_type_and_the_containers(scenes):
    env, drawn = scenes
    assert anywhere_scene(env, 3, "pr2") == drawn[3]  # the same seed, the same scene
    assert drawn[3] != drawn[5]
    counter = env.surface("counter")
    x0, y0, x1, y1 = counter.bounds
    back = []  # on the counter's back half (towards the wall): out of the narrow starts' strips
    types, containers = set(), set()
    for placements in drawn.values():
        assert [p.type for p in placements] == list(ANYWHERE_OBJECTS)
        for p in placements:
            types.add(p.type)
            assert p.support in anywhere_sources(env, p.type)
            surface = env.surface(p.support)
            assert surface.contains(p.position[0], p.position[1])
            if p.container is not None:
                assert env.container_of(p.support).name == p.container
                containers.add(p.container)
            if p.support == "counter" and p.position[1] > (y0 + y1) / 2:
                back.append(p)
        for a in placements:  # clear of each other
            assert not any(a is not b and a.overlaps(b) for b in placements)
    assert types == set(ANYWHERE_OBJECTS)
    assert len(back) >= 3, back
    assert containers, "no object started inside a container"


def test_every_anywhere_start_passes_the_reachability_filter_among_the_others(scenes):
    env, drawn = scenes
    reach = reachability("pr2", env.name)
    for seed, placements in drawn.items():
        for p in placements:
            others = [q for q in placements if q is not p]
            # as the robot's reasoning judges it once it has seen them all: the others believed,
            # the turn as perceived, and (for the spot as drawn) a centimetre off too
            ok, why = reach.graspable(p.type, p.position, p.yaw, p.support, others, as_perceived=True)
            assert ok, (seed, p, why)
        last = placements[-1]
        ok, why = reach.graspable(
            last.type, last.position, last.yaw, last.support, placements[:-1], True, PERCEPTION_MARGIN
        )
        assert ok, (seed, last, why)


def test_the_filter_takes_an_objects_turn_as_perception_reports_it():
    assert perceived_yaw("cup", 2.95) == 0.0  # a round object: no turn measured
    assert perceived_yaw("plate", -1.0) == 0.0
    assert perceived_yaw("milk", math.radians(100)) == pytest.approx(math.radians(10))  # a square top
    assert perceived_yaw("cereal", math.radians(170)) == pytest.approx(math.radians(-10))  # half a turn on
    assert perceived_yaw("cereal", math.radians(60)) == pytest.approx(math.radians(60))


def test_a_spot_in_a_drawer_is_judged_with_the_drawer_open_and_a_spot_behind_the_wall_not_at_all():
    env = load_environment("apartment")
    reach = reachability("pr2", env.name)
    # the middle of drawer 2, as it stands closed: reached once the drawer is opened
    ok, why = reach.graspable("cup", (0.42, 2.9, 0.42), 0.0, "drawer 2 inside")
    assert ok, why
    # with every container closed (no support named) the same point is inside the cabinet
    assert not reach.graspable("cup", (0.42, 2.9, 0.42), 0.0)[0]


def test_an_unknown_start_mode_or_object_is_refused_naming_the_valid_choices():
    from pycram.apps.scenarios.set_table.driver import check_starts

    with pytest.raises(ValueError, match=r"unknown start mode 'everywhere'; valid start modes: narrow, anywhere"):
        check_starts("everywhere")
    with pytest.raises(ValueError, match=r"unknown or unsupported object type\(s\) 'mugg'"):
        anywhere_scene(load_environment("apartment"), 1, "pr2", ("mugg",))


#: A development seed whose ``anywhere`` scene the PR2 sets (measured: `docs/set-table.md`): the
#: cup starts inside the closed drawer 3, the other five on the worktops.
END_TO_END = ("pr2", 3)


@pytest.mark.timeout(400)
def test_the_table_is_set_end_to_end_with_anywhere_starts():
    robot, seed = END_TO_END
    out = run_set_table(robot, seed, starts="anywhere")
    assert out["success"], out["summary"]
    assert out["starts"] == "anywhere"
    assert set(out["objects"]) == set(ANYWHERE_OBJECTS)
    assert all(o["placed"] and o["failure"] is None for o in out["objects"].values())
    assert out["started_in"] == {"cup": "drawer 3"}  # brought out of a closed drawer ...
    assert out["failure_causes"] == [] and out["open_containers"] == {}  # ... and every drawer closed again


def test_set_table_anywhere_runs_in_other_environments_and_set_table_says_it_does_not():
    from types import SimpleNamespace

    from pycram.apps.experiments.scenarios import get_scenario
    from pycram.apps.scenarios.set_table.driver import check_environment
    from pycram.apps.scenarios.set_table.faults import Faults

    assert check_environment("procedural:7", "anywhere") == "procedural:7"
    with pytest.raises(ValueError, match=r"apartment only .*, not procedural:7; set-table-anywhere runs in any"):
        check_environment("procedural:7", "narrow")
    with pytest.raises(ValueError, match=r"procedural:x"):
        check_environment("procedural:x", "anywhere")
    # `pycram experiment --env` asks the scenario's function: set-table is refused up front
    assert get_scenario("set-table-anywhere").takes_environment()
    assert not get_scenario("set-table").takes_environment()
    # a person puts an object down in a strip along the counter's front edge (the edge the
    # robot works at: nearest the kitchen place), in any environment
    for name in ("procedural:1", "procedural:2", "procedural:3"):
        environment = load_environment(name)
        x0, y0, x1, y1 = Faults._counter_region(
            SimpleNamespace(world=SimpleNamespace(environment=environment)), "spoon"
        )
        counter = environment.surface("counter")
        assert counter.contains(x0, y0) and counter.contains(x1, y1), (name, (x0, y0, x1, y1), counter.bounds)
        kx, ky, _ = environment.place("kitchen").pose
        centre = ((x0 + x1) / 2, (y0 + y1) / 2)
        cx0, cy0, cx1, cy1 = counter.bounds
        assert math.dist((kx, ky), centre) < math.dist((kx, ky), ((cx0 + cx1) / 2, (cy0 + cy1) / 2))


@pytest.mark.timeout(400)
def test_the_table_is_set_in_a_generated_apartment():
    from pycram.apps.scenarios.set_table.driver import run_set_table_anywhere

    # development seed 1 in the development world procedural:1 (`pycram.apps.experiments.splits`)
    out = run_set_table_anywhere("pr2", 1, environment="procedural:1")
    assert out["environment"] == "procedural:1"
    assert out["success"], out["summary"]
    assert set(out["objects"]) == set(ANYWHERE_OBJECTS)
    assert out["failure_causes"] == [] and out["open_containers"] == {}
