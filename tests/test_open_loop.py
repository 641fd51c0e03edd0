"""The Drake open-loop diagram against an independent scipy integration of the same equations."""
import numpy as np
import pytest
from reference_open_loop import solve_ivp_open_loop

from drake_entry.diagrams.open_loop import simulate
from drake_entry.scenario import load_scenario


@pytest.fixture(scope="module")
def horus_1500s():
    s = load_scenario("horus2b")
    s.simulation.max_time_s = 1500.0
    s.terminal.altitude_km, s.terminal.mach = 5.0, None  # fly the full 1500 s
    return s


def test_drake_matches_solve_ivp_within_1m_altitude_after_1500s(horus_1500s):
    tr = simulate(horus_1500s)
    sol, _ = solve_ivp_open_loop(horus_1500s, 1500.0, method="DOP853", rtol=1e-11)
    assert tr.time[-1] == pytest.approx(1500.0)
    assert abs(tr.state[-1, 0] - sol.y[0, -1]) < 1.0
    assert abs(tr.state[-1, 3] - sol.y[3, -1]) < 0.1
    r = 6378137.0
    assert r * abs(tr.state[-1, 1] - sol.y[1, -1]) < 5.0 and r * abs(tr.state[-1, 2] - sol.y[2, -1]) < 5.0


def test_run_stops_exactly_on_the_terminal_interface():
    s = load_scenario("horus2b")
    tr = simulate(s)
    assert "altitude" in tr.reason or "mach" in tr.reason
    if "altitude" in tr.reason:
        assert tr.state[-1, 0] == pytest.approx(25000.0, abs=1.0)
    else:
        assert tr.column("mach")[-1] == pytest.approx(2.5, abs=1e-3)
    assert np.all(np.diff(tr.time) > 0)


def test_an_alpha_schedule_in_mach_flies_open_loop():
    """A continuous alpha schedule in Mach reads Mach from the state and the air data (the flight
    conditions depend on alpha: reading them closed an algebraic loop the diagram refused); the
    flown alpha is the schedule at the logged V / a."""
    import dataclasses as dc
    import math

    s = load_scenario("horus2b")
    s.alpha = dc.replace(s.alpha, variable="mach", breakpoints=[3.0, 10.0], values_deg=[15.0, 40.0], smooth=False)
    tr = simulate(s)
    mach = tr.column("mach")
    alpha = np.degrees(tr.alpha)
    expected = np.interp(mach, [3.0, 10.0], [15.0, 40.0])
    assert np.abs(alpha - expected).max() < 1e-6
    assert alpha.min() < 20.0 and alpha.max() == pytest.approx(40.0) and math.isfinite(tr.time[-1])


def test_cli_simulate_writes_table_summary_and_plots(tmp_path):
    """The written table (CSV, 10 significant digits) recomputes from first principles: dynamic
    pressure 0.5 rho V^2, the Chapman heat flux of paper 000 eq. 34 (R_N 0.8 m), the specific
    energy V^2/2 - mu/r with WGS-84's mu and radius (central gravity); summary.json's peaks are
    the table's maxima and its heat load the trapezoid integral of the tabulated heat flux
    (within 0.5 %: 1-s samples); the flight ends on Mach 2.5 as the scenario's terminal interface
    says; six PNG figures."""
    import json

    from drake_entry.cli import main
    from drake_entry.tables import read_table

    assert main(["simulate", "horus2b", "--out", str(tmp_path), "--format", "csv"]) == 0
    t = read_table(str(tmp_path / "trajectory.csv"))
    summary = json.loads((tmp_path / "summary.json").read_text())
    rho, V, h = np.asarray(t["density_kg_m3"]), np.asarray(t["velocity_m_s"]), np.asarray(t["altitude_m"])
    assert h[0] == pytest.approx(122e3) and np.all(np.diff(t["time_s"]) > 0)
    assert np.asarray(t["dynamic_pressure_Pa"]) == pytest.approx(0.5 * rho * V ** 2, rel=1e-8)
    assert np.asarray(t["heat_flux_W_m2"]) == pytest.approx(5.28137e-5 / np.sqrt(0.8) * np.sqrt(rho) * V ** 3.15,
                                                            rel=1e-8)
    mu, R = 3.986004418e14, 6378137.0
    assert np.asarray(t["energy_J_kg"]) == pytest.approx(0.5 * V ** 2 - mu / (R + h), rel=1e-6)
    assert summary["stop"] == "reached mach = 2.5" and summary["final_mach"] == pytest.approx(2.5, abs=1e-6)
    assert summary["peak_heat_flux_W_m2"] >= max(t["heat_flux_W_m2"]) * (1 - 1e-9)  # CSV digits
    assert summary["peak_heat_flux_W_m2"] == pytest.approx(max(t["heat_flux_W_m2"]), rel=2e-3)
    assert summary["heat_load_J_m2"] == pytest.approx(np.trapezoid(t["heat_flux_W_m2"], t["time_s"]), rel=5e-3)
    for png in ("altitude_velocity", "groundtrack", "heat_flux", "dynamic_pressure", "load_factor", "controls"):
        assert (tmp_path / f"{png}.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_cli_reports_bad_scenario_in_one_line(tmp_path, capsys):
    from drake_entry.cli import main

    bad = tmp_path / "bad.yaml"
    bad.write_text("name: x\nvehicle: horus2b\nentry: {altitude_km: 120, velocity_m_s: -5}\nterminal: {mach: 2}\n")
    assert main(["simulate", str(bad)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "entry.velocity_m_s = -5.0 is out of range" in err


def test_cli_plan_writes_figures_3_to_5_and_reports_the_socp(tmp_path, capsys):
    from drake_entry.cli import main

    assert main(["plan", "horus2b", "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "SOCP (clarabel, 40 nodes): optimal" in out and "bank saturated at 0 nodes" in out
    for png in ("corridor", "reference_profile", "extraction_vs_propagation"):
        assert (tmp_path / f"{png}.png").stat().st_size > 20_000


def test_cli_fly_reaches_the_terminal_interface_near_the_runway(tmp_path):
    import json

    from drake_entry.cli import main

    assert main(["fly", "horus2b", "--out", str(tmp_path), "--format", "csv"]) == 0
    s = json.load(open(tmp_path / "summary.json"))
    assert s["success"] and s["err_distance_m"] < 2000.0 and abs(s["err_altitude_m"]) < 200.0
    assert s["peak_heat_flux_W_m2"] <= 530e3 and s["peak_normal_load_g"] <= 2.5 and s["method"] == "drag_energy"
    assert (tmp_path / "drag_tracking.png").exists()
