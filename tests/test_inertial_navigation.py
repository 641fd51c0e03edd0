"""The inertial navigation error model (models.inertial_navigation) and its Drake system
(systems.inertial_navigation): a bias alone gives b t and b t^2 / 2, the Schuler loop bounds the
horizontal error as its closed form says, the accelerometers' drag and lift carry the bias and
scale factor, the drawn entry errors have their covariance, the perfect-navigation switch flies
the same flight as no INS, and bad input is one line naming the field."""
import dataclasses as dc
import math

import numpy as np
import pytest
from pydrake.common import RandomGenerator
from pydrake.systems.analysis import Simulator

from drake_entry.errors import ScenarioError
from drake_entry.models import inertial_navigation as ins
from drake_entry.models.dispersions import DispersionSpec, draw, validate
from drake_entry.models.dynamics import FLIGHT_CONDITION_NAMES
from drake_entry.models.planet import Earth
from drake_entry.systems.inertial_navigation import InertialNavigation

PLANET = Earth.spherical()
BIAS = np.array([2e-3, -1e-3, 5e-4])


def _errors(bias=BIAS, scale=(0.0, 0.0, 0.0), drift=(0.0, 0.0, 0.0), initial=None, feedback=False, enabled=True):
    return ins.InertialErrors(np.zeros(6) if initial is None else np.asarray(initial, float), np.asarray(bias, float),
                              np.asarray(scale, float), np.asarray(drift, float), feedback, enabled)


def test_a_bias_alone_gives_b_t_and_b_t_squared_over_two():
    """Heading north, level, no force, no gravity feedback: stability x is north, z up, y west
    (y = z x x), so the error follows the bias's rotation exactly."""
    rotation = ins.stability_to_local_level(0.0, 0.0, 0.0)
    assert rotation == pytest.approx(np.column_stack([[0, 1, 0], [-1, 0, 0], [0, 0, 1]]), abs=1e-15)
    e, t = np.zeros(9), 0.0
    for _ in range(300):
        e = ins.propagate(e, _errors(), rotation, 0.0, 0.0, 9.8, 6.4e6, 0.5)
        t += 0.5
    b = rotation @ BIAS
    assert e[3:6] == pytest.approx(b * t, rel=1e-12)
    assert e[0:3] == pytest.approx(b * t * t / 2, rel=1e-12)


def test_the_schuler_loop_bounds_the_horizontal_error_as_its_closed_form():
    """With gravity feedback a north bias b gives dr_N = b / w^2 (1 - cos w t), w^2 = g / r
    (Titterton & Weston ch. 12), to 0.5 % of its peak over a Schuler half-period (2530 s) at 0.5 s."""
    g, r = 9.8, 6.4e6
    w = math.sqrt(g / r)
    rotation = ins.stability_to_local_level(0.0, 0.0, 0.0)
    errors = _errors(bias=(1e-3, 0.0, 0.0), feedback=True)
    e, dt = np.zeros(9), 0.5
    n = int(round(math.pi / w / dt))
    for _ in range(n):
        e = ins.propagate(e, errors, rotation, 0.0, 0.0, g, r, dt)
    t = n * dt
    expected = 1e-3 / w**2 * (1 - math.cos(w * t))
    assert e[1] == pytest.approx(expected, rel=5e-3)
    assert e[1] < 0.5 * 1e-3 * t * t  # far below the open-loop b t^2 / 2


def test_the_drake_system_propagates_the_bias_and_gives_the_navigated_state():
    x = np.array([40e3, 0.2, 0.1, 3000.0, 0.0, 0.0])  # level, heading north
    system = InertialNavigation(_errors(), PLANET, period=1.0)
    ctx = system.CreateDefaultContext()
    system.GetInputPort("true_state").FixValue(ctx, x)
    system.GetInputPort("flight_conditions").FixValue(ctx, np.zeros(len(FLIGHT_CONDITION_NAMES)))
    system.GetInputPort("bank").FixValue(ctx, [0.0])
    sim = Simulator(system, ctx)
    sim.AdvanceTo(100.0)  # updates at 0, 1, ..., 99: 100 s of propagation
    est = system.GetOutputPort("estimated_state").Eval(sim.get_context())
    r = PLANET.radius(x[0])
    north, east, up = BIAS[0] * 100**2 / 2, -BIAS[1] * 100**2 / 2, BIAS[2] * 100**2 / 2  # stability y is west
    assert est[2] - x[2] == pytest.approx(north / r, rel=1e-9)
    assert (est[1] - x[1]) * r * math.cos(x[2]) == pytest.approx(east, rel=1e-9)
    assert est[0] - x[0] == pytest.approx(up, rel=1e-9)
    dv = 100 * np.array([-BIAS[1], BIAS[0], BIAS[2]])  # east, north, up
    assert est[3] == pytest.approx(math.hypot(dv[0], x[3] + dv[1], dv[2]), rel=1e-14)
    assert est[4] == pytest.approx(math.asin(dv[2] / est[3]), rel=1e-12)
    error = system.GetOutputPort("navigation_error").Eval(sim.get_context())
    assert error[1] == pytest.approx(np.linalg.norm(BIAS) * 100, rel=1e-12)


def test_the_accelerometers_read_drag_and_lift_with_bias_and_scale_factor():
    errors = _errors(bias=(0.01, 0.0, -0.02), scale=(1e-3, 0.0, -2e-3))
    drag, lift = ins.sensed_drag_lift(errors, 20.0, 8.0)
    assert drag == pytest.approx(1.001 * 20.0 - 0.01, rel=1e-14)
    assert lift == pytest.approx(0.998 * 8.0 - 0.02, rel=1e-14)
    system = InertialNavigation(errors, PLANET, period=1.0)
    ctx = system.CreateDefaultContext()
    c = np.arange(1.0, 10.0)
    system.GetInputPort("flight_conditions").FixValue(ctx, c)
    sensed = system.GetOutputPort("sensed_conditions").Eval(ctx)
    i_l, i_d = FLIGHT_CONDITION_NAMES.index("lift"), FLIGHT_CONDITION_NAMES.index("drag")
    assert sensed[i_d] == pytest.approx(1.001 * c[i_d] - 0.01) and sensed[i_l] == pytest.approx(0.998 * c[i_l] - 0.02)
    others = [k for k in range(9) if k not in (i_l, i_d)]
    assert np.array_equal(sensed[others], c[others])


def test_perfect_navigation_outputs_the_true_state_and_accelerations():
    x = np.array([40e3, 0.2, 0.1, 3000.0, -0.01, 1.0])
    system = InertialNavigation(_errors(initial=[100, 0, 0, 1, 0, 0], enabled=False), PLANET, period=1.0)
    ctx = system.CreateDefaultContext()
    system.GetInputPort("true_state").FixValue(ctx, x)
    system.GetInputPort("flight_conditions").FixValue(ctx, np.arange(1.0, 10.0))
    assert np.array_equal(system.GetOutputPort("estimated_state").Eval(ctx), x)
    assert np.array_equal(system.GetOutputPort("sensed_conditions").Eval(ctx), np.arange(1.0, 10.0))


def test_the_navigated_state_of_zero_error_is_the_true_state_and_keeps_the_heading_continuous():
    x = np.array([40e3, 0.2, 0.1, 3000.0, -0.01, 2 * math.pi + 0.3])
    assert ins.navigated_state(x, np.zeros(9), 6.4e6) == pytest.approx(x, rel=1e-14)


SPEC = ins.InertialNavigationSpec(initial_covariance=[[400.0, 100.0, 0, 0, 0, 0], [100.0, 400.0, 0, 0, 0, 0],
                                                      [0, 0, 900.0, 0, 0, -3.0], [0, 0, 0, 0.04, 0, 0],
                                                      [0, 0, 0, 0, 0.04, 0], [0, 0, -3.0, 0, 0, 0.09]],
                                  accelerometer_bias_sigma_m_s2=5e-4, accelerometer_scale_factor_sigma_ppm=100.0,
                                  gyro_drift_sigma_deg_h=0.01)


def test_the_drawn_errors_have_the_specified_covariance_and_sigmas():
    spec = DispersionSpec(inertial_navigation=SPEC)
    draws = [draw(spec, RandomGenerator(seed)).inertial for seed in range(10_000)]
    initial = np.array([d.initial for d in draws])
    expected = np.asarray(SPEC.initial_covariance)
    sd = np.sqrt(np.diag(expected))
    assert np.corrcoef(initial.T) == pytest.approx(expected / np.outer(sd, sd), abs=0.03)
    assert np.diag(np.cov(initial.T)) == pytest.approx(np.diag(expected), rel=0.04)
    assert np.std([d.accelerometer_bias for d in draws], axis=0) == pytest.approx([5e-4] * 3, rel=0.04)
    assert np.std([d.scale_factor for d in draws], axis=0) == pytest.approx([1e-4] * 3, rel=0.04)
    assert np.std([d.gyro_drift for d in draws], axis=0) == pytest.approx([math.radians(0.01) / 3600] * 3, rel=0.04)


@pytest.mark.parametrize("change, message", [
    ({"accelerometer_bias_sigma_m_s2": -1e-3}, "inertial_navigation.accelerometer_bias_sigma_m_s2 = -0.001 is out "
                                               "of range; allowed: [0, 1]"),
    ({"gyro_drift_sigma_deg_h": float("inf")}, "inertial_navigation.gyro_drift_sigma_deg_h = inf is out of range"),
    ({"initial_covariance": [[1.0] * 6] * 5}, "inertial_navigation.initial_covariance needs 6 rows of 6 values"),
    ({"initial_covariance": (np.eye(6) - 2 * np.eye(6)[0:1].T @ np.eye(6)[0:1]).tolist()},
     "inertial_navigation.initial_covariance is not positive semi-definite"),
])
def test_bad_inertial_input_is_one_line_naming_the_field(change, message):
    with pytest.raises(ScenarioError) as e:
        validate(DispersionSpec(inertial_navigation=dc.replace(SPEC, **change)))
    assert message in str(e.value) and "\n" not in str(e.value)


def test_two_navigation_models_at_once_are_refused():
    with pytest.raises(ScenarioError, match="two navigation models; give one"):
        validate(DispersionSpec(inertial_navigation=SPEC, nav_noise_sigma=[10.0, 0, 0, 0, 0, 0]))


@pytest.mark.slow
def test_the_perfect_navigation_switch_flies_the_flight_without_an_ins():
    """The same sample with the INS switched off (its draws still made, after every other draw)
    flies exactly the flight of the scenario without an INS; switched on, it flies another."""
    from drake_entry.campaign.sample import run_sample
    from drake_entry.diagrams.closed_loop import ClosedLoopSetup
    from drake_entry.scenario import load_scenario

    base = load_scenario("capsule_lu2008")
    rows = []
    for spec in (None, dc.replace(SPEC, enabled=False), SPEC):
        scenario = dc.replace(base, dispersions=dc.replace(base.dispersions, inertial_navigation=spec))
        rows.append(run_sample(ClosedLoopSetup.from_scenario(scenario), 4, 1, trajectory_step_s=0)[0])
    assert rows[1]["err_distance_m"] == rows[0]["err_distance_m"]
    assert rows[1]["nav_position_error_max_m"] == 0.0
    assert rows[2]["err_distance_m"] != rows[0]["err_distance_m"] and rows[2]["nav_position_error_max_m"] > 1.0


def test_the_stability_axes_are_a_right_handed_orthonormal_triad_with_z_along_the_banked_lift():
    rng = np.random.default_rng(2)
    for gamma, psi, bank in rng.uniform([-0.5, -4.0, -1.6], [0.3, 4.0, 1.6], (20, 3)):
        r = ins.stability_to_local_level(gamma, psi, bank)
        assert r.T @ r == pytest.approx(np.eye(3), abs=1e-14) and np.linalg.det(r) == pytest.approx(1.0, abs=1e-14)
        assert r[:, 1] == pytest.approx(np.cross(r[:, 2], r[:, 0]), abs=1e-14)
        assert r[:, 0] == pytest.approx([math.cos(gamma) * math.sin(psi), math.cos(gamma) * math.cos(psi),
                                         math.sin(gamma)], abs=1e-14)
        assert r[2, 2] == pytest.approx(math.cos(gamma) * math.cos(bank), abs=1e-14)  # the lift's vertical share
