"""The set-table plan's round budget (`ROUND_TIME_BUDGET`) bounds fetching the object, not the
search for it: a search through a big kitchen's containers may take longer than the budget."""

from __future__ import annotations

import pytest

import pycram.apps.scenarios.set_table.plan as plan
from pycram.core.runtime.evaporation import sleep
from pycram.execution.robot import Robot

BUDGET = 0.3  # [s] of the active clock (wall time here: no world)


@pytest.fixture
def fake_plan(monkeypatch):
    """The plan's world-facing steps replaced: `find` takes `times['search']` [s], `Transport`
    takes `times['fetch']` [s]; what was done is noted in `done`."""
    times = {"search": 0.0, "fetch": 0.0}
    done: list[str] = []

    def find(type_name, record=None):
        sleep(times["search"])
        done.append(f"found {type_name}")
        return f"{type_name}-1"

    def perform(designator):
        sleep(times["fetch"])
        done.append(f"brought {designator}")

    monkeypatch.setattr(plan, "ROUND_TIME_BUDGET", BUDGET)
    monkeypatch.setattr(plan, "find", find)
    monkeypatch.setattr(plan, "perform", perform)
    monkeypatch.setattr(plan, "Transport", lambda found, point: found)
    monkeypatch.setattr(plan, "held_objects", dict)
    monkeypatch.setattr(plan, "close_opened_containers", list)
    return times, done


def _bring_the_bowl() -> plan.SettingOutcome:
    outcome = plan.SettingOutcome(plan.PlaceSetting("bowl", (4.0, 2.0, 0.8)))
    with Robot("fake"):
        plan._bring(outcome, None, plan.PlanRecord())
    return outcome


def test_a_search_longer_than_the_budget_still_brings_the_object(fake_plan):
    times, done = fake_plan
    times["search"] = 2 * BUDGET
    outcome = _bring_the_bowl()
    assert outcome.placed and outcome.failure is None and outcome.attempts == []
    assert done == ["found bowl", "brought bowl-1"]


def test_fetching_longer_than_the_budget_runs_out_in_each_round(fake_plan):
    times, done = fake_plan
    times["fetch"] = 10 * BUDGET
    outcome = _bring_the_bowl()
    assert not outcome.placed and isinstance(outcome.failure, TimeoutError)
    assert len(outcome.attempts) == plan.ROUNDS
    assert all("fetch the bowl" in attempt and "TimeoutError" in attempt for attempt in outcome.attempts)
    assert done == ["found bowl"] * plan.ROUNDS  # evaporated: never brought
