"""`pycram robot check` (issue 34): the short form passes for every registered robot, and a
robot described wrongly fails the check that finds it, saying why.

The short form (description, world, every motion type, reach envelope, camera, one action) runs
in-process for each robot of the registry -- a robot added by another package is checked too.
Broken robots are registered the way a package outside PyCRAM registers one (an entry point
written into distribution metadata on `sys.path`, as in `tests/world/test_robot_plugin.py`), with
the TIAGo's description changed where the test says.
"""

from __future__ import annotations

import contextlib
import json
import os
import textwrap

import pytest

from pycram.apps.robot_check import FAIL, PASS, SKIP, CheckReport, CheckResult, report_table, run_robot_check
from pycram.apps.robot_check.motions import MOTION_CASES, motion_cases
from pycram.apps.robot_check.reach import COUNTER_HEIGHT, SHORT_STEP, ArmEnvelope, grid
from pycram.testing.robot_packages import installed_robot_package
from pycram.world import robot_registry

os.environ.setdefault("MUJOCO_GL", "egl")


def _failures(report: CheckReport) -> str:
    return "\n".join(f"{r.check}: {r.detail}" for r in report.failures())


# -- the short form, for every registered robot --------------------------------------------------


@pytest.mark.parametrize("robot_name", robot_registry.robot_names())
def test_the_short_form_passes_for_every_registered_robot(robot_name):
    seen: list[CheckResult] = []
    report = run_robot_check(robot_name, short=True, on_result=seen.append)
    assert report.passed, f"{robot_name} failed the short check:\n{_failures(report)}"
    assert seen == report.results  # told as they ran
    checks = {r.check: r for r in report.results}
    description = robot_registry.robot_description(robot_name)
    # every motion type of the vocabulary was performed (none skipped for want of a case)
    for name in MOTION_CASES:
        assert checks[f"motion: {name}"].result == PASS, checks[f"motion: {name}"]
    for arm in description.ARMS:
        row = checks[f"reach: {arm} arm"]
        assert row.result == PASS and row.data["at_counter_height"][0] > 0 and row.data["step"] == SHORT_STEP
    assert checks["camera sees a test object"].result == PASS
    assert checks["camera sees a test object"].data["error"] < 0.03
    assert checks["action: transporting"].result == PASS
    assert checks["set-table seeds"].result == SKIP  # the full form's
    # simulated time was spent where the robot moved, none where nothing was simulated
    assert checks["motion: moving"].sim_time > 0.5 and checks["description validates"].sim_time is None


# -- broken robots ----------------------------------------------------------------------------------


@pytest.fixture
def register_robot(tmp_path):
    """Registers a robot package ``NAME`` with the TIAGo's description under that name plus
    `changes` (module code appended to the description), as `pip install` of a package
    declaring ``[project.entry-points."pycram.robots"] NAME = "<package>"`` would
    (`pycram.testing.robot_packages`; each in a folder of its own, forgotten after the test)."""
    with contextlib.ExitStack() as registered:

        def register(name: str, changes: str) -> str:
            registered.enter_context(installed_robot_package(tmp_path / name, name, changes=textwrap.dedent(changes)))
            return name

        yield register


#: An arm whose joint chain lists only the wrist: the description names two of its seven joints,
#: so the IK moves the tool about the wrist alone (a description error a new robot easily has).
WRIST_ONLY_ARM = """
ARMS = {"right": {**ARMS["right"], "joints": ("arm_6_joint", "arm_7_joint")}}
ARM_CONFIGURATIONS = {"right": {name: q[5:] for name, q in ARM_CONFIGURATIONS["right"].items()}}
"""


def test_an_arm_that_reaches_nothing_fails_the_reach_check_saying_so(register_robot):
    name = register_robot("wrist-only", WRIST_ONLY_ARM)
    report = run_robot_check(name, short=True)
    assert not report.passed
    checks = {r.check: r for r in report.results}
    assert checks["description validates"].result == PASS
    assert checks["world builds, robot loads"].result == PASS
    reach = checks["reach: right arm"]
    assert reach.result == FAIL
    assert f"reaches nothing at counter height ({COUNTER_HEIGHT} m)" in reach.detail
    assert reach.data["fraction"] == 0.0 and reach.data["reachable"] == []
    # the plans cannot use the arm either: reaching and the action fail, naming why
    assert checks["motion: reaching"].result == FAIL and checks["motion: reaching"].detail
    assert checks["action: transporting"].result == FAIL
    assert "ObjectOutOfReach" in checks["action: transporting"].detail
    # the other checks still ran
    assert checks["camera sees a test object"].result == PASS


def test_a_description_that_does_not_validate_fails_first_and_the_rest_is_skipped(register_robot):
    name = register_robot("no-torso", "del TORSO\n")
    report = run_robot_check(name, short=True)
    assert not report.passed
    first, *rest = report.results
    assert first.check == "description validates" and first.result == FAIL
    assert "RobotDescriptionError" in first.detail and "'TORSO'" in first.detail and "no-torso" in first.detail
    assert rest and all(r.result == SKIP and r.detail == "needs a valid description" for r in rest)


def test_an_unknown_robot_name_raises_listing_the_registered_robots():
    with pytest.raises(robot_registry.UnknownRobotError, match="'nosuch' does not exist. Available: pr2, tiago"):
        run_robot_check("nosuch", short=True)


# -- the command line ---------------------------------------------------------------------------------


def test_the_command_fails_with_exit_code_1_prints_the_reason_and_writes_json(register_robot, tmp_path):
    from typer.testing import CliRunner

    from pycram.apps.cli import app

    name = register_robot("wrist-only", WRIST_ONLY_ARM)
    out = tmp_path / "check.json"
    result = CliRunner().invoke(
        app, ["robot", "check", "--short", "--quiet", name, "--json", str(out)], env={"COLUMNS": "200"}
    )
    assert result.exit_code == 1, result.output
    assert "reaches nothing at counter height" in result.output
    assert f"failed: {name}" in result.output
    data = json.loads(out.read_text())
    assert data["passed"] is False
    (robot,) = data["robots"]
    assert robot["robot"] == name and robot["form"] == "short" and robot["counts"]["FAIL"] >= 1
    rows = {r["check"]: r for r in robot["checks"]}
    assert rows["reach: right arm"]["result"] == FAIL and rows["reach: right arm"]["wall_time"] > 0.0


def test_the_command_refuses_an_unknown_robot_with_exit_code_2_naming_the_choices():
    from typer.testing import CliRunner

    from pycram.apps.cli import app

    result = CliRunner().invoke(app, ["robot", "check", "nosuch"])
    assert result.exit_code == 2
    assert "robot 'nosuch' does not exist. Available: " in result.output
    assert all(n in result.output for n in robot_registry.robot_names())


def test_robot_list_shows_every_registered_robot_and_an_invalid_description(register_robot, tmp_path):
    from typer.testing import CliRunner

    from pycram.apps.cli import app

    register_robot("no-torso", "del TORSO\n")
    out = tmp_path / "robots.json"
    result = CliRunner().invoke(app, ["robot", "list", "--json", str(out)], env={"COLUMNS": "250"})
    assert result.exit_code == 0, result.output
    rows = {r["name"]: r for r in json.loads(out.read_text())}
    assert set(rows) == set(robot_registry.robot_names())
    for name, row in rows.items():
        if name == "no-torso":
            assert "TORSO" in row["error"]
            continue
        description = robot_registry.robot_description(name)
        assert row["error"] is None and row["urdf"] == description.URDF
        assert {a: r["joints"] for a, r in row["arms"].items()} == {
            a: len(s["joints"]) for a, s in description.ARMS.items()
        }
        assert row["base"] == description.BASE.get("kind", "omnidirectional")
        assert name in result.output
    assert "invalid description" in result.output


# -- the pieces -----------------------------------------------------------------------------------------


def test_the_reach_grid_spans_the_ranges_and_includes_counter_height():
    points = grid(0.2)
    assert len(points) == 4 * 6 * 5
    assert {p[2] for p in points} == {0.5, 0.7, 0.9, 1.1, 1.3}
    assert min(p[0] for p in points) == 0.3 and max(p[0] for p in points) == 0.9
    assert min(p[1] for p in points) == -0.5 and max(p[1] for p in points) == 0.5
    assert len(grid(0.1)) == 7 * 11 * 9
    with pytest.raises(ValueError, match="step"):
        grid(0.0)


def test_an_envelope_counts_the_points_at_counter_height_and_their_ranges():
    envelope = ArmEnvelope("right", [(0.3, 0.0, 0.9), (0.5, 0.1, 0.9), (0.5, 0.1, 1.1)], [True, False, True])
    assert envelope.at_height(0.9) == (1, 2)
    assert envelope.fraction == pytest.approx(2 / 3)
    assert envelope.ranges() == {"x": (0.3, 0.5), "y": (0.0, 0.1), "z": (0.9, 1.1)}
    assert ArmEnvelope("left", [(0.3, 0.0, 0.9)], [False]).ranges() is None


def test_a_motion_type_without_a_case_is_listed_to_be_skipped():
    cases = motion_cases({"moving": object(), "hovering": object()})
    by_name = {name: (case, why) for name, case, why in cases}
    assert by_name["moving"][0] is MOTION_CASES["moving"]
    assert by_name["hovering"] == (None, "no conformance case for this motion type yet")
    assert by_name["reaching"] == (None, "not in the robot's motion vocabulary")


def test_the_table_shows_details_literally_and_a_result_must_be_known():
    from rich.console import Console

    report = CheckReport(
        "pr2", "short", [CheckResult("reach", "reach: [left] arm", FAIL, "x in [0.3, 0.9] m", 1.0, 0.5)]
    )
    console = Console(width=200, record=True)
    console.print(report_table(report))
    text = console.export_text()
    assert "reach: [left] arm" in text and "x in [0.3, 0.9] m" in text and "FAIL" in text
    assert "0 passed, 1 failed, 0 skipped" in text
    with pytest.raises(ValueError, match="PASS, FAIL, SKIP"):
        CheckResult("reach", "reach", "MAYBE")
