"""End-to-end runs of the thesis demo in the simulated kitchen (headless).

Each test runs the real plan (`pycram.apps.demos.kitchen_plan`) on a simulated robot and checks what
the issue asks of the demo. Wall-clock speed is not asserted here: `benchmarks/demo_speed.py`
prints it.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from pycram.apps.demos.kitchen import DemoOptions, run_demo

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
    import numpy as np
    from PIL import Image

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
    from pycram.apps.demos import kitchen_plan

    result = demo(tmp_path, steal=2, seed=3)
    assert result.exit_code == 0, result.message
    assert result.recoveries == 2
    assert result.item_on_cooker_1
    # the head tracking was suspended (not ended) while the robot asked for help, each time
    assert kitchen_plan.head_suspensions.get_value() == 2


def test_no_item_ends_with_a_clear_failure(tmp_path):
    result = demo(tmp_path, item_at=0)
    assert result.exit_code != 0
    assert "NoItemGrasped" in result.message and "cooker #2" in result.message
    assert grasp_attempts(result.tree_text) == ["failed", "failed", "failed"]
    assert not result.item_on_cooker_1


@pytest.mark.parametrize(
    "option, value, expected",
    [
        ("robot", "nao", "--robot must be 'pr2', 'tiago' or 'tiago-pro'"),
        ("item_at", 4, "--item-at must be 0 (no item) or a position 1, 2 or 3"),
    ],
)
def test_bad_options_get_a_clear_message_and_exit_code_2(tmp_path, capsys, option, value, expected):
    from pycram.apps.demos.kitchen import main

    assert main(output=str(tmp_path), record=False, quiet=True, **{option: value}) == 2
    assert expected in capsys.readouterr().out


def test_the_command_prints_the_collapsed_task_tree_and_a_verdict(tmp_path, capsys):
    from pycram.apps.demos.kitchen import main

    code = main(output=str(tmp_path / "out"), db=f"sqlite:///{tmp_path / 'runs.sqlite3'}", quiet=True)
    out = capsys.readouterr().out
    assert code == 0, out
    assert re.search(r"head: pointing_head ×\d+ \[process-module\] succeeded", out)  # one line, not ~100
    assert "fetch_and_place [plan] succeeded" in out
    assert "x real time" in out and "SUCCESS: the item rests on cooker #1" in out
    assert "recorded as run 1" in out


# -- the pictures tell the story (issue 12, point 5) -----------------------------------------------


def item_pixels(rgb) -> int:
    """How many pixels of an RGB image show the demo's yellow item."""
    import numpy as np

    rgb = np.asarray(rgb, dtype=int)
    r, g, b = rgb[..., 0], rgb[..., 1], rgb[..., 2]
    return int(((r > 170) & (g > 120) & (b < 90) & (r - b > 110)).sum())


def test_the_pictures_show_the_item_and_each_frame_says_what_happens(tmp_path):
    """Two failed grasps and one theft: the item stands out in start.png, end.png and in every
    frame of the animation while it is in the kitchen; every frame has a caption band whose
    text (recorded with the frame) follows the story in order, with the simulated time."""
    import numpy as np
    from PIL import Image

    result = demo(tmp_path, item_at=3, steal=1, animation=True)
    assert result.exit_code == 0, result.message
    for name in ("start.png", "end.png"):
        assert item_pixels(Image.open(result.output / name).convert("RGB")) >= 30, f"no item to see in {name}"

    animation = Image.open(result.output / "run.gif")
    assert animation.n_frames == len(result.captions) > 50
    times = [t for t, _ in result.captions]
    assert all(a < b for a, b in zip(times, times[1:]))
    texts = [text for _, text in result.captions]
    story = [
        "resetting the robot",
        "fetching: grasp 1 of 3",
        "fetching: grasp 1 of 3 failed, trying position 2",
        "fetching: grasp 2 of 3 failed, trying position 3",
        "transporting",
        "item taken (1x): recovering",
        "transporting (recovered 1x)",
        "placing",
        "done",
    ]
    missing = [part for part in story if part not in texts]
    assert not missing, f"no frame says {missing}; the captions: {sorted(set(texts))}"
    assert [texts.index(part) for part in story] == sorted(texts.index(part) for part in story)

    band = max(14, animation.size[1] // 14)
    visible = []
    for i, (_, text) in enumerate(result.captions):
        animation.seek(i)
        frame = np.asarray(animation.convert("RGB"))
        caption = frame[-band:]
        assert caption.mean() < 80 and (caption.min(axis=2) > 200).sum() > 20, f"frame {i} has no caption"
        if not text.startswith("item taken"):  # the thief puts the item out of the kitchen
            visible.append(item_pixels(frame[:-band]) >= 8)
    assert np.mean(visible) >= 0.95, f"the item is visible in only {np.mean(visible):.0%} of the frames"


def test_each_run_writes_to_its_own_folder(tmp_path, monkeypatch):
    """Without --output: output/demo-ROBOT-RUNID for recorded runs (a timestamped folder that
    never reuses an existing one otherwise); `animation=False` writes no GIF."""
    from pycram.apps.demos.kitchen import default_output

    monkeypatch.chdir(tmp_path)
    db = f"sqlite:///{tmp_path / 'runs.sqlite3'}"
    first = run_demo(DemoOptions(quiet=True, db=db, animation=False))
    second = run_demo(DemoOptions(quiet=True, db=db, animation=False))
    assert (first.run_id, second.run_id) == (1, 2)
    assert first.output == Path("output/demo-pr2-1") and second.output == Path("output/demo-pr2-2")
    for result in (first, second):
        assert (result.output / "start.png").is_file() and (result.output / "end.png").is_file()
        assert not (result.output / "run.gif").exists()
    unrecorded = default_output("tiago")
    assert re.fullmatch(r"demo-tiago-\d{8}-\d{6}", unrecorded.name) and unrecorded.parent == Path("output")
    unrecorded.mkdir(parents=True)
    again = default_output("tiago")
    assert again != unrecorded and not again.exists()


# -- SIGINT and SIGTERM end a run as "interrupted" (issue 12, point 6) ------------------------------


def _run_record(db: str):
    from pycram.trace import query

    (info,) = query.runs(db, 1)
    return info, {record.name: record for record in query.tasks(info.id, db)}


@pytest.mark.parametrize(
    "signame, code, reason",
    [("SIGINT", 130, "interrupted by Ctrl-C (SIGINT)"), ("SIGTERM", 143, "terminated by SIGTERM")],
)
def test_a_signal_during_the_plan_ends_the_run_as_interrupted(tmp_path, signame, code, reason):
    import signal

    from signal_helpers import Command

    db = f"sqlite:///{tmp_path / 'runs.sqlite3'}"
    demo_run = Command(["demo", "--no-animation", "--output", str(tmp_path / "out")], db, tmp_path)
    demo_run.wait_for_line(r"trying to grasp at position 1")
    demo_run.send(getattr(signal, signame))
    assert demo_run.wait() == code, demo_run.output
    assert f"INTERRUPTED: {reason} after" in demo_run.stdout and "Traceback" not in demo_run.output
    assert (tmp_path / "out" / "start.png").is_file() and (tmp_path / "out" / "end.png").is_file()
    info, tasks = _run_record(db)
    assert info.outcome == "interrupted" and reason in (info.error or ""), info
    assert tasks["fetch_and_place"].status == "evaporated"  # the plan (and with it the robot) was stopped
    assert tasks["pycram-demo-plan"].status != "running"  # the plan thread's root ended with it
    assert not [name for name, task in tasks.items() if task.status == "running"]


def test_sigint_after_the_plan_succeeded_is_still_an_interruption(tmp_path):
    import signal

    from signal_helpers import Command

    db = f"sqlite:///{tmp_path / 'runs.sqlite3'}"
    demo_run = Command(["demo", "--no-animation", "--output", str(tmp_path / "out")], db, tmp_path)
    demo_run.wait_for_line(r"placed the item at")
    demo_run.send(signal.SIGINT)
    assert demo_run.wait() == 130, demo_run.output
    assert "INTERRUPTED: interrupted by Ctrl-C (SIGINT)" in demo_run.stdout and "Traceback" not in demo_run.output
    info, _ = _run_record(db)
    assert info.outcome == "interrupted" and "interrupted by Ctrl-C (SIGINT)" in (info.error or ""), info


def test_a_second_sigint_while_stopping_exits_at_once(tmp_path):
    import signal

    from signal_helpers import Command

    db = f"sqlite:///{tmp_path / 'runs.sqlite3'}"
    demo_run = Command(["demo", "--no-animation", "--output", str(tmp_path / "out")], db, tmp_path)
    demo_run.wait_for_line(r"trying to grasp at position 1")
    demo_run.send(signal.SIGINT)
    demo_run.wait_for_line(r"stopping the plan: interrupted by Ctrl-C")
    demo_run.send(signal.SIGINT)
    assert demo_run.wait() == 130, demo_run.output
    assert "interrupted by Ctrl-C (SIGINT) again while stopping; exiting at once" in demo_run.stderr
    assert "Traceback" not in demo_run.output
