"""The report's statistics against published values and independent formulas."""
import math

import numpy as np
import pytest
from scipy import stats

from drake_entry.campaign.statistics import (
    describe,
    order_statistic_bound,
    order_statistic_rank,
    runs_for_bound,
    success_lower_bound,
)
from drake_entry.errors import ScenarioError


@pytest.mark.parametrize("runs, level", [(100, 0.90), (100, 0.95), (1000, 0.90), (30, 0.95)])
def test_all_successes_bound_is_the_closed_form(runs, level):
    """n successes in n runs: the one-sided Clopper-Pearson bound is (1 - level)^(1/n) (0.9772 at
    90 % and 0.9705 at 95 % for 100 of 100; the 'rule of three' 1 - 3/n is its approximation)."""
    assert success_lower_bound(runs, runs, level) == pytest.approx((1.0 - level) ** (1.0 / runs), rel=1e-9)
    if level == 0.95:
        assert success_lower_bound(runs, runs, level) == pytest.approx(1.0 - 3.0 / runs, abs=0.15 / runs)


@pytest.mark.parametrize("k, n", [(37, 50), (1, 10), (990, 1000), (95, 100)])
def test_clopper_pearson_is_the_beta_quantile(k, n):
    """The exact lower bound is the (1 - level) quantile of Beta(k, n - k + 1) (Clopper & Pearson 1934)."""
    for level in (0.90, 0.95):
        assert success_lower_bound(k, n, level) == pytest.approx(stats.beta.ppf(1.0 - level, k, n - k + 1), rel=1e-9)
    assert success_lower_bound(0, n, 0.9) == 0.0


def test_bad_counts_are_named():
    with pytest.raises(ScenarioError, match="successes must be an integer in"):
        success_lower_bound(11, 10, 0.9)
    with pytest.raises(ScenarioError, match="level must be in"):
        success_lower_bound(5, 10, 0.3)


@pytest.mark.parametrize("coverage, confidence, runs", [(0.95, 0.95, 59), (0.95, 0.99, 90), (0.99, 0.90, 230),
                                                        (0.99, 0.95, 299), (0.99, 0.99, 459)])
def test_wilks_first_order_run_counts_are_the_published_ones(coverage, confidence, runs):
    """Wilks' one-sided first-order sample sizes (the 59 runs of 95 %/95 %, as used in nuclear
    safety and EDL Monte-Carlo practice; 230 for 99 %/90 %)."""
    assert runs_for_bound(coverage, confidence) == runs
    assert order_statistic_rank(runs, coverage, confidence) == 1
    assert order_statistic_rank(runs - 1, coverage, confidence) == 0


def test_second_order_needs_93_runs_for_95_95():
    """The second largest of 93 runs bounds the 95 % quantile at 95 % confidence (Wilks, second order)."""
    assert order_statistic_rank(93, 0.95, 0.95) == 2 and order_statistic_rank(92, 0.95, 0.95) == 1


def test_order_statistic_bound_covers_its_quantile_as_often_as_claimed():
    """Over 4000 samples of 230 standard normals the maximum exceeds the 99 % quantile in
    1 - 0.99^230 = 90.1 % of them (within 3 binomial sigmas)."""
    rng = np.random.default_rng(7)
    q99 = stats.norm.ppf(0.99)
    hits = np.mean([order_statistic_bound(rng.standard_normal(230)) >= q99 for _ in range(4000)])
    expected = 1.0 - 0.99 ** 230
    assert abs(hits - expected) < 3.0 * math.sqrt(expected * (1 - expected) / 4000)
    assert order_statistic_bound(rng.standard_normal(100)) is None  # 100 runs cannot bound 99 %/90 %
    assert order_statistic_bound(np.arange(300.0), upper=False) == order_statistic_rank(300) - 1


def test_describe_reports_only_resolved_percentiles():
    """P1 and P99 from 100 samples are order statistics; P0.13 and P99.87 need 770 and are None."""
    d = describe(np.arange(100.0))
    assert d["n"] == 100 and d["min"] == 0.0 and d["max"] == 99.0 and d["p50"] == pytest.approx(49.5)
    assert d["p1"] == pytest.approx(0.99) and d["p99"] == pytest.approx(98.01)
    assert d["p0.13"] is None and d["p99.87"] is None
    assert d["sigma"] == pytest.approx(np.std(np.arange(100.0), ddof=1))
    big = describe(np.arange(1000.0))
    assert big["p0.13"] == pytest.approx(1.2987) and big["p99.87"] == pytest.approx(997.7013)
    assert describe([np.nan, np.inf])["n"] == 0
