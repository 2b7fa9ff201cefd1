"""Fixtures for the robot tests: one world and its loaded robot per robot, shared by a module."""

from __future__ import annotations

import pytest


@pytest.fixture(scope="module", params=["pr2", "tiago", "tiago-pro"])
def robot(request):
    """A world and its robot (loaded with ``pycram.robots.load``), active for the module."""
    pytest.importorskip("mujoco")
    from pycram import robots
    from pycram.sim import World

    world = World(request.param)
    loaded = robots.load(request.param, world)
    with loaded:
        yield loaded
    loaded.shutdown()
    world.close()
