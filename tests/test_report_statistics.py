"""The report's statistics against published values and independent formulas."""
import math

import numpy as np
import pytest
from scipy import stats

from drake_entry.campaign.statistics import (
    convergence_counts,
    describe,
    order_statistic_bound,
    order_statistic_rank,
    running_estimates,
    runs_for_bound,
    success_lower_bound,
    success_upper_bound,
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


def test_describe_mean_and_a_single_sample():
    """The mean is numpy's; one sample has sigma 0 and only its median resolved (P50 needs one
    sample, P1 and P99 a hundred); NaN and inf are dropped before counting."""
    x = np.array([3.0, 1.0, 4.0, 1.0, 5.0, np.nan, np.inf])
    d = describe(x)
    assert d["n"] == 5 and d["mean"] == pytest.approx(2.8) and d["sigma"] == pytest.approx(np.std(x[:5], ddof=1))
    one = describe([7.5])
    assert one == {"n": 1, "min": 7.5, "mean": 7.5, "sigma": 0.0, "max": 7.5, "p0.13": None, "p1": None,
                   "p50": 7.5, "p99": None, "p99.87": None}
    two = describe([1.0, 3.0])
    assert two["sigma"] == pytest.approx(math.sqrt(2.0)) and two["p50"] == 2.0


@pytest.mark.parametrize("call, field", [
    (lambda: success_lower_bound(1, 1, 0.5), "level"), (lambda: success_lower_bound(1, 1, 1.0), "level"),
    (lambda: success_lower_bound(0, 0, 0.9), "runs"), (lambda: runs_for_bound(0.0, 0.9), "coverage"),
    (lambda: runs_for_bound(0.99, 1.0), "confidence"), (lambda: order_statistic_rank(10, 1.0, 0.9), "coverage"),
    (lambda: order_statistic_rank(10, 0.9, 0.0), "confidence")])
def test_the_open_intervals_exclude_their_ends_and_name_the_field(call, field):
    with pytest.raises(ScenarioError, match=f"^{field} must be"):
        call()


def test_the_smallest_cases_at_the_ends_of_the_ranges():
    """One run, one success: the exact (Clopper-Pearson) lower bound is 1 - level; just inside
    (0.5, 1) is allowed. The maximum of
    runs_for_bound samples is the last rank that qualifies (r = runs exactly when even the
    smallest sample bounds the quantile: runs = 1, coverage 0.5, confidence 0.5)."""
    assert success_lower_bound(1, 1, 0.9) == pytest.approx(0.1)
    assert success_lower_bound(1, 1, 0.5000001) == pytest.approx(0.4999999)
    assert order_statistic_rank(runs_for_bound(0.9, 0.9), 0.9, 0.9) == 1
    assert order_statistic_rank(1, 0.5, 0.5) == 1 and order_statistic_rank(3, 0.5, 0.1) == 3
    assert runs_for_bound(0.5, 0.75) == 2  # 1 - 0.5^2 = 0.75 exactly: two runs suffice


def test_order_statistic_bound_uses_the_confidence_it_is_given():
    """At 90 % coverage and 50 % confidence 30 samples allow a deeper rank than at 90 %
    confidence: the bound is that rank's sample, from both ends."""
    x = np.arange(30.0)
    r50, r90 = order_statistic_rank(30, 0.9, 0.5), order_statistic_rank(30, 0.9, 0.9)
    assert r50 > r90 >= 1
    assert order_statistic_bound(x, 0.9, 0.5) == x[-r50] and order_statistic_bound(x, 0.9, 0.9) == x[-r90]
    assert order_statistic_bound(x, 0.9, 0.5, upper=False) == x[r50 - 1]


def test_running_estimates_are_those_of_each_prefix():
    """At every count n: the success fraction and the one-sided bounds of the first n samples,
    and the percentiles of their values (P1 and P99 only from 100 values, as the report's)."""
    rng = np.random.default_rng(7)
    success = rng.random(300) < 0.9
    miss = rng.lognormal(0.0, 1.0, 300)
    miss[5] = np.nan  # a sample that did not reach the interface
    est = running_estimates(success, {"miss": miss}, level=0.95)
    n = np.array(est["n"])
    assert n[0] == 1 and n[-1] == 300 and np.all(np.diff(n) > 0) and set(range(1, 21)) <= set(n.tolist())
    assert np.array_equal(convergence_counts(300), n) and list(convergence_counts(7)) == list(range(1, 8))
    for i in (0, 19, 40, len(n) - 1):
        k, m = int(success[:n[i]].sum()), int(n[i])
        assert est["fraction"][i] == k / m
        assert est["lower"][i] == success_lower_bound(k, m, 0.95) and est["upper"][i] == success_upper_bound(k, m, 0.95)
        v = miss[:m][np.isfinite(miss[:m])]
        assert est["quantities"]["miss"]["p50"][i] == pytest.approx(np.percentile(v, 50))
        assert est["quantities"]["miss"]["max"][i] == v.max()
        assert (est["quantities"]["miss"]["p99"][i] is None) == (v.size < 100)
    assert est["quantities"]["miss"]["p99"][-1] == pytest.approx(np.percentile(miss[np.isfinite(miss)], 99))


def test_a_cloud_in_separate_arms_has_several_modes_and_no_normal_ellipse(tmp_path):
    """One normal cloud (with a far outlier, or skewed) has 1 mode along its principal axes; three
    separate arms have 3, two clusters 2.5 sigma apart each side of 0 have 2; the footprint then
    draws no 99 % normal ellipse and its caption says why."""
    from drake_entry.campaign.report_figures import footprint
    from drake_entry.campaign.statistics import principal_axis_modes

    rng = np.random.default_rng(1)
    assert principal_axis_modes(*rng.normal(size=(2, 300))) == 1
    assert principal_axis_modes(*np.hstack([rng.normal(size=(2, 99)), [[50.0], [0.0]]])) == 1
    assert principal_axis_modes(*rng.lognormal(size=(2, 300))) == 1
    arms = np.hstack([0.5 * rng.normal(size=(2, 100)) + np.array([[c], [0.0]]) for c in (-6.0, 0.0, 6.0)])
    assert principal_axis_modes(*arms) == 3
    assert principal_axis_modes(*np.hstack([rng.normal(size=(2, 150)) + np.array([[c], [0.0]])
                                            for c in (-2.5, 2.5)])) == 2
    assert principal_axis_modes([0.0, 1.0, 2.0], [0.0, 1.0, 2.0]) == 1  # too few points to tell
    _, caption = footprint(arms[0], arms[1], str(tmp_path), "arms", radius_km=5.0)
    assert "No normal ellipse: the cloud is not one cluster (3 modes" in caption
    _, caption = footprint(*rng.normal(size=(2, 300)), str(tmp_path), "normal", radius_km=5.0)
    assert "The ellipse holds 99 % of a normal distribution" in caption and "red crosses" not in caption
    failed = np.arange(300) % 50 == 0
    _, caption = footprint(*rng.normal(size=(2, 300)), str(tmp_path), "normal", radius_km=5.0, failed=failed)
    assert "the 6 not successful drawn as red crosses on top" in caption


def test_path_figure_draws_failed_samples_on_top_and_the_total_load_where_limited(tmp_path):
    """Two stored samples, one not successful: the caption says so; a vehicle limiting the total
    load gets its panel (four axes), one without it three."""
    import types

    from drake_entry.campaign.report_figures import path_quantities
    from drake_entry.figures import plt
    from drake_entry.models.verdict import PathLimit

    t = np.linspace(0.0, 1.0, 20)
    traj = {"sample": [0] * 20 + [1] * 20, "energy_J_kg": list(-t) * 2,
            "dynamic_pressure_Pa": list(1e4 * t) * 2, "heat_flux_W_m2": list(1e5 * t) * 2,
            "normal_load_g": list(t) * 2, "total_load_g": list(1.1 * t) * 2}
    limits = types.SimpleNamespace(dynamic_pressure_max=2e4, heat_flux_max=5e5, normal_load_max=2.5,
                                   total_load_max=2.0)
    figures, made = [], []
    real_subplots = plt.subplots

    def counting(*a, **k):
        fig, axes = real_subplots(*a, **k)
        figures.append(len(np.atleast_1d(axes)))
        made.append(np.atleast_1d(axes))
        return fig, axes

    plt.subplots = counting
    try:
        _, caption = path_quantities(traj, str(tmp_path), "t", limits, failed=[1, 7])
        limits.total_load_max = math.inf
        path_quantities(traj, str(tmp_path), "t", limits)
        # a mission's bound on a state (paper 001's flight-path bounds) gets a panel of its own
        traj["flight_path_deg"] = list(-31.0 * t) * 2
        gamma = PathLimit("flight_path", "gamma", upper=math.radians(0.5), lower=math.radians(-30.0), unit="deg",
                          scale=180.0 / math.pi)
        path_quantities(traj, str(tmp_path), "t", limits, mission_limits=[gamma], failed=[1])
        axes = made[-1]
    finally:
        plt.subplots = real_subplots
    assert "not successful in red, on top: 1" in caption and "of the 2 stored trajectories" in caption
    assert figures == [4, 3, 4]
    bounds = sorted(line.get_ydata()[0] for line in axes[-1].get_lines() if line.get_linestyle() == ":")
    assert bounds == pytest.approx([-30.0, 0.5]) and axes[-1].get_ylabel() == "flight path [deg]"
    assert min(axes[-1].get_lines()[1].get_ydata()) == pytest.approx(-31.0)  # the failed dive, past -30
    legend = [t.get_text() for t in axes[0].get_legend().get_texts()]
    assert legend[:2] == ["successful (1)", "not successful (1)"], legend  # both groups named with their counts


def _recording_subplots(call):
    """(call()'s result, the axes of every figure pyplot.subplots made during it)."""
    from drake_entry.figures import plt

    made, real_subplots = [], plt.subplots

    def keeping(*a, **k):
        fig, axes = real_subplots(*a, **k)
        made.append(axes)
        return fig, axes

    plt.subplots = keeping
    try:
        return call(), made
    finally:
        plt.subplots = real_subplots


def test_margin_figure_shows_a_lower_bound_breach_the_path_panels_cannot(tmp_path):
    """Three flights' margins to a 12-kPa floor (+8 %, +3 %, -1.2 %: the last one not successful)
    and to a vehicle 'no limit': the floor gets a panel whose bins meet at the limit, the breach
    sits left of 0 in red, the worst sample is named by its index; the far limit is named in the
    caption, not drawn; a margin within rounding of 0 sits on the limit."""
    from drake_entry.campaign.report_figures import margin_histograms

    (_, caption), made = _recording_subplots(lambda: margin_histograms(
        {"path_dynamic_pressure": ([0.08, 0.03, -0.012], [False, False, True], ">= 12 kPa"),
         "dynamic_pressure": ([0.999, 0.999, 0.999], [False, False, True], "<= 1e+06 kPa")},
        str(tmp_path), "t", samples=[4, 9, 17]))
    axes = made[-1]
    assert [ax.get_visible() for ax in axes.flat] == [True]
    ax = axes.flat[0]
    red = [p for p in ax.patches if p.get_facecolor()[0] > 0.7 and p.get_height() > 0]
    assert len(red) == 1 and red[0].get_x() < -1.2 and red[0].get_x() + red[0].get_width() <= 1e-12
    w = red[0].get_width()  # every edge a whole number of widths from 0: 0 is an edge
    assert all(p.get_x() / w == pytest.approx(round(p.get_x() / w), abs=1e-9) for p in ax.patches)
    legend = [t.get_text() for t in ax.get_legend().get_texts()]
    assert "limit >= 12 kPa" in legend and "worst -1.20 % (sample 17)" in legend, legend
    assert "Not drawn" in caption and "dynamic pressure <= 1e+06 kPa" in caption
    assert margin_histograms({"x": ([np.nan], [True], "")}, str(tmp_path), "t") is None
    # a bank clamped at its limit reads -1e-16: on the limit, not past it (models.verdict.ROUNDING)
    _, made = _recording_subplots(lambda: margin_histograms({"bank": ([-1e-16, 0.05, 0.1], [False] * 3, "")},
                                                             str(tmp_path), "t"))
    ax = made[-1].flat[0]
    assert min(p.get_x() for p in ax.patches if p.get_height() > 0) == pytest.approx(0.0, abs=1e-12)
    assert "worst +0.00 % (sample 0)" in [t.get_text() for t in ax.get_legend().get_texts()]


def test_drag_figure_shows_the_tracking_error_with_the_failed_samples_on_top(tmp_path):
    """Sample 0 flies 10 % above its reference, sample 1 (not successful) 5 % below: the right
    panel plots +10 % and -5 % where the reference is engaged (> 0), the failed one last and red."""
    from drake_entry.campaign.report_figures import drag_profiles

    t = np.linspace(0.0, 1.0, 20)
    ref = np.where(t > 0.2, 5.0 + 10.0 * t, 0.0)
    traj = {"sample": [0] * 20 + [1] * 20, "energy_J_kg": list(-t) * 2, "reference_drag_m_s2": list(ref) * 2,
            "drag_m_s2": list(np.where(ref > 0, 1.1 * ref, 2.0)) + list(np.where(ref > 0, 0.95 * ref, 2.0))}
    (_, caption), made = _recording_subplots(lambda: drag_profiles(traj, str(tmp_path), "t", failed=[1]))
    lines = [line for line in made[-1][1].get_lines() if len(line.get_ydata()) > 2]
    assert [len(line.get_ydata()) for line in lines] == [int((ref > 0).sum())] * 2
    assert np.allclose(lines[0].get_ydata(), 10.0) and np.allclose(lines[1].get_ydata(), -5.0)
    assert lines[1].get_color() == "C3" and "the 1 not successful in red on top" in caption


def test_a_star_of_arms_from_one_centre_or_far_outliers_get_no_normal_ellipse(tmp_path):
    """A normal cloud fills its contours as a normal does (about 50 % and 99 % inside the 50 % and
    99 % ones); three arms from one centre (one mode: the plan-once swarm footprint's shape), a
    ring, and a normal core with 1 % far outliers do not, and the footprint draws no ellipse and
    says why; fewer than 20 points are not judged."""
    from drake_entry.campaign.report_figures import footprint
    from drake_entry.campaign.statistics import normal_ellipse_fill, principal_axis_modes

    rng = np.random.default_rng(3)
    f50, f99, fits = normal_ellipse_fill(*rng.normal(size=(2, 1000)))
    assert fits and abs(f50 - 0.5) < 0.05 and abs(f99 - 0.99) < 0.01
    r = rng.exponential(1.0, 900)
    angle = np.repeat(np.radians([90.0, 210.0, 330.0]), 300) + 0.02 * rng.normal(size=900)
    star = np.vstack([r * np.cos(angle), r * np.sin(angle)])
    assert principal_axis_modes(*star) == 1 and not normal_ellipse_fill(*star)[2]
    theta = rng.uniform(0.0, 2.0 * np.pi, 1000)
    assert not normal_ellipse_fill(np.cos(theta), np.sin(theta))[2]  # a ring: 0 % inside the 50 % contour
    core = np.hstack([rng.normal(size=(2, 990)), 40.0 * np.ones((2, 10))])
    assert not normal_ellipse_fill(*core)[2]
    assert normal_ellipse_fill(*star[:, :19])[2]  # too few to judge
    _, caption = footprint(star[0], star[1], str(tmp_path), "star", radius_km=5.0)
    assert "No normal ellipse: the samples do not fill a normal's contours" in caption
    _, caption = footprint(*rng.normal(size=(2, 1000)), str(tmp_path), "normal", radius_km=5.0)
    assert "as a normal sample would" in caption


def test_a_footprint_whose_successful_samples_would_be_a_dot_gets_an_inset_on_them(tmp_path):
    """The LGL guidance's SHEFEX-3 footprint: 99 samples within 40 m and one failure 26 km out on a
    25-km ring. The axes span the ring, so the successful core (1.3 x its P99 offset) gets an inset
    in the corner with the fewest samples (not the failure's); a cloud already visible gets none."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from drake_entry.campaign.report_figures import footprint, footprint_core_inset

    rng = np.random.default_rng(5)
    x = np.append(0.003 * rng.normal(size=99), -17.6)
    y = np.append(-0.025 + 0.004 * rng.normal(size=99), 19.9)
    failed = np.arange(100) == 99
    fig, ax = plt.subplots()
    core = footprint_core_inset(ax, x, y, failed, half=27.5)
    good = np.maximum(np.abs(x[:99]), np.abs(y[:99]))
    assert core == pytest.approx(1.3 * np.percentile(good, 99))
    (inset,) = ax.child_axes
    assert inset.get_xlim() == pytest.approx((-core, core)) and inset.get_position().x0 > 0.5  # not the failure's corner
    plt.close(fig)
    fig, ax = plt.subplots()  # a cloud the axes already show: no inset
    assert footprint_core_inset(ax, *rng.normal(size=(2, 100)), np.zeros(100, bool), half=4.0) is None
    assert footprint_core_inset(ax, x[:2], y[:2], np.zeros(2, bool), half=27.5) is None  # too few to zoom on
    assert not ax.child_axes
    plt.close(fig)
    _, caption = footprint(x, y, str(tmp_path), "inset", radius_km=25.0, failed=failed)
    assert f"the inset zooms on the successful samples (+-{core:.3g} km" in caption
