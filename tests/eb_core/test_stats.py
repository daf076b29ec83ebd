"""eb_core.stats: interval coverage by simulation, paired tests on constructed outcomes, determinism."""

import math

import numpy as np
import pytest

from eb_core.stats import (
    cluster_bootstrap_interval,
    mcnemar_exact,
    min_detectable_difference,
    outcome_matrix,
    paired_comparison,
    rate_interval,
    repeat_sd,
    wilson_interval,
)

SIMS = 2000


def coverage(lo, hi, truth):
    return float(np.mean((lo <= truth) & (truth <= hi)))


@pytest.mark.parametrize(("n_tasks", "p"), [(50, 0.3), (60, 0.5), (300, 0.4)])
def test_wilson_interval_covers_p_95_percent_of_the_time(n_tasks, p):
    """2,000 simulated single-repeat runs of Bernoulli tasks with a known success probability."""
    rng = np.random.default_rng(7)
    outcomes = rng.random((SIMS, n_tasks)) < p
    lo, hi = wilson_interval(outcomes.sum(axis=1), n_tasks)
    assert 0.93 <= coverage(lo, hi, p) <= 0.97
    # the production path on one of those runs gives the same interval
    one = rate_interval(outcomes[0].astype(float)[:, None], binary=True)
    assert one["ci_method"] == "wilson" and one["ci_low"] == pytest.approx(lo[0]) and one["ci_high"] == pytest.approx(hi[0])


@pytest.mark.parametrize(("n_tasks", "repeats"), [(60, 3), (50, 5)])
def test_cluster_bootstrap_covers_the_task_population_mean(n_tasks, repeats):
    """Tasks differ (p_i from a Beta), each is played `repeats` times; the target is the mean of the p_i's
    distribution. All 2,000 simulated runs share one set of bootstrap draws (one matrix product)."""
    rng = np.random.default_rng(11)
    a, b = 1.0, 1.5
    truth = a / (a + b)
    p_i = rng.beta(a, b, size=(SIMS, n_tasks, 1))
    played = (rng.random((SIMS, n_tasks, repeats)) < p_i).astype(float)
    lo, hi = cluster_bootstrap_interval(played.mean(axis=2))
    assert 0.93 <= coverage(lo, hi, truth) <= 0.97
    one = rate_interval(played[0], binary=True)
    assert one["ci_method"] == "cluster-bootstrap" and one["repeats"] == repeats
    assert one["ci_low"] == pytest.approx(lo[0]) and one["ci_high"] == pytest.approx(hi[0])


def test_intervals_are_deterministic_and_bracket_the_estimate():
    rng = np.random.default_rng(3)
    m = (rng.random((60, 3)) < 0.4).astype(float)
    first, second = rate_interval(m, binary=True), rate_interval(m.copy(), binary=True)
    assert first == second
    assert first["ci_low"] < first["mean"] < first["ci_high"]


def test_all_solved_still_has_an_interval():
    r = rate_interval(np.ones((60, 3)), binary=True)
    assert r["mean"] == 1.0 and r["ci_high"] == 1.0 and 0.9 < r["ci_low"] < 0.96  # Wilson on 60/60 tasks
    assert rate_interval(np.zeros((0, 1)), binary=True)["ci_low"] is None


def test_repeat_sd_is_the_spread_of_per_repeat_rates():
    m = np.array([[1, 0, 1], [1, 1, 0], [0, 0, 1], [1, 0, 0]], dtype=float)  # per-repeat rates .75 .25 .5
    assert repeat_sd(m) == pytest.approx(np.std([0.75, 0.25, 0.5], ddof=1))
    assert repeat_sd(m[:, :1]) is None
    m[0, 2] = np.nan  # repeat 2 incomplete: only repeats 0 and 1 count
    assert repeat_sd(m) == pytest.approx(np.std([0.75, 0.25], ddof=1))


def test_outcome_matrix_puts_repeats_in_columns():
    ids, m = outcome_matrix({"b": {1: 1.0}, "a": {0: 1.0, 1: 0.0}})
    assert ids == ["a", "b"] and m.shape == (2, 2) and np.isnan(m[1, 0]) and m[1, 1] == 1.0


def test_mcnemar_exact_matches_the_binomial_tail():
    a = np.array([1] * 2 + [0] * 8 + [1] * 5 + [0] * 5, dtype=bool)
    b = np.array([0] * 2 + [1] * 8 + [1] * 5 + [0] * 5, dtype=bool)
    # 2 tasks only A solved, 8 only B: p = 2 * P(X <= 2), X ~ Bin(10, 1/2)
    expected = 2 * sum(math.comb(10, k) for k in range(3)) / 2 ** 10
    assert mcnemar_exact(a, b) == pytest.approx(expected) == pytest.approx(0.109375)
    assert mcnemar_exact(a, a) == 1.0


def test_paired_identical_runs_are_not_significant():
    rng = np.random.default_rng(5)
    a = (rng.random(60) < 0.5).astype(float)
    res = paired_comparison(a, a.copy())
    assert res["test"] == "mcnemar-exact" and res["p_value"] == 1.0 and not res["significant"]
    assert res["diff"] == 0.0 and res["ci_low"] == 0.0 == res["ci_high"]
    rep = (rng.random((60, 3)) < 0.5).astype(float)
    res3 = paired_comparison(rep, rep.copy())
    assert res3["test"] == "paired-bootstrap" and res3["p_value"] == 1.0 and not res3["significant"]


def test_paired_twenty_more_solved_of_sixty_is_significant():
    a = np.zeros(60)
    a[:15] = 1
    b = a.copy()
    b[15:35] = 1  # B solves the same 15 and 20 more
    res = paired_comparison(a, b)
    assert res["test"] == "mcnemar-exact" and res["significant"]
    assert res["p_value"] == pytest.approx(2 / 2 ** 20)
    assert res["diff"] == pytest.approx(20 / 60) and 0 < res["ci_low"] < res["diff"] < res["ci_high"]
    # the same with three repeats each (B's extra tasks solved in 2 of 3 repeats): paired bootstrap
    a3 = np.repeat(a[:, None], 3, axis=1)
    b3 = a3.copy()
    b3[15:35, :2] = 1
    res3 = paired_comparison(a3, b3)
    assert res3["test"] == "paired-bootstrap" and res3["significant"] and res3["ci_low"] > 0


def test_a_small_difference_on_few_tasks_is_not_significant():
    a = np.zeros(50)
    a[:20] = 1
    b = a.copy()
    b[20:23] = 1  # 3 more of 50
    res = paired_comparison(a, b)
    assert not res["significant"] and res["ci_low"] <= 0 <= res["ci_high"]


def test_min_detectable_difference():
    # two independent rates near 50 % on 300 tasks: (1.96 + 0.84) * sqrt(2 * 0.25 / 300)
    assert min_detectable_difference(300, 0.5) == pytest.approx((1.959964 + 0.841621) * math.sqrt(0.5 / 300),
                                                                 rel=1e-4)
