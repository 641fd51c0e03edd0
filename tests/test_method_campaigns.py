"""Small campaigns of the database (paper 003) and swarm (paper 004) guidance under their
scenarios' dispersions, in the default run (the SCvx campaign: example 09's test; drag-energy:
tests/test_guidance_methods.py). Each row's verdict is recomputed here from its own numbers
against the papers' limits and the scenario's acceptance box, never read back from the verdict."""
import math

import numpy as np
import pyarrow.parquet as pq
import pytest

from drake_entry.campaign.montecarlo import run_campaign
from drake_entry.campaign.rows import row_problem
from drake_entry.campaign.store import read_rows
from drake_entry.scenario import load_scenario

#: the path limits as the papers state them (peak column: limit, SI)
PAPER_LIMITS = {
    # paper 003 eq. 3: q <= 50 kPa, heat flux <= 6.5 MW/m^2, n <= 10 g
    "shefex3_ampi": {"peak_dynamic_pressure_Pa": 50e3, "peak_heat_flux_W_m2": 6.5e6, "peak_normal_load_g": 10.0},
    # paper 004 eqs. 13-15: heat flux <= 6 MW/m^2, q <= 60 kPa, n <= 2 g
    "cav_h_paper004": {"peak_heat_flux_W_m2": 6e6, "peak_dynamic_pressure_Pa": 60e3, "peak_total_load_g": 2.0},
}
#: sigma_0 given, so the pre-flight search (110 s; tests/test_swarm_bank.py) is not repeated here
OVERRIDES = {"cav_h_paper004": {"guidance.bank_start_deg": 58.79}}
#: the dispersions each scenario declares, as row columns
DISPERSED = {"shefex3_ampi": ["disp_dh_m", "disp_dlon_deg", "disp_dlat_deg", "disp_dV_m_s", "disp_dgamma_deg",
                              "disp_dpsi_deg"],
             "cav_h_paper004": ["disp_dh_m", "disp_dV_m_s", "disp_density_scale", "disp_lift_scale", "disp_drag_scale"]}


@pytest.mark.parametrize("name", [pytest.param(n, marks=pytest.mark.slow) if n == "cav_h_paper004" else n
                                  for n in sorted(PAPER_LIMITS)])  # paper 004's (11 s of a core): CI's slow set
def test_dispersed_campaign_rows_carry_verdicts_their_numbers_support(name, tmp_path):
    out = run_campaign(name, runs=2, out_dir=str(tmp_path / "mc"), seed=3, workers=1, progress=False,
                       overrides=OVERRIDES.get(name))
    rows = pq.read_table(f"{out}/samples.parquet").to_pandas()
    assert len(rows) == 2 and rows["reached_terminal"].all(), rows["message"].tolist()
    varied = sorted(c for c in rows.columns if c.startswith("disp_") and rows[c].nunique() == 2)
    assert varied == sorted(DISPERSED[name])  # each declared dispersion drawn per sample, and no other
    term = load_scenario(name).terminal
    for _, r in rows.iterrows():
        assert r["inside_distance_box"] == (r["err_distance_m"] <= term.distance_tolerance_km * 1e3)
        assert r["inside_altitude_box"] == (abs(r["box_altitude_error"]) <= term.altitude_tolerance_km * 1e3)
        held = all(r[peak] <= limit for peak, limit in PAPER_LIMITS[name].items())
        assert r["within_limits"] == held, (r["violations"], {p: r[p] for p in PAPER_LIMITS[name]})
        assert r["inside_box"] == all(r[c] for c in rows.columns if c.startswith("inside_") and c.endswith("_box"))
        assert r["success"] == (r["reached_terminal"] and r["inside_box"] and r["within_limits"])
        assert math.isfinite(r["flight_time_s"]) and np.isfinite(r["err_distance_m"])
    streamed = read_rows(out)[0]  # the rows a report reads meet the campaign-row schema
    assert len(streamed) == 2 and all(row_problem(r) == "" for r in streamed.values())
