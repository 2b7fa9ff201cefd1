"""End-to-end runs of the thesis demo in the simulated kitchen (headless).

Each test runs the real plan (`pycram.demos.kitchen_plan`) on a simulated robot and checks what
the issue asks of the demo. Wall-clock speed is not asserted here: `benchmarks/demo_speed.py`
prints it.
"""

from __future__ import annotations

import re

import pytest

from pycram.demos.kitchen import DemoOptions, run_demo

pytestmark = pytest.mark.timeout(300)


def demo(tmp_path, **options):
    db = f"sqlite:///{tmp_path / 'runs.sqlite3'}"
    options.setdefault("animation", False)
    result = run_demo(DemoOptions(output=tmp_path / "out", quiet=True, db=db, **options))
    print(result.tree_text)
    print(result.message, f"sim {result.sim_time:.1f} s, plan wall {result.plan_wall_time:.1f} s")
    return result


def grasp_attempts(tree_text: str) -> list[str]:
    """The status words of the three grasp attempts (`try_in_order` steps), in order."""
    return re.findall(r"try_in_order@kitchen_plan\.py:\d+#\d \[step\] (\w+)", tree_text)


def assert_pictures(result):
    from PIL import Image
    import numpy as np

    for name in ("start.png", "end.png", "timeline.png"):
        image = np.asarray(Image.open(result.output / name).convert("RGB"), dtype=float)
        assert image.std() > 10, f"{name} is blank"
    animation = Image.open(result.output / "run.gif")
    assert animation.n_frames > 10
    assert (result.output / "task-tree.svg").read_text().lstrip().startswith(("<?xml", "<svg"))


@pytest.mark.parametrize("robot", ["pr2", "tiago"])
def test_default_run_places_the_item_on_cooker_1(tmp_path, robot):
    result = demo(tmp_path, robot=robot, animation=robot == "pr2")
    assert result.exit_code == 0, result.message
    assert result.item_on_cooker_1
    assert result.failed_grasps == 0 and result.recoveries == 0
    assert grasp_attempts(result.tree_text) == ["succeeded"]
    assert "fetch_and_place [plan] succeeded" in result.tree_text
    assert result.sim_time > 5.0  # the robot really drove, grasped and placed
    if robot == "pr2":
        assert_pictures(result)


def test_item_at_position_3_fails_two_grasps_then_succeeds(tmp_path):
    result = demo(tmp_path, item_at=3)
    assert result.exit_code == 0, result.message
    assert result.failed_grasps == 2
    assert grasp_attempts(result.tree_text) == ["failed", "failed", "succeeded"]
    assert result.tree_text.count("GraspFailed") >= 2


def test_two_thefts_are_recovered(tmp_path):
    result = demo(tmp_path, steal=2, seed=3)
    assert result.exit_code == 0, result.message
    assert result.recoveries == 2
    assert result.item_on_cooker_1


def test_no_item_ends_with_a_clear_failure(tmp_path):
    result = demo(tmp_path, item_at=0)
    assert result.exit_code != 0
    assert "NoItemGrasped" in result.message and "cooker #2" in result.message
    assert grasp_attempts(result.tree_text) == ["failed", "failed", "failed"]
    assert not result.item_on_cooker_1


@pytest.mark.parametrize("option, value, expected", [
    ("robot", "nao", "--robot must be 'pr2' or 'tiago'"),
    ("item_at", 4, "--item-at must be 0 (no item) or a position 1, 2 or 3"),
])
def test_bad_options_get_a_clear_message_and_exit_code_2(tmp_path, capsys, option, value, expected):
    from pycram.demos.kitchen import main

    assert main(output=str(tmp_path), record=False, quiet=True, **{option: value}) == 2
    assert expected in capsys.readouterr().out


def test_the_command_prints_the_collapsed_task_tree_and_a_verdict(tmp_path, capsys):
    from pycram.demos.kitchen import main

    code = main(output=str(tmp_path / "out"), db=f"sqlite:///{tmp_path / 'runs.sqlite3'}", quiet=True)
    out = capsys.readouterr().out
    assert code == 0, out
    assert re.search(r"head: pointing_head ×\d+ \[process-module\] succeeded", out)  # one line, not ~100
    assert "fetch_and_place [plan] succeeded" in out
    assert "x real time" in out and "SUCCESS: the item rests on cooker #1" in out
    assert "recorded as run 1" in out
