"""Paper 003's database layer: the eq. 5 grid and its continuation order, Algorithms 1-2
against scipy's RegularGridInterpolator, the eq. 11-12 LD-HD expansion, the database's
synthesis, nearest entry (NTT), consistency check and file round trip."""
import math

import numpy as np
import pytest
from scipy.interpolate import RegularGridInterpolator

from drake_entry.errors import ScenarioError
from drake_entry.guidance.ampi.database import OBJECTIVE_FACTOR, TrajectoryDatabase, hd_matrix
from drake_entry.guidance.ampi.grid import ParameterGrid
from drake_entry.guidance.ampi.synthesis import interpolate, select_subspace
from drake_entry.planning.pseudospectral import lgl_nodes


def test_paper_grid_is_eq_5_and_continuation_reaches_every_case_from_the_nominal():
    grid = ParameterGrid.paper_003()
    assert grid.names == ("h", "lon", "lat", "V", "gamma", "psi") and grid.size == 3 ** 6
    assert grid.offsets(0) == pytest.approx({"h": -250.0, "lon": -math.radians(0.5), "lat": -math.radians(0.5),
                                             "V": -70.0, "gamma": -math.radians(0.5), "psi": -math.radians(0.5)})
    assert [len(w) for w in grid.waves()] == [1, 12, 60, 160, 240, 192, 64]  # C(6, k) 2^k
    centre = grid.index(grid.centre)
    assert grid.waves()[0] == [centre] and grid.parent(centre) is None
    for i in range(grid.size):  # every parent is one step closer, so waves solve in order
        p = grid.parent(i)
        if p is not None:
            assert grid.distance(p) == grid.distance(i) - 1 and p in grid.neighbours(i)
    assert len(grid.neighbours(centre)) == 12 and len(grid.neighbours(0)) == 6


def test_grid_rejects_bad_levels_with_the_field():
    with pytest.raises(ScenarioError, match="'q' is not an entry state"):
        ParameterGrid(("q",), ((0.0, 1.0),))
    with pytest.raises(ScenarioError, match=r"levels\['V'\] = \[1.0, 0.0\]: needs >= 2 finite, strictly increasing"):
        ParameterGrid(("V",), ((1.0, 0.0),))
    with pytest.raises(ScenarioError, match="n_levels = 4: allowed an odd integer >= 3"):
        ParameterGrid.from_steps({"V": 70.0}, n_levels=4)


def test_algorithms_1_and_2_equal_scipy_multilinear_interpolation_inside_and_extrapolated():
    rng = np.random.default_rng(3)
    levels = [np.array([-1.0, 0.0, 1.5]), np.array([0.0, 0.2, 0.4]), np.array([-3.0, 0.0, 3.0]), np.array([5.0, 6.0, 9.0])]
    values = rng.normal(size=(3, 3, 3, 3, 2))
    oracle = RegularGridInterpolator(levels, values, method="linear", bounds_error=False, fill_value=None)
    for _ in range(200):
        x = np.array([rng.uniform(lv[0], lv[-1]) for lv in levels])
        got, outside = interpolate(values, levels, x)
        assert got == pytest.approx(oracle(x)[0], abs=1e-12) and not outside.any()
    x = np.array([2.0, 0.1, -3.0, 5.5])  # above the first dimension's grid: extrapolated, flagged
    got, outside = interpolate(values, levels, x)
    assert got == pytest.approx(oracle(x)[0], abs=1e-12) and list(outside) == [True, False, False, False]
    # Algorithm 1's typo case: a value on a grid point takes the interval it starts
    lower, frac, _ = select_subspace(levels, [0.0, 0.2, 0.0, 9.0])
    assert list(lower) == [1, 1, 1, 1] and frac == pytest.approx([0.0, 0.0, 0.0, 1.0])


def test_ld_hd_matrix_is_exact_for_the_ld_polynomial():
    """Eqs. 11-12: T_HD = P T_LD reproduces every polynomial of degree < N_LD at the HD points."""
    n_ld, n_hd = 12, 101
    tau, hd = lgl_nodes(n_ld), np.linspace(-1.0, 1.0, n_hd)
    P = hd_matrix(n_ld, n_hd)
    for deg in range(n_ld):
        assert P @ tau ** deg == pytest.approx(hd ** deg, abs=1e-11)
    assert np.abs(P @ tau ** n_ld - hd ** n_ld).max() > 1e-6  # degree N_LD is not


def _linear_database(grid, n_ld=9):
    """Each case's trajectory and t_f linear in the offsets (so multilinear synthesis is exact)."""
    db = TrajectoryDatabase.empty(grid, n_ld, ("a", "b"), ("u",))
    tau = lgl_nodes(n_ld)
    for i in range(grid.size):
        p = grid.point(i)
        X = np.column_stack([tau + p.sum(), tau ** 2 * (1.0 + p[0])])
        db.set_case(i, X, (tau * p[-1])[:, None], 600.0 + 0.1 * p[0], 10.0 + 0.01 * p[0], True)
    return db


def test_database_synthesis_expands_stores_and_finds_the_nearest_entry(tmp_path):
    grid = ParameterGrid(("V", "gamma"), ((-70.0, 0.0, 70.0), (-0.01, 0.0, 0.01)))
    db = _linear_database(grid)
    x = np.array([35.0, -0.004])
    s = db.synthesise(x, hd_points=41)
    hd = np.linspace(-1.0, 1.0, 41)
    assert s.final_time == pytest.approx(600.0 + 3.5)
    assert s.states[:, 0] == pytest.approx(hd + x.sum(), abs=1e-9)
    assert s.states[:, 1] == pytest.approx(hd ** 2 * (1.0 + x[0]), abs=1e-9)
    assert s.time[-1] == pytest.approx(s.final_time) and sorted(s.cases) == [3, 4, 6, 7]
    assert db.nearest([40.0, -0.004]) == grid.index((2, 1))
    assert db.reference("ntt", [40.0, -0.004]).cases == [grid.index((2, 1))]
    assert np.array_equal(db.reference("ampi", x, 41).states, s.states)
    with pytest.raises(ScenarioError, match="mode = 'best'; allowed: ampi, ntt"):
        db.reference("best", x)
    path = tmp_path / "db.npz"
    db.save(str(path))
    back = TrajectoryDatabase.load(str(path))
    assert back.grid == grid and np.array_equal(back.values, db.values) and back.verified.all()
    assert db.storage_bytes == 9 * 9 * 3 * 8 + 9 * 8
    db.verified[4] = False
    with pytest.raises(ScenarioError, match=r"database cases \[4\] enclosing offsets .* are not verified"):
        db.synthesise(x)


def test_inconsistent_cases_are_named_with_their_reason():
    grid = ParameterGrid(("V", "gamma"), ((-70.0, 0.0, 70.0), (-0.01, 0.0, 0.01)))
    db = _linear_database(grid)
    assert db.inconsistent() == {}
    db.objective[4] = 2.0 * OBJECTIVE_FACTOR * np.median(db.objective[grid.neighbours(4)])  # a worse branch
    db.final_time[0] += 100.0
    db.verified[8] = False
    bad = db.inconsistent()
    assert "objective" in bad[4] and "t_f" in bad[0] and bad[8] == "not verified"


def test_case_problem_offsets_the_entry_and_keeps_the_geodetic_altitude():
    """Eq. 6: x(t0) = x*(t0) + offsets; an altitude offset is geodetic, and a latitude offset
    keeps the geodetic entry altitude (100.1 km + dh) on the oblate Earth."""
    from drake_entry.guidance.ampi.database_study import case_problem
    from drake_entry.planning.ocp_yaml import load_problem

    problem, _ = load_problem("shefex3")
    grid = ParameterGrid.paper_003()
    planet = problem.planet
    i = grid.index((2, 0, 2, 0, 1, 2))  # h +250 m, lon -0.5, lat +0.5, V -70, gamma 0, psi +0.5 deg
    p = case_problem(problem, grid, i)
    x0, x = problem.initial, p.initial
    assert x["lat"] == pytest.approx(x0["lat"] + math.radians(0.5)) and x["lon"] == pytest.approx(x0["lon"] - math.radians(0.5))
    assert x["V"] == pytest.approx(x0["V"] - 70.0) and x["gamma"] == x0["gamma"]
    assert x["psi"] == pytest.approx(x0["psi"] + math.radians(0.5))
    assert planet.atmospheric_altitude(x["h"], x["lat"]) == pytest.approx(100.1e3 + 250.0, abs=1e-6)
    assert problem.initial is x0 and x0["V"] == 4712.3  # the nominal is untouched


@pytest.mark.slow
def test_database_build_by_continuation_is_verified_resumable_and_stored(tmp_path):
    """A reduced database (V at -35, 0, +35 m/s) through the campaign engine: every case
    verified, the off-nominal ones warm-started from the nominal, consistent, stored at the LD
    nodes; a rerun solves nothing again; the stored LD samples rebuild the solution."""
    from drake_entry.guidance.ampi.database_study import DATABASE_FILE, DatabaseStudy, build_database

    grid = ParameterGrid.from_steps({"V": 35.0})
    study = DatabaseStudy(grid=grid.as_dict(), ld_nodes=60)
    db, report = build_database(str(tmp_path), study, backend="serial", progress=False)
    assert report["verified"] == 3 and report["inconsistent"] == {}
    assert db.verified.all() and np.all(np.diff(db.objective) != 0)
    assert report["storage_MB"] == pytest.approx(3 * 60 * 9 * 8 / 1e6 + 3 * 8 / 1e6)
    back = TrajectoryDatabase.load(str(tmp_path / DATABASE_FILE))
    assert np.array_equal(back.values, db.values)
    from drake_entry.campaign.store import read_rows

    rows, _ = read_rows(str(tmp_path))
    assert rows[0]["guess_from"] == 1 and rows[2]["guess_from"] == 1 and rows[1]["guess_from"] == -1
    again, report2 = build_database(str(tmp_path), study, backend="serial", progress=False)
    assert np.array_equal(again.values, db.values) and report2["re_solved"] == 0
    # the nominal synthesised at offset 0 is the nominal entry itself
    s = db.synthesise([0.0])
    t, X, U = db.case(1)
    assert s.final_time == db.final_time[1] and np.array_equal(s.states, X)
