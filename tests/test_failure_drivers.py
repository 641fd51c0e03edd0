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
