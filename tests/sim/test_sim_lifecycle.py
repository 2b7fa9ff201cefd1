"""The world's life: simulated time for plans, real-time pacing, sensor rate, one thread touching
MuJoCo, repeated worlds in one process, and a clean shutdown.

Assertions on wall time are only lower bounds caused by real-time pacing (a loaded machine can
only make them longer), never speed.
"""

from __future__ import annotations

import threading
import time

import mujoco
import pytest
from sim_helpers import Recorder, T, ok, wait_wall

from pycram.backends.sim.errors import WorldClosedError
from pycram.backends.sim.world import REALTIME_SLACK
from pycram.fluent import Fluent
from pycram.runtime import current_clock, sleep
from pycram.sim import World


def test_plans_sleep_and_time_out_in_simulated_time():
    """At half real-time speed, `sleep(0.5)` lasts >= 0.5 s simulated and so ~1 s of wall time
    (a wall-clock sleep would last 0.5 s); a fluent time-out of 0.3 s likewise. This also shows
    that real-time mode paces the simulation."""
    factor, tick = 0.5, 0.01

    def least_wall_time(simulated: float) -> float:
        """Pacing guarantee [s]: a waiter may wake one control tick early and the schedule may
        slip by REALTIME_SLACK (see `World`); load only adds to it."""
        return simulated / factor - REALTIME_SLACK - tick / factor

    before = current_clock()
    with World("tiago", realtime=True, realtime_factor=factor, control_period=tick) as world:
        assert current_clock() is world.clock
        s0, w0 = world.clock.now(), time.monotonic()
        sleep(0.5)
        s1, w1 = world.clock.now(), time.monotonic()
        assert s1 - s0 >= 0.5
        assert w1 - w0 >= least_wall_time(0.5)  # a wall-clock sleep would end after 0.5 s
        assert Fluent().wait_for(0.3) is False
        assert world.clock.now() - s1 >= 0.3
        assert time.monotonic() - w1 >= least_wall_time(0.3)
        assert abs(world.sim_time.get_value() - world.clock.now()) < 0.1
    assert current_clock() is before


def test_sensor_rate_is_configurable():
    with World("tiago", sensor_rate=10.0) as world:
        stamps = Recorder(world.joint_states)
        poses = Recorder(world.base_pose)
        assert (world.sim_time >= 2.0).wait_for(T)
        times = [js.stamp for js in stamps.samples]
        gaps = [b - a for a, b in zip(times, times[1:])]
        assert len(gaps) >= 15 and all(abs(g - 0.1) < 1e-6 for g in gaps), gaps  # 10 Hz of simulated time
        assert abs(len(poses.samples) - len(stamps.samples)) <= 1  # all sensors publish together


def test_mujoco_is_only_touched_by_the_simulation_thread(monkeypatch):
    """Commands from several threads at once: every MuJoCo call after construction comes from
    the world's own thread."""
    calls: list[tuple[int, str]] = []
    lock = threading.Lock()

    def spy(name, fn):
        def wrapper(*args, **kwargs):
            with lock:
                calls.append((threading.get_ident(), name))
            return fn(*args, **kwargs)

        return wrapper

    for name in ("mj_step", "mj_forward", "mj_kinematics", "mj_comPos", "mj_jacSite", "mj_jacBody"):
        monkeypatch.setattr(mujoco, name, spy(name, getattr(mujoco, name)))
    for name in ("update_scene", "render"):
        monkeypatch.setattr(mujoco.Renderer, name, spy(name, getattr(mujoco.Renderer, name)))

    with World("pr2") as world:
        constructed = len(calls)
        d = world.description
        errors: list[BaseException] = []

        def client(work):
            try:
                work()
            except BaseException as exc:  # reported below
                errors.append(exc)

        base = world.base_pose.get_value()
        left = world.tool_poses.get_value()["left"].position
        jobs = [
            lambda: (
                ok(world.reach("left", (left[0], left[1], left[2] + 0.03))),  # map frame: before driving
                ok(world.drive_to(base.x + 0.3, base.y, base.yaw)),
            ),
            lambda: ok(world.move_arm_to(d.DEFAULT_ARM, "carry")),
            lambda: (ok(world.point_head((2.0, 0.6, 0.8))), ok(world.perceive())),
            lambda: (ok(world.request_image("head_camera")), ok(world.move_item("mug", (0.1, -1.15, 0.951)))),
            lambda: ok(world.remove_obstacle(ok(world.place_obstacle(3.5, 3.0)))),
        ]
        threads = [threading.Thread(target=client, args=(job,)) for job in jobs]
        for t in threads:
            t.start()
        with world.clock.watching():  # this thread joins plain threads: the lock-step world runs on
            for t in threads:
                t.join(120)
        assert errors == []
        sim_thread = world._thread.ident
        later = calls[constructed:]
    names = {name for _, name in later}
    assert {"mj_step", "mj_forward", "mj_jacSite", "mj_jacBody", "render"} <= names
    assert {ident for ident, _ in later} == {sim_thread}


def test_worlds_can_be_built_again_and_again():
    for robot in ("pr2", "tiago", "pr2"):
        with World(robot) as world:
            start = world.base_pose.get_value()
            pose = ok(world.drive_to(start.x + 0.2, start.y, start.yaw))
            assert abs(pose.x - (start.x + 0.2)) < 0.02


def test_worlds_closed_in_any_order_restore_the_clock():
    before = current_clock()
    first, second = World("tiago"), World("tiago")
    assert current_clock() is second.clock
    first.close()
    assert current_clock() is second.clock  # the running world keeps simulated time
    second.close()
    assert current_clock() is before  # not the first world's dead clock


def test_clean_shutdown_leaves_no_thread(tmp_path):
    before = set(threading.enumerate())
    waiter_done = threading.Event()
    with World("pr2") as w:
        world_clock = w.clock
        ok(w.start_recording(fps=10))
        w.snapshot(tmp_path / "a.png")
        ok(w.perceive())
        w.stop_recording(tmp_path / "a.gif")
        handle = w.drive_to(3.0, 3.0, 0.0)

        def plan_waiting_on_simulated_time():
            sleep(1e6)  # on the world's clock: woken when the world closes
            waiter_done.set()

        waiter = threading.Thread(target=plan_waiting_on_simulated_time, daemon=True)
        waiter.start()
        asleep = lambda: (world_clock.next_deadline() or 0.0) > 1e5  # noqa: E731
        assert wait_wall(asleep, [w.sim_time], timeout=60.0)
        assert w.running
    assert not w.running
    assert handle.wait(1.0).reason == "closed"
    waiter.join(30)
    assert waiter_done.is_set()
    assert set(threading.enumerate()) <= before
    assert current_clock() is not world_clock
    with pytest.raises(WorldClosedError):
        w.drive_to(0, 0, 0)
    with pytest.raises(WorldClosedError, match="closed"):
        w.snapshot(tmp_path / "b.png")
    w.close()  # idempotent
