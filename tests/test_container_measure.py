"""Measuring how far a container is open by looking at its handle (`container_state._measure`),
with a stand-in for the robot's head and perception: a look measures the container only when it
points at where the handle really is."""

from __future__ import annotations

import math

import pytest

from pycram.actions import container_state
from pycram.environments import load
from pycram.world.belief import BeliefState

APARTMENT = load("apartment")
FRIDGE = APARTMENT.container("fridge")


class Head:
    """`motion` for `_measure`: remembers where the head points; a detection measures the fridge
    when the head points at its handle's true position."""

    def __init__(self, belief: BeliefState, true_opening: float) -> None:
        self.belief, self.true_opening = belief, true_opening
        self.looked_at: list[tuple[float, ...]] = []
        self.stamp = 0.0

    def __call__(self, type: str, **kwargs) -> None:
        if type == "pointing_head":
            self.looked_at.append(tuple(kwargs["coordinates"]))
        elif type == "detecting":
            self.stamp += 1.0
            if math.dist(self.looked_at[-1], FRIDGE.handle_position(self.true_opening)) < 1e-6:
                self.belief.container_states["fridge"] = self.true_opening
                self.belief.container_stamps["fridge"] = self.stamp


@pytest.fixture
def belief() -> BeliefState:
    return BeliefState(APARTMENT)


def test_a_look_where_the_container_is_believed_measures_it_and_nothing_more(monkeypatch, belief):
    belief.moved_container("fridge", 1.2)
    head = Head(belief, 1.2)
    monkeypatch.setattr(container_state, "motion", head)
    assert container_state._measure(belief, FRIDGE, then=[0.0]) == pytest.approx(1.2)
    assert head.looked_at == [FRIDGE.handle_position(1.2)]  # measured: no look at the others


def test_where_it_is_not_the_looks_go_on_to_the_openings_named_then(monkeypatch, belief):
    """The hand let go of the door at 69 deg, but had slipped off its handle at once: believed at
    69 deg, the door is measured by the looks that follow, at where it was before."""
    belief.moved_container("fridge", 1.2)
    head = Head(belief, 0.0)
    monkeypatch.setattr(container_state, "motion", head)
    assert container_state._measure(belief, FRIDGE) is None  # only where it is believed: not seen
    head.looked_at.clear()
    assert container_state._measure(belief, FRIDGE, then=[0.6, 0.0]) == pytest.approx(0.0)
    assert head.looked_at == [FRIDGE.handle_position(q) for q in (1.2, 0.6, 0.0)]
