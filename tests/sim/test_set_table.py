"""The set-table scenario (issue 17): the scenario's data, bad input, and end-to-end runs judged
with the simulator's truth (a few fixed seeds per robot -- not the seeds the benchmark reports --
and a faulted run that recovers).

The end-to-end runs take 20-90 s of wall time each on a 2-core machine; they are few.
"""

from __future__ import annotations

import json
import math
import random
from pathlib import Path

import pytest

from pycram.apps.scenarios import set_table
from pycram.apps.scenarios.set_table import (
    FAULTS,
    OBJECTS,
    check_faults,
    driver,
    place_settings,
    run_set_table,
    scene,
    start_scene,
)
from pycram.environments import load as load_environment

#: Seeds that set the whole table, measured (never the seeds the experiments report, 1-200), with
#: the objects each robot brings: both all four (one TIAGo run also with the cup and the milk
#: alone); in PR2 seed 203 the cup starts in the cupboard.
#: Arms per robot (their descriptions' ARMS).
ARMS = {"pr2": 2, "tiago": 1}
END_TO_END = [("pr2", 201, OBJECTS), ("pr2", 203, OBJECTS), ("tiago", 202, ("cup", "milk")), ("tiago", 205, OBJECTS)]


def test_place_settings_are_data_on_the_table_apart_from_each_other():
    env = load_environment("apartment")
    settings = place_settings(env)
    table = env.surface("table")
    assert [s.type for s in settings] == list(OBJECTS)
    for s in settings:
        assert table.contains(s.point[0], s.point[1], 0.1), s
        assert s.point[2] > table.height
    for a in settings:
        for b in settings:
            if a is not b:
                assert math.dist(a.point[:2], b.point[:2]) > 0.2


def test_the_start_scene_comes_from_the_seed_and_stays_in_the_start_regions():
    env = load_environment("apartment")
    first, again, other = start_scene(env, 5), start_scene(env, 5), start_scene(env, 6)
    assert first == again and first != other
    # seed 221's first draw leaves no room for the milk on the counter: drawn again, not refused
    assert scene._draw_scene(env, 221, OBJECTS, True, random.Random(221)) is None
    assert [p.type for p in start_scene(env, 221)] == list(OBJECTS) and start_scene(env, 221) == start_scene(env, 221)
    inside: set[tuple[str, str]] = set()
    for seed in range(30):
        # set-table-open: every object on an open surface, where it is in set-table too unless the
        # draw put it in a container
        plain = start_scene(env, seed, in_containers=False)
        assert all(p.container is None for p in plain)
        with_containers = start_scene(env, seed)
        assert [p for p in with_containers if p.container is None] == [
            p for p in plain if p.name not in {q.name for q in with_containers if q.container is not None}
        ]
        for p in with_containers:
            if p.container is None:
                x0, y0, x1, y1 = set_table.START_REGIONS[p.type][p.support]
                assert x0 <= p.position[0] <= x1 and y0 <= p.position[1] <= y1
                continue
            # inside a closed container: on its inside surface, in the region of START_CONTAINERS
            _, regions = set_table.START_CONTAINERS[p.type]
            x0, y0, x1, y1 = regions[p.support]
            assert x0 <= p.position[0] <= x1 and y0 <= p.position[1] <= y1
            surface = env.surface(p.support)
            assert env.container_of(p.support).name == p.container
            assert surface.contains(p.position[0], p.position[1], p.radius)
            assert surface.height < p.position[2] < surface.height + surface.clearance
            inside.add((p.type, p.container))
    # some seeds start the cup in drawer 2, some in the cupboard (the bowl and the milk never in a
    # container: see the docs)
    assert inside == {("cup", "drawer 2"), ("cup", "cupboard")}


def test_a_person_moving_an_object_from_the_cabinet_top_puts_it_clear_of_the_others_on_the_counter():
    # the `moved` fault's spot near an object on the cabinet top: no counter spot is within
    # 0.6 m of it; the person put it in the counter region's middle whatever stood there (a
    # plate 0.12 m from the milk carton, into it: seeds 6, 15, 24), now at the clearest spot
    import random
    from types import SimpleNamespace

    from pycram.apps.scenarios.set_table import START_REGIONS, Faults
    from pycram.fluent import Fluent

    environment = load_environment("apartment")
    x0, y0, x1, y1 = START_REGIONS["bowl"]["counter"]
    middle = ((x0 + x1) / 2, (y0 + y1) / 2)
    pose = lambda x, y: SimpleNamespace(position=(x, y, 0.95))  # noqa: E731
    world = SimpleNamespace(
        environment=environment,
        gripper_states={},
        item_poses=Fluent({"milk": pose(middle[0] + 0.1, middle[1]), "bowl": pose(0.44, 2.79)}),
    )
    faults = object.__new__(Faults)  # only the spot drawing: no threads, no scene
    faults.world, faults.rng = world, random.Random(15)
    x, y, _ = faults._free_counter_spot("bowl", (0.44, 2.79))
    assert x0 <= x <= x1 and y0 <= y <= y1
    assert math.hypot(x - middle[0] - 0.1, y - middle[1]) > 0.3  # clear of the milk carton


def test_unknown_fault_and_robot_names_are_refused_naming_the_valid_choices():
    with pytest.raises(ValueError, match=r"unknown fault\(s\) 'flood'; valid faults: moved, taken, stuck"):
        run_set_table("pr2", 1, frozenset({"flood"}))
    with pytest.raises(ValueError, match=r"valid robots: pr2, tiago"):
        run_set_table("robby", 1)
    assert check_faults("moved, taken") == frozenset({"moved", "taken"})
    assert check_faults("") == frozenset()
    assert set(FAULTS) == {"moved", "taken", "stuck", "obstacle", "missed"}


def test_the_demo_command_refuses_an_unknown_scenario_or_fault_naming_the_valid_choices():
    pytest.importorskip("typer")
    from typer.testing import CliRunner

    from pycram.apps.cli import app

    runner = CliRunner()
    result = runner.invoke(app, ["demo", "--scenario", "dinner"])
    assert result.exit_code == 2
    assert "unknown scenario 'dinner'" in result.output and "thesis, set-table" in result.output
    result = runner.invoke(app, ["demo", "--scenario", "set-table", "--faults", "flood", "--no-record"])
    assert result.exit_code == 2
    assert "valid faults: moved, taken, stuck, obstacle, missed" in result.output
    result = runner.invoke(app, ["demo", "--faults", "taken"])
    assert result.exit_code == 2 and "not the thesis demo" in result.output


def test_the_demo_command_runs_a_scenario_through_its_registered_front_end(tmp_path, monkeypatch):
    # `pycram demo --scenario NAME` finds the scenario's terminal front end in the experiments'
    # scenario registry (no list of scenarios in the CLI); set-table-open starts nothing inside.
    pytest.importorskip("typer")
    from typer.testing import CliRunner

    from pycram.apps.cli import app
    from pycram.apps.experiments.scenarios import demo_scenario_names
    from pycram.apps.scenarios.set_table import display

    assert demo_scenario_names() == [
        "set-table",
        "set-table-open",
        "set-table-anywhere",
        "clear-table",
        "put-away",
        "serve",
    ]
    started = []

    class Stopped(Exception):
        pass

    def run_scenario(robot, seed, kinds, **options):
        started.append((robot, seed, options["in_containers"], options["starts"]))
        raise Stopped

    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(display, "run_scenario", run_scenario)
    for scenario in ("set-table", "set-table-open", "set-table-anywhere"):
        args = ["demo", "--scenario", scenario, "--robot", "tiago", "--seed", "3", "--no-record", "-q"]
        result = CliRunner().invoke(app, args)
        assert isinstance(result.exception, Stopped), result.output
    assert started == [("tiago", 3, True, "narrow"), ("tiago", 3, False, "narrow"), ("tiago", 3, True, "anywhere")]


def _assert_set(out: dict, objects: tuple[str, ...] = OBJECTS) -> None:
    assert json.loads(json.dumps(out)) == out  # JSON-serialisable, as the experiment runner needs
    assert out["success"], out["summary"]
    assert set(out["objects"]) == set(objects)
    assert all(o["placed"] and o["failure"] is None for o in out["objects"].values())
    assert out["failure_causes"] == [] and out["open_containers"] == {}
    assert out["sim_time"] > out["wall_time"] > 0  # faster than real time


@pytest.mark.timeout(400)
@pytest.mark.parametrize(("robot", "seed", "objects"), END_TO_END)
def test_the_table_is_set_end_to_end(robot, seed, objects):
    out = run_set_table(robot, seed, objects=objects)
    _assert_set(out, objects)
    assert out["robot"] == robot and out["seed"] == seed and out["faults"] == []
    # the same plan file: the one-armed TIAGo carries one object at a time (simulator's truth)
    held_at_once = out["concurrency"]["most_held_at_once"]
    assert 1 <= len(held_at_once) <= ARMS[robot], held_at_once
    if robot == "tiago":
        assert out["concurrency"]["carried_together"] == []


#: Seeds (not the benchmark's 1-200) where the cup starts in a closed container, measured to set
#: the table: (robot, seed, the container). The cup alone: with the milk too, the PR2 knocked
#: the carton off the counter and the TIAGo found no drive to a placing pose in 1 of 2 runs each
#: (docs/set-table.md, "What does not work yet").
IN_A_CONTAINER = [
    ("pr2", 1006, "drawer 2"),
    ("tiago", 1006, "drawer 2"),
    ("pr2", 1012, "cupboard"),
    ("tiago", 1012, "cupboard"),
]


@pytest.mark.timeout(400)
@pytest.mark.parametrize(("robot", "seed", "container"), IN_A_CONTAINER)
def test_a_cup_starting_in_a_closed_container_is_brought_and_the_containers_are_closed_again(robot, seed, container):
    (start,) = start_scene(load_environment("apartment"), seed, ("cup",))
    assert start.container == container
    out = run_set_table(robot, seed, objects=("cup",))
    assert out["started_in"] == {"cup": container}
    _assert_set(out, ("cup",))  # at its setting, every drawer and door closed


@pytest.mark.timeout(400)
def test_a_run_with_faults_recovers_from_a_taken_and_a_moved_object_and_an_obstacle():
    out = run_set_table("pr2", 205, frozenset({"taken", "moved", "obstacle"}))
    kinds = {f.split(":")[0] for f in out["faults_injected"]}
    assert {"taken", "moved", "obstacle"} <= kinds, out["faults_injected"]
    assert out["faults"] == ["moved", "obstacle", "taken"]
    _assert_set(out)


#: Seeds (not the experiments' 1-200) whose cup starts in drawer 2, for a run with the drawer
#: stuck and perception missing objects.
STUCK_AND_MISSED = {"pr2": 211, "tiago": 206}


@pytest.mark.timeout(400)
@pytest.mark.parametrize("robot", sorted(STUCK_AND_MISSED))
def test_a_run_recovers_from_the_drawer_holding_the_cup_being_stuck_and_from_missed_detections(robot):
    """The drawer holding the cup is stuck (it frees itself seconds after the robot first pulls
    on it; `Open` tries other standing poses, the search moves on and a second round comes back)
    and perception misses 3 in 10 sightings (over the run's dozens of looks some are missed: the
    belief and the actions look again). The cup is brought all the same."""
    seed = STUCK_AND_MISSED[robot]
    out = run_set_table(robot, seed, frozenset({"stuck", "missed"}), objects=("cup",))
    assert out["started_in"] == {"cup": "drawer 2"}
    assert out["faults"] == ["missed", "stuck"]
    assert out["faults_injected"][0] == "stuck: drawer 2 is stuck"
    assert any(f.startswith("stuck: drawer 2 came free") for f in out["faults_injected"]), out["faults_injected"]
    _assert_set(out, ("cup",))


@pytest.mark.timeout(300)
def test_a_run_for_the_experiment_runner_is_recorded_with_pictures(tmp_path, monkeypatch):
    pytest.importorskip("sqlalchemy")
    from pycram.trace import query

    monkeypatch.chdir(tmp_path)
    url = f"sqlite:///{tmp_path / 'trace.db'}"
    out = run_set_table("tiago", 207, db_url=url, pictures=True, objects=("cup", "milk"))
    _assert_set(out, ("cup", "milk"))
    assert out["run_id"] is not None
    assert (tmp_path / "output" / "set-table-tiago-207" / "end.png").exists()
    assert any(str(r.id) == str(out["run_id"]) for r in query.runs(url=url))


# -- concurrency where a person would (issue 17) ----------------------------------------------------
#
# Fixed seeds and scenes, not the benchmark's seeds; judged with the simulator's truth and the
# task tree the plan left.


def _statuses(task) -> dict[str, str]:
    """A task's children by name (without the branch number, "1:drive" -> "drive") -> status."""
    return {str(child.name).split(":", 1)[-1]: child.status.get_value().name for child in task.children}


@pytest.mark.timeout(120)
def test_while_driving_runs_the_job_alongside_each_drive_and_ends_it_with_the_drive():
    from action_helpers import COUNTER, apartment_with, run_as_task, tasks_named

    from pycram.actions import Navigate
    from pycram.actions.core import while_driving
    from pycram.designator import perform
    from pycram.failures import PlanFailure
    from pycram.fluent import Fluent

    with apartment_with("pr2", {"cup": COUNTER}) as (world, robot):
        started, ended = [], []

        def job() -> None:
            started.append(world.base_pose.get_value())
            try:
                Fluent(None).wait_for()  # never set: only the end of the drive stops it
            finally:
                ended.append(world.base_pose.get_value())

        def failing_job() -> None:
            raise PlanFailure("a look that fails")

        def body():
            with while_driving(job):
                first = perform(Navigate((3.0, 1.2, 0.0)))
            with while_driving(failing_job):  # the job's failure is not the drive's
                second = perform(Navigate((2.6, 1.2, 0.0)))
            third = perform(Navigate((2.2, 1.2, 0.0)))  # outside the block: alone
            return first, second, third

        (first, second, third), root = run_as_task(body)
        assert math.hypot(first.x - 3.0, first.y - 1.2) < 0.05
        assert math.hypot(second.x - 2.6, second.y - 1.2) < 0.05 and math.hypot(third.x - 2.2, third.y - 1.2) < 0.05
        assert len(started) == 1 and len(ended) == 1  # one drive in the first block, the job ended with it
        assert math.hypot(ended[0].x - 3.0, ended[0].y - 1.2) < 0.1  # ... where the drive ended
        drives = tasks_named(root, "drive, looking around")
        assert len(drives) == 2
        assert _statuses(drives[0]) == {"drive": "SUCCEEDED", "look_while_driving": "EVAPORATED"}
        assert _statuses(drives[1]) == {"drive": "SUCCEEDED", "look_while_driving": "EVAPORATED"}


@pytest.mark.timeout(300)
def test_a_search_is_ended_by_pursue_when_a_look_while_driving_turns_the_object_up():
    """The robot stands at the table, the cup on the cabinet top beyond the camera's range (4 m
    away): the search drives to the cabinet top, the nearest place where cups are likely that
    it has not seen; the look taken while driving sees the cup before the drive ends, and the
    search is evaporated."""
    from functools import partial

    from action_helpers import apartment_with, run_as_task, tasks_named

    from pycram.actions.core import while_driving
    from pycram.apps.scenarios.set_table.plan import PlanRecord, find, look_for_the_next

    with apartment_with("pr2", {"cup": ("cabinet top", (0.5, 2.8))}, base_pose=(4.3, 0.9, math.pi / 2)) as (world, _):
        record = PlanRecord()

        def body():
            with while_driving(partial(look_for_the_next, lambda: ["cup"], record)):
                return find("cup", record)

        cup, root = run_as_task(body)
        truth = world.item_poses.get_value()["cup"].position
        assert math.dist(cup.pose[:2], truth[:2]) < 0.05, (cup, truth)
        assert record.found_while_driving == [f"{cup.name} on cabinet top"]
        assert record.searches_ended_by_sighting == [f"cup: {cup.name}"]
        (search,) = tasks_named(root, "search for the cup")
        assert _statuses(search) == {"search": "EVAPORATED", "until_seen_while_driving": "SUCCEEDED"}
        assert tasks_named(search, "drive, looking around")  # the search was driving when it ended


@pytest.mark.timeout(400)
def test_the_pr2_carries_two_objects_at_once_and_looks_for_the_next_while_driving():
    """PR2, seed 3 (measured 4 of 4 runs: the plate and the bowl carried together): after
    picking one object it brings the next with its free arm, both held at once (the
    simulator's truth), and the looks taken while driving find objects the belief did not
    hold. Every drive ran with its look alongside, ended with the drive."""
    from action_helpers import tasks_named

    result, task = set_table.run_scenario("pr2", 3)
    assert result.success, result.summary()
    concurrency = result.concurrency
    assert len(concurrency["most_held_at_once"]) == 2, concurrency
    assert concurrency["carried_together"], concurrency
    assert concurrency["found_while_driving"], concurrency
    drives = tasks_named(task, "drive, looking around")
    assert drives
    assert all(_statuses(drive)["look_while_driving"] == "EVAPORATED" for drive in drives)


def test_the_two_scenarios_write_the_pictures_of_a_seed_to_folders_of_their_own(monkeypatch):
    """`set-table`, `set-table-open` and `set-table-anywhere` runs of the same seed and robot do not overwrite each
    other's pictures (the run itself is replaced: only the folder it is given is under test)."""
    folders = []

    class Stopped(Exception):
        pass

    def run_scenario(robot, seed, kinds, recorder=None, output=None, **options):
        folders.append(output)
        raise Stopped

    monkeypatch.setattr(driver, "run_scenario", run_scenario)
    for run in (set_table.run_set_table, set_table.run_set_table_on_open_surfaces, set_table.run_set_table_anywhere):
        with pytest.raises(Stopped):
            run("pr2", 7, pictures=True)
    assert folders == [
        Path("output") / "set-table-pr2-7",
        Path("output") / "set-table-open-pr2-7",
        Path("output") / "set-table-anywhere-pr2-7",
    ]


def test_the_stuck_fault_sticks_a_drawer_the_one_holding_the_cup_if_any():
    """`stuck` is a stuck drawer (the issue's fault): drawer 2 when the cup starts in it, some
    drawer when it starts in the cupboard -- never the cupboard's door."""
    from types import SimpleNamespace

    env = load_environment("apartment")
    world = SimpleNamespace(environment=env)  # the fault's choices need the environment only
    drawers = {c.name for c in env.containers if c.kind == "drawer"}
    seen = set()
    for seed in range(1, 41):
        placements = start_scene(env, seed)
        (inside,) = {p.container for p in placements if p.container} or {None}
        faults = set_table.Faults(world, frozenset({"stuck"}), random.Random(seed), place_settings(env), placements)
        assert faults.stuck_drawer in drawers, (seed, faults.stuck_drawer)
        if inside == "drawer 2":
            assert faults.stuck_drawer == "drawer 2"
        seen.add(inside)
    assert seen == {None, "drawer 2", "cupboard"}
