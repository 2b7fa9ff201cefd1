"""The thesis demo end to end over ROS: plan -> ROS process modules -> roscore -> bridge -> MuJoCo."""

from __future__ import annotations

import os
import subprocess
import sys

from pycram.apps.demos.kitchen import DemoOptions, run_demo


def test_demo_over_ros_recovers_from_failed_grasps_and_a_theft_pr2(start_bridge, transport, tmp_path):
    """PR2, in this process, against a bridge on the session's master: the item is at the third
    position (two grasps close on nothing) and is stolen once during the transport."""
    start_bridge("pr2", item_at=3)
    result = run_demo(
        DemoOptions(
            robot="pr2", backend="ros", item_at=3, steal=1, output=tmp_path, record=False, quiet=True, animation=False
        )
    )
    assert result.exit_code == 0, f"{result.message}\n{result.tree_text}"
    assert result.item_on_cooker_1
    assert result.failed_grasps == 2
    assert result.recoveries == 1
    assert (tmp_path / "end.png").stat().st_size > 0  # rendered by the bridge


def test_demo_cli_over_ros_starts_its_own_roscore_and_bridge_tiago(ros_master, tmp_path):
    """`pycram demo --backend ros` without ROS_MASTER_URI: its own roscore and bridge (TIAGo)."""
    env = {k: v for k, v in os.environ.items() if k not in ("ROS_MASTER_URI", "ROS_IP", "ROS_HOSTNAME")}
    env.setdefault("MUJOCO_GL", "egl")
    completed = subprocess.run(
        [
            sys.executable,
            "-m",
            "pycram",
            "demo",
            "--backend",
            "ros",
            "--robot",
            "tiago",
            "--steal",
            "1",
            "--no-record",
            "--quiet",
            "--output",
            str(tmp_path),
        ],
        env=env,
        capture_output=True,
        text=True,
        timeout=240,
    )
    assert completed.returncode == 0, completed.stdout[-3000:] + completed.stderr[-3000:]
    assert "SUCCESS: the item rests on cooker #1" in completed.stdout
    assert "recoveries: 1" in completed.stdout
