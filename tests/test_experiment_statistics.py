"""Success rates with 95 % confidence intervals (Wilson) and differences beyond the noise
(Newcombe), checked against published values and against a simulation of the noise."""

from __future__ import annotations

import random

import pytest

from pycram.apps.experiments.statistics import Z_95, compare_rates, wilson_interval


@pytest.mark.parametrize(
    ("successes", "runs", "low", "high"),
    [
        # Newcombe (1998), table I: 81/263, 15/148, 0/20, 1/29
        (81, 263, 0.2553, 0.3662),
        (15, 148, 0.0624, 0.1605),
        (0, 20, 0.0, 0.1611),
        (1, 29, 0.0061, 0.1718),
        (195, 200, 0.9428, 0.9893),
    ],
)
def test_wilson_intervals_match_published_values(successes, runs, low, high):
    got = wilson_interval(successes, runs)
    assert got == pytest.approx((low, high), abs=5e-5)


def test_an_interval_holds_its_rate_and_stays_inside_zero_to_one():
    for runs in (1, 5, 24, 200):
        for successes in range(runs + 1):
            low, high = wilson_interval(successes, runs)
            assert 0.0 <= low <= successes / runs <= high <= 1.0
    assert wilson_interval(0, 0) == (0.0, 1.0)  # no runs: nothing known
    with pytest.raises(ValueError, match="successes <= runs"):
        wilson_interval(3, 2)


def test_the_difference_interval_matches_newcombes_example():
    # Newcombe (1998), table II, example (a): 56/70 - 48/80, method 10: 0.0524 to 0.3339
    difference = compare_rates(56, 70, 48, 80)
    assert difference.difference == pytest.approx(0.2)
    assert (difference.low, difference.high) == pytest.approx((0.0524, 0.3339), abs=5e-4)
    assert difference.beyond_noise
    assert "larger than the noise" in difference.describe()


def test_the_set_table_variant_measured_twice_differs_only_within_the_noise():
    # docs/set-table.md reported one variant at 22/24, then 20/24 on the same code
    difference = compare_rates(22, 24, 20, 24)
    assert not difference.beyond_noise
    assert difference.describe().startswith("+8.3 pp") and "within the noise" in difference.describe()


def test_a_95_percent_interval_covers_the_true_rate_about_95_percent_of_the_time():
    rng = random.Random(7)
    true_rate, runs, trials = 0.9, 50, 2000
    covered = 0
    for _ in range(trials):
        successes = sum(rng.random() < true_rate for _ in range(runs))
        low, high = wilson_interval(successes, runs)
        covered += low <= true_rate <= high
    assert 0.92 <= covered / trials <= 0.98
    assert Z_95 == pytest.approx(1.96, abs=1e-3)


# -- in the report and on the command line ---------------------------------------------------------


def _runs(robot: str, variant: str, successes: int, failures: int) -> list:
    from pycram.apps.experiments.store import RunRecord

    ok = [RunRecord(robot, seed, variant, "done", True, [], 10.0, 1.0) for seed in range(successes)]
    bad = [RunRecord(robot, 1000 + s, variant, "done", False, ["GraspFailed"], 12.0, 1.0) for s in range(failures)]
    return ok + bad


def test_the_summary_table_shows_each_success_rate_with_its_interval():
    from rich.console import Console

    from pycram.apps.experiments import report

    groups = report.summarize(_runs("pr2", "", 195, 5) + _runs("tiago", "", 150, 50))
    console = Console(width=200, record=True)
    console.print(report.summary_table(groups))
    text = console.export_text()
    assert "95 % CI" in text
    assert "94.3-98.9 %" in text and "68.6-80.5 %" in text, text


def test_comparisons_say_which_differences_are_beyond_the_noise():
    from pycram.apps.experiments import report

    groups = report.summarize(
        _runs("pr2", "", 22, 2)
        + _runs("pr2", "taken", 20, 4)
        + _runs("tiago", "", 12, 12)
        + _runs("tiago", "taken", 10, 14)
    )
    lines = report.comparisons(groups)
    assert any(line.startswith("pr2: faults taken vs none: 20/24 vs 22/24, -8.3 pp") for line in lines), lines
    assert all("within the noise" in line for line in lines if "vs none" in line), lines
    between_robots = [line for line in lines if line.startswith("faults none: pr2 vs tiago")]
    assert between_robots and "larger than the noise" in between_robots[0], lines
    reference = report.summarize(_runs("pr2", "", 12, 12))
    against = report.comparisons(groups, reference=reference)
    assert against == [
        "pr2, faults none: this vs reference: 22/24 vs 12/24, " + report.compare_rates(22, 24, 12, 24).describe()
    ]
    assert "larger than the noise" in against[0]


def test_an_experiment_is_compared_with_an_earlier_one_from_the_database(tmp_path):
    pytest.importorskip("sqlalchemy")
    from typer.testing import CliRunner

    from pycram.apps.cli import app

    db = tmp_path / "t.sqlite3"
    common = ["--scenario", "pycram.testing:scenario_double", "--robot", "pr2", "--seeds", "1-9", "--workers", "1"]
    common += ["--db", str(db), "--output", str(tmp_path / "out")]
    first = CliRunner().invoke(app, ["experiment", *common, "--faults", "drop", "--name", "before"])
    assert first.exit_code == 0, first.output
    second = CliRunner().invoke(
        app, ["experiment", *common, "--faults", "none", "--name", "after", "--compare", "before"]
    )
    assert second.exit_code == 0, second.output
    text = " ".join(second.output.split())
    assert "compared with experiment 1 (before):" in text
    assert "(no robot and variant in common)" in text  # `none` against `drop`: nothing to pair
    third = CliRunner().invoke(
        app, ["experiment", *common, "--faults", "drop", "--name", "again", "--compare", "before"]
    )
    text = " ".join(third.output.split())
    assert "pr2, faults drop: this vs reference: 6/9 vs 6/9, +0.0 pp" in text and "within the noise" in text, text
    missing = CliRunner().invoke(app, ["experiment", *common, "--compare", "nope"])
    assert missing.exit_code == 2 and "nope" in missing.output
