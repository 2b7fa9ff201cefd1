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
