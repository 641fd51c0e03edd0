"""ExpressionTape: a model's symbolic form evaluated at many points at once, values and
Jacobians, against the float and AutoDiffXd paths it replaces."""
import numpy as np
import pytest
from pydrake.autodiffutils import AutoDiffXd, ExtractGradient, ExtractValue, InitializeAutoDiff
from pydrake.symbolic import Expression, Variable, if_then_else, logical_and
from pydrake.symbolic import max as smax
from pydrake.symbolic import min as smin

from drake_entry.errors import UnsupportedScalarError
from drake_entry.guidance.scvx.decision import initial_decision
from drake_entry.guidance.scvx.entry import EntryProblem
from drake_entry.guidance.scvx.guess import glide_guess
from drake_entry.guidance.scvx.mission import ScvxMission
from drake_entry.guidance.scvx.settings import EntryProblemSettings
from drake_entry.models.atmosphere import DispersedAtmosphere, US76Atmosphere
from drake_entry.models.expression_tape import ExpressionTape, TracedAtmosphere
from drake_entry.models.planet import Earth
from drake_entry.models.vehicles import load_vehicle


def _every_operation(x, y):
    """One expression per operation the tape knows, written once for any scalar type."""
    return [3.0 + 2.0 * x * y ** 2 - x / y, np.log(x) * np.exp(-y), np.sqrt(x * y), x ** 2.5,
            np.sin(x) * np.cos(y) + np.tan(0.3 * y), np.arcsin(0.2 * y) + np.arccos(0.1 * x), np.arctan(x - y),
            np.arctan2(y, x - 2.0), np.sinh(0.5 * x) + np.cosh(0.2 * y) * np.tanh(y), abs(x - 2.0 * y)]


def _symbolic_extras(x, y):
    return [x ** y, if_then_else(x < y, x * x, 3.0 * y), smin(x, 2.0 * y), smax(x * y, 4.0),
            if_then_else(logical_and(x > 1.5, y < 2.0), x, y)]


def _float_extras(x, y):
    return [x ** y, np.where(x < y, x * x, 3.0 * y), np.minimum(x, 2.0 * y), np.maximum(x * y, 4.0),
            np.where((x > 1.5) & (y < 2.0), x, y)]


@pytest.fixture(scope="module")
def tape_xy():
    x, y = Variable("x"), Variable("y")
    X, Y = Expression(x), Expression(y)
    with np.errstate(all="ignore"):  # numpy's object loops report stray FP flags as warnings
        return ExpressionTape(_every_operation(X, Y) + _symbolic_extras(X, Y), [x, y])


def test_values_equal_the_float_formulas_at_every_point(tape_xy):
    rng = np.random.default_rng(1)
    p = np.column_stack([rng.uniform(0.5, 3.0, 50), rng.uniform(0.5, 3.0, 50)])
    expected = np.column_stack(_every_operation(p[:, 0], p[:, 1]) + _float_extras(p[:, 0], p[:, 1]))
    assert tape_xy(p) == pytest.approx(expected, rel=1e-14, abs=1e-14)


def test_jacobians_equal_autodiff_and_central_differences(tape_xy):
    """Every operation's derivative against AutoDiffXd (the path the tape replaces) to 1e-13 and
    central differences to 1e-7; each branch of if_then_else, min and max is taken at some point."""
    rng = np.random.default_rng(2)
    p = np.column_stack([rng.uniform(0.5, 3.0, 40), rng.uniform(0.5, 3.0, 40)])
    values, jac = tape_xy(p, gradients=True)
    n_smooth = len(_every_operation(1.0, 1.0))
    for k, point in enumerate(p):
        ad = InitializeAutoDiff(point)[:, 0]
        out = np.array(_every_operation(ad[0], ad[1]), dtype=object)
        assert values[k, :n_smooth] == pytest.approx(ExtractValue(out)[:, 0], rel=1e-14)
        assert jac[k, :n_smooth] == pytest.approx(ExtractGradient(out), rel=1e-13, abs=1e-13)
    h = 1e-6
    for j in range(2):
        step = np.zeros(2)
        step[j] = h
        fd = (tape_xy(p + step) - tape_xy(p - step)) / (2 * h)
        far = np.abs(p[:, 0] - p[:, 1]) > 1e-3  # away from the kinks
        assert jac[far, :, j] == pytest.approx(fd[far], rel=1e-6, abs=1e-7)
    chose_x = p[:, 0] < p[:, 1]
    assert chose_x.any() and (~chose_x).any()
    assert jac[chose_x, n_smooth + 1, 0] == pytest.approx(2 * p[chose_x, 0]) and np.all(jac[~chose_x, n_smooth + 1, 1] == 3.0)


def test_traced_atmosphere_gives_the_models_air_data_and_altitude_derivatives():
    """Density and speed of sound through the tape equal the model's float path and its
    AutoDiffXd altitude derivative, for US76 (table above 86 km) and a dispersed one."""
    h = Variable("h")
    for base in (US76Atmosphere(), DispersedAtmosphere(US76Atmosphere(), scale=1.1, amplitude=0.05,
                                                          wavelength=9e3, phase=0.3)):
        traced = TracedAtmosphere(base)
        with np.errstate(all="ignore"):
            tape = ExpressionTape(list(traced.air_data(Expression(h))), [h], traced.functions)
        alt = np.array([[-1e3], [5e3], [11e3], [47.5e3], [85.9e3], [86.1e3], [120e3], [400e3]])
        values, jac = tape(alt, gradients=True)
        for k, z in enumerate(alt[:, 0]):
            rho, a = base.air_data(float(z))
            assert values[k] == pytest.approx([rho, a], rel=1e-13)
            rho_ad, a_ad = base.air_data(AutoDiffXd(float(z), [1.0]))
            assert jac[k, :, 0] == pytest.approx([rho_ad.derivatives()[0], a_ad.derivatives()[0]], rel=1e-12)


def test_tape_names_what_it_cannot_evaluate_and_wrong_shapes():
    x, y = Variable("x"), Variable("y")
    with pytest.raises(UnsupportedScalarError, match="variable y"):
        ExpressionTape([Expression(x) + y], [x])
    with pytest.raises(ValueError, match=r"shape \(n, 1\)"):
        ExpressionTape([Expression(x) * 2.0], [x])(np.zeros((3, 2)))


@pytest.fixture(scope="module")
def sphynx():
    vehicle, planet, atmosphere, mission = load_vehicle("sphynx"), Earth.oblate(), US76Atmosphere(), ScvxMission()
    return vehicle, planet, atmosphere, mission, glide_guess(vehicle, planet, atmosphere, mission)


@pytest.mark.parametrize("formulation", ["lossless", "hybrid", "direct_bank", "direct"])
def test_scvx_nodes_by_tape_equal_the_node_by_node_autodiff(sphynx, formulation):
    """Paper 001's node outputs (dynamics, heat flux, load, speed of sound, geodetic altitude) at
    the glide guess's nodes: the tape equals the one-node-at-a-time float and AutoDiffXd
    evaluation to 1e-12 of each output's scale, values and Jacobians, in every formulation (the
    alpha schedule of the formulations without an alpha state included)."""
    vehicle, planet, atmosphere, mission, guess = sphynx
    problem = EntryProblem(vehicle, planet, atmosphere, mission, EntryProblemSettings(formulation=formulation),
                           guess.final_time)
    assert problem.tape is not None
    X, U, _ = problem.unpack(initial_decision(problem, guess))
    v_ref, j_ref = problem._nodes_one_by_one(X, U, gradients=True)
    v, j = problem._nodes(X, U, gradients=True)
    scale = np.abs(v_ref).max(axis=0) + 1e-300
    assert np.max(np.abs(v - v_ref) / scale) < 1e-12
    j_scale = np.abs(j_ref).max(axis=0) + 1e-300
    assert np.max(np.abs(j - j_ref) / j_scale) < 1e-12
    assert problem._nodes(X, U, gradients=False)[0] == pytest.approx(v, rel=0, abs=0)


def test_scvx_path_margin_ramps_in_from_the_first_node(sphynx):
    """The nodes' heat-flux and load bounds start at the vehicle's limits and reach the full
    path margin path_margin_ramp_s into the plan, so a re-plan from a vehicle riding a limit is
    not infeasible at its first nodes; 0 gives the full margin everywhere."""
    vehicle, planet, atmosphere, mission, guess = sphynx
    settings = EntryProblemSettings(formulation="direct")
    problem = EntryProblem(vehicle, planet, atmosphere, mission, settings, 1000.0)
    q, n, _ = problem.node_limits
    q_max, n_max, _ = EntryProblem(vehicle, planet, atmosphere, mission, EntryProblemSettings(
        formulation="direct", path_margin=0.0), 1000.0).node_limits
    t = problem.mesh.s[1:] * 1000.0
    margin = settings.path_margin * np.minimum(1.0, t / settings.path_margin_ramp_s)
    assert settings.path_margin == 0.02 and (t < settings.path_margin_ramp_s).sum() >= 3
    assert q == pytest.approx((1.0 - margin) * q_max, rel=1e-15) and n == pytest.approx((1.0 - margin) * n_max, rel=1e-15)
    assert q[0] > 0.995 * q_max[0] and q[-1] == pytest.approx(0.98 * q_max[-1])
    flat = EntryProblem(vehicle, planet, atmosphere, mission, EntryProblemSettings(formulation="direct",
                                                                                 path_margin_ramp_s=0.0), 1000.0)
    assert np.all(flat.node_limits[0] == q[-1])
    with pytest.raises(Exception, match="path_margin_ramp_s"):
        EntryProblemSettings(path_margin_ramp_s=-1.0)
