"""Fixtures for simulation tests: one world per robot, shared by the tests of a module."""

from __future__ import annotations

import pytest

pytest.importorskip("mujoco")

ROBOTS = ("pr2", "tiago")


@pytest.fixture(scope="module", params=ROBOTS)
def world(request):
    """A running world for each robot (shared within the module; tests must leave it usable)."""
    from pycram.sim import World

    w = World(request.param)
    yield w
    w.close()
