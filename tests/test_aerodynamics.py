import ast

import numpy as np
import pytest

from drake_entry.models.aerodynamics import (
    CallableAero,
    CavHAero,
    DragPolarAero,
    fit_horus_forms,
    horus2b_table,
    horus_cd_form,
    horus_cl_form,
    packaged_data,
)
from drake_entry.models.data_tables import read_csv_rows
from drake_entry.models.vehicles import load_vehicle


@pytest.fixture(scope="module")
def table():
    return horus2b_table()


def _m692_cells(name: str) -> np.ndarray:
    """The published clean M-692 cells of coefficient ``name`` ('CD' or 'CL') as rows (alpha
    [deg], Mach, value), read from the packaged CSV (blank cells left out)."""
    with packaged_data("horus2b_clean_aero_m692.csv") as f:
        rows = read_csv_rows(f)
    mach = [float(h.lstrip("Mm")) for h in rows[0][2:]]
    return np.array([(float(r[1]), m, float(v)) for r in rows[1:] if r[0] == name
                     for m, v in zip(mach, r[2:]) if v.strip()])


def test_table_reproduces_every_cell_of_m692_and_the_2024_fill(table):
    for i, a in enumerate(table.alpha_deg):
        for j, m in enumerate(table.mach):
            cl, cd = table.coefficients(np.radians(a), m)
            assert cl == pytest.approx(table.CL[i, j], abs=1e-12)
            assert cd == pytest.approx(table.CD[i, j], abs=1e-12)


@pytest.mark.parametrize("alpha_deg, mach", [(17.0, 2.6), (33.0, 7.5), (41.0, 14.0)])
def test_table_partials_equal_finite_differences(table, alpha_deg, mach):
    a = np.radians(alpha_deg)
    d = table.derivatives(a, mach)
    e = 1e-6
    for k, c in enumerate((d.CL, d.CD)):
        fa = (table.coefficients(a + e, mach)[k] - table.coefficients(a - e, mach)[k]) / (2 * e)
        fm = (table.coefficients(a, mach + e)[k] - table.coefficients(a, mach - e)[k]) / (2 * e)
        assert c.d_alpha == pytest.approx(fa, rel=1e-6, abs=1e-9)
        assert c.d_mach == pytest.approx(fm, rel=1e-5, abs=1e-9)


def test_table_is_held_constant_above_mach_20(table):
    assert table.coefficients(0.7, 25.0) == pytest.approx(table.coefficients(0.7, 20.0))
    assert table.derivatives(0.7, 25.0).CD.d_mach == 0.0


def test_packaged_horus_fit_residuals_as_documented():
    """horus2b.yaml states C_D RMS 0.0145 and C_L RMS 0.0087 over the published M-692 cells."""
    fit = load_vehicle("horus2b").aero
    for name, form, coefs, rms_doc in (("CD", horus_cd_form, fit.aD, 0.0145), ("CL", horus_cl_form, fit.aL, 0.0087)):
        a, m, data = _m692_cells(name).T
        res = form(coefs, a, m) - data
        assert np.sqrt(np.mean(res**2)) == pytest.approx(rms_doc, abs=1e-4)


@pytest.fixture(scope="module")
def fit_report():
    """The HORUS-2B fit from a generic start, made once (about 20 s)."""
    return fit_horus_forms()


def test_fit_of_paper000_forms_from_a_generic_start(fit_report):
    """C_D is linear in its ten coefficients (eq. 32), so the fit is the least-squares optimum
    exactly when its residual is orthogonal to every basis column (the normal equations, checked
    here on the published cells independently of the solver), and no coefficient change lowers
    the RMS. The RMS itself (0.014509) is a regression pin of that optimum on these 66 cells."""
    rep = fit_horus_forms()
    assert rep.cells_CD == 66 and rep.cells_CL == 63
    cells = _m692_cells("CD")
    basis = np.stack([horus_cd_form(np.eye(10)[k], cells[:, 0], cells[:, 1]) for k in range(10)], -1)
    residual = basis @ rep.aD - cells[:, 2]
    assert np.sqrt(np.mean(residual ** 2)) == pytest.approx(rep.rms_CD, rel=1e-12)
    scale = np.linalg.norm(basis, axis=0) * np.linalg.norm(residual)
    assert np.all(np.abs(basis.T @ residual) <= 1e-8 * scale)  # normal equations
    rng = np.random.default_rng(0)
    for _ in range(20):  # any nearby coefficients fit worse
        other = rep.aD + 1e-3 * rng.standard_normal(10) * np.abs(rep.aD)
        assert np.sqrt(np.mean((basis @ other - cells[:, 2]) ** 2)) > rep.rms_CD
    assert rep.rms_CD == pytest.approx(0.014509, abs=1e-5)  # regression pin (this optimum)
    assert rep.rms_CL < 0.010


def test_drag_polar_alpha_bar_is_paper002_eq19():
    assert DragPolarAero().alpha_max_lift_to_drag == pytest.approx(0.207, abs=5e-4)


def test_cav_h_max_lift_to_drag_is_about_3p4_at_mach_10_to_15():
    m = CavHAero()
    a = np.radians(np.linspace(5, 20, 301))
    ld = m.lift_to_drag(a, 12.0)
    assert ld.max() == pytest.approx(3.4, abs=0.15)
    assert 9.0 <= np.degrees(a[ld.argmax()]) <= 14.0


def test_user_callables_give_exact_autodiff_derivatives():
    m = CallableAero(cl=lambda a, M: 1.5 * np.sin(a) ** 2 / M, cd=lambda a, M: 0.1 + a * a)
    d = m.derivatives(0.3, 5.0)
    assert d.CD.d_alpha == pytest.approx(0.6)
    assert d.CD.d_alpha_alpha == pytest.approx(2.0, rel=1e-6)
    assert d.CL.d_mach == pytest.approx(-1.5 * np.sin(0.3) ** 2 / 25.0)


def test_analytic_horus_drag_partials_equal_autodiff_and_differences():
    from drake_entry.models.aerodynamics import AeroModel

    fit = load_vehicle("horus2b").aero
    for alpha, mach in ((0.6, 7.0), (0.3, 2.4), (0.7, 15.0)):
        analytic, cl = fit.drag_derivatives(alpha, mach)
        generic = AeroModel.derivatives(fit, alpha, mach)
        assert cl == pytest.approx(generic.CL.value, rel=1e-12)
        for field in ("value", "d_alpha", "d_mach", "d_alpha_alpha", "d_alpha_mach", "d_mach_mach"):
            assert getattr(analytic, field) == pytest.approx(getattr(generic.CD, field), rel=1e-5, abs=1e-9), field


def test_sphynx_representative_aero_has_paper001_lift_to_drag():
    """Paper 001 Sec. II.A quotes L/D about 1.2 supersonic and about 2 subsonic; the labelled
    representative model gives max L/D 1.17 at Mach 10, 1.74 at Mach 1.2, 2.05 at Mach 0.5, and
    its subsonic drag blend is C1 (finite-difference slope continuous across Mach 2)."""
    from drake_entry.models.vehicles import load_vehicle

    v = load_vehicle("sphynx")
    assert (v.mass, v.reference_area, v.nose_radius) == (550.0, 2.408, 0.5)
    alphas = np.radians(np.linspace(5.0, 45.0, 401))

    def max_l_over_d(mach):
        cl, cd = v.aero.coefficients(alphas, mach)
        return np.max(cl / cd)

    assert max_l_over_d(10.0) == pytest.approx(1.2, abs=0.1)  # paper 001 Sec. II.A: about 1.2 supersonic
    assert max_l_over_d(0.5) == pytest.approx(2.0, abs=0.1)  # and about 2.0 subsonic
    assert max_l_over_d(1.2) == pytest.approx(1.74, abs=0.03)  # regression pin of the model (transonic)
    a = np.radians(25.0)
    for m in (0.8, 2.0):
        e = 1e-5
        left = (v.aero.coefficients(a, m - e)[1] - v.aero.coefficients(a, m - 2 * e)[1]) / e
        right = (v.aero.coefficients(a, m + 2 * e)[1] - v.aero.coefficients(a, m + e)[1]) / e
        assert left == pytest.approx(right, abs=1e-3)


def test_cli_fit_horus_prints_coefficients_whose_residuals_it_states(capsys, monkeypatch, fit_report):
    """``drake-entry fit-horus`` exits 0 and prints coefficients that, put back into eqs. 32-33 on
    the packaged M-692 cells (recomputed here from the CSV, not by the fit), give the cell
    counts, RMS and largest residual it prints (the fit itself is the one the test above checks,
    made once)."""
    import drake_entry.models.aerodynamics as aerodynamics
    from drake_entry.cli import main

    monkeypatch.setattr(aerodynamics, "fit_horus_forms", lambda **kw: fit_report)
    assert main(["fit-horus"]) == 0
    out = capsys.readouterr().out
    lines = {line.split(":")[0].split(" =")[0]: line for line in out.splitlines()}
    coefs = {k: np.array(ast.literal_eval(lines[k].split("=", 1)[1])) for k in ("aD", "aL")}
    for name, form, key in (("CD", horus_cd_form, "aD"), ("CL", horus_cl_form, "aL")):
        a, m, data = _m692_cells(name).T
        res = form(coefs[key], a, m) - data
        words = lines[f"C_{name[1]}"].replace(",", "").split()
        assert int(words[1]) == len(data)
        assert float(words[words.index("RMS") + 1]) == pytest.approx(np.sqrt(np.mean(res ** 2)), abs=6e-5)
        assert float(words[-1]) == pytest.approx(np.abs(res).max(), abs=6e-5)
