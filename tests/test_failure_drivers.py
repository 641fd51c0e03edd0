"""What drives the misses and failures (campaign.drivers): on synthetic rows whose failures and
errors are set by known inputs, those inputs come first with significant correlations, a pure-noise
input does not pass the Bonferroni level, and the report shows the section."""
import json

import numpy as np
import pytest

from drake_entry.campaign.drivers import failure_drivers


def _rows(n=200, seed=1):
    rng = np.random.default_rng(seed)
    wind, cl, noise = rng.normal(0, 10, n), rng.normal(0, 0.03, n), rng.normal(0, 1, n)
    range_error = 800.0 * wind + rng.normal(0, 2000, n)  # the wind pushes the range
    margin = 0.1 - 2.0 * cl + rng.normal(0, 0.01, n)  # a larger lift eats the heat-flux margin
    success = (range_error < 10_000) & (margin > 0)  # long by more than 10 km, or a breach
    return {"index": list(range(n)), "success": success.tolist(), "err_range_m": range_error.tolist(),
            "err_distance_m": np.abs(range_error).tolist(), "margin_heat_flux": margin.tolist(),
            "disp_wind_east_30km": wind.tolist(), "disp_dCL_hypersonic": cl.tolist(), "disp_noise": noise.tolist(),
            "disp_constant": [1.0] * n}


def test_the_inputs_that_set_the_outcomes_come_first_and_noise_is_not_significant():
    d = failure_drivers(_rows())
    json.dumps(d)  # goes into summary.json
    ranked = [r["input"] for r in d["inputs"]]
    assert set(ranked[:2]) == {"disp_wind_east_30km", "disp_dCL_hypersonic"}
    assert "disp_constant" not in ranked  # an input that does not vary is no driver
    cells = {r["input"]: r["cells"] for r in d["inputs"]}
    assert cells["disp_wind_east_30km"]["err_range_m"][0] > 0.9 and cells["disp_wind_east_30km"]["err_range_m"][1] < d["level"]
    assert cells["disp_dCL_hypersonic"]["margin_heat_flux"][0] < -0.9
    assert all(p > d["level"] for _, p in cells["disp_noise"].values())
    assert d["level"] == pytest.approx(0.05 / (3 * 4))  # inputs x outcomes (success, miss, range, margin)
    failed = {f["input"]: f for f in d["failures"]}
    assert failed["disp_wind_east_30km"]["median_failed"] > failed["disp_wind_east_30km"]["median_successful"]
    assert failed["disp_wind_east_30km"]["mann_whitney_p"] < 1e-4


def test_too_few_samples_or_no_varying_input_gives_nothing():
    rows = _rows(n=6)
    assert failure_drivers(rows) == {}
    rows = _rows()
    for k in ("disp_wind_east_30km", "disp_dCL_hypersonic", "disp_noise"):
        rows.pop(k)
    assert failure_drivers(rows) == {}


def test_failures_at_both_tails_of_an_input_are_found_where_a_shift_test_sees_nothing():
    """Failures where |density - 1| > 0.2 (both tails): the failed samples' median equals the
    successful ones', so Mann-Whitney sees no shift, but the Kolmogorov-Smirnov test separates
    them and the failures sit in the outer quintiles only."""
    rng = np.random.default_rng(3)
    n = 300
    density, noise = rng.uniform(0.7, 1.3, n), rng.normal(0, 1, n)
    success = np.abs(density - 1.0) <= 0.2
    rows = {"index": list(range(n)), "success": success.tolist(), "err_distance_m": rng.uniform(0, 1e3, n).tolist(),
            "disp_density_scale": density.tolist(), "disp_noise": noise.tolist(),
            "message": ["reached E_f" if ok else "outside the acceptance box: distance error 3 km outside 2 km "
                        "(reached E_f at t = 1 s, 3 km from the target)" for ok in success]}
    d = failure_drivers(rows)
    first = d["failures"][0]
    assert first["input"] == "disp_density_scale" and first["ks_p"] < 1e-6 and first["mann_whitney_p"] > 0.01
    bins = first["failed_by_quintile"]
    assert bins[1] == bins[2] == bins[3] == 0 and bins[0] > 0 and bins[4] > 0 and sum(bins) == (~success).sum()
    (mode,) = d["modes"]
    assert mode["reason"] == "outside the box: distance" and mode["samples"] == (~success).sum()
    assert mode["separating"]["input"] == "disp_density_scale"


def test_failure_modes_are_grouped_by_reason_each_with_its_own_separating_input():
    """Box misses set by the wind, heat-flux breaches by the lift: two groups, each naming its input."""
    rows = _rows()
    n = len(rows["index"])
    long, breach = np.array(rows["err_range_m"]) >= 10_000, np.array(rows["margin_heat_flux"]) <= 0
    rows["message"] = ["reached" if not (lo or br) else " | ".join(
        (["outside the acceptance box: distance error +12 km outside +-10 km"] if lo else [])
        + (["path limits breached: heat_flux 600 kW/m^2 at t = 900.0 s (limit <= 530 kW/m^2, margin -13 %)"]
           if br else [])) + " (reached E_f at t = 1500.0 s, 12 km from the target)"
        for lo, br in zip(long, breach)]
    modes = {m["reason"]: m for m in failure_drivers(rows)["modes"]}
    assert modes["outside the box: distance"]["separating"]["input"] == "disp_wind_east_30km"
    assert modes["breached: heat_flux"]["separating"]["input"] == "disp_dCL_hypersonic"
    assert sum(m["samples"] for m in modes.values()) == n - sum(rows["success"])


def test_pawn_finds_a_non_monotonic_driver_that_rank_correlation_misses_and_not_the_noise():
    """An altitude error set by (x - 0.5)^2 of a uniform input: Spearman near 0, PAWN far above
    the dummies' floor; a pure-noise input stays below its floor; the table goes into summary.json."""
    from drake_entry.campaign.sensitivity import pawn_sensitivity

    rng = np.random.default_rng(5)
    n = 400
    x, wind, noise = rng.uniform(0, 1, n), rng.normal(0, 10, n), rng.normal(0, 1, n)
    rows = {"index": list(range(n)), "success": [True] * n, "disp_cl_shape": x.tolist(),
            "disp_wind_east_30km": wind.tolist(), "disp_noise": noise.tolist(),
            "err_altitude_m": (4e3 * (x - 0.5) ** 2 + rng.normal(0, 20, n)).tolist(),
            "err_range_m": (800.0 * wind + rng.normal(0, 2000, n)).tolist()}
    d = pawn_sensitivity(rows)
    json.dumps(d)
    cells = {r["input"]: r["cells"] for r in d["inputs"]}
    rho = {r["input"]: r["cells"] for r in failure_drivers(rows)["inputs"]}["disp_cl_shape"]["err_altitude_m"]
    assert abs(rho[0]) < 0.2 and rho[1] > 0.01  # rank correlation does not see it
    assert cells["disp_cl_shape"]["err_altitude_m"][1] and cells["disp_cl_shape"]["err_altitude_m"][0] > 0.5
    assert cells["disp_wind_east_30km"]["err_range_m"][1] and not cells["disp_wind_east_30km"]["err_altitude_m"][1]
    assert not any(sig for _, sig in cells["disp_noise"].values())
    assert 0.05 < d["floors"]["err_altitude_m"] < 0.3  # the KS distance of random slices of 40 samples
    assert pawn_sensitivity(_rows(n=30)) == {}  # too few samples for 10 slices
