"""Each LeafSystem: ports, units, and behaviour against the model functions."""
import dataclasses as dc
import math

import numpy as np
import pytest
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import ConstantVectorSource

from drake_entry.models.dynamics import FLIGHT_CONDITION_NAMES, flight_conditions, state_derivatives
from drake_entry.models.planet import Earth
from drake_entry.models.schedules import Schedule
from drake_entry.systems.actuators import BankActuator
from drake_entry.systems.atmosphere import AtmosphereSystem
from drake_entry.systems.monitors import TerminationMonitor
from drake_entry.systems.navigation import Navigation
from drake_entry.systems.schedule import ScheduleSource, make_schedule_source
from drake_entry.systems.vehicle import EntryVehicle, EntryVehicle_


def _fixed_inputs(system, context, **values):
    for name, v in values.items():
        system.GetInputPort(name).FixValue(context, np.atleast_1d(v))


def test_entry_vehicle_ports():
    from drake_entry.models.vehicles import load_vehicle

    s = EntryVehicle(load_vehicle("horus2b"), Earth.spherical(), None, air_data_input=True)
    assert [s.get_input_port(i).get_name() for i in range(s.num_input_ports())] == ["bank", "alpha", "air_data"]
    assert s.GetOutputPort("state").size() == 6
    assert s.GetOutputPort("flight_conditions").size() == len(FLIGHT_CONDITION_NAMES) == 9


def test_entry_vehicle_derivatives_and_conditions_equal_the_model(horus, us76, entry_state, earth):
    s = EntryVehicle(horus, earth, us76, initial_state=entry_state)
    ctx = s.CreateDefaultContext()
    _fixed_inputs(s, ctx, bank=0.6, alpha=0.7)
    xdot = s.EvalTimeDerivatives(ctx).CopyToVector()
    assert np.allclose(xdot, state_derivatives(entry_state, 0.6, 0.7, horus, earth, us76), rtol=1e-14)
    fc = s.GetOutputPort("flight_conditions").Eval(ctx)
    assert np.allclose(fc, flight_conditions(entry_state, 0.6, 0.7, horus, earth, us76), rtol=1e-14)


def test_entry_vehicle_converts_to_autodiff_for_trajectory_optimisation(horus, us76, entry_state, earth):
    s = EntryVehicle(horus, earth, us76, initial_state=entry_state)
    from pydrake.autodiffutils import AutoDiffXd, ExtractGradient, InitializeAutoDiff

    ad = s.ToAutoDiffXd()
    assert isinstance(ad, EntryVehicle_[AutoDiffXd])
    ctx = ad.CreateDefaultContext()
    ad.get_input_port(0).FixValue(ctx, InitializeAutoDiff(np.array([0.6]), 2, 0).ravel())
    ad.get_input_port(1).FixValue(ctx, InitializeAutoDiff(np.array([0.7]), 2, 1).ravel())
    ctx.SetContinuousState(entry_state.astype(object) + 0 * InitializeAutoDiff(np.zeros(1), 2, 0)[0, 0])
    xdot = ad.EvalTimeDerivatives(ctx).CopyToVector()
    grad = ExtractGradient(xdot)  # d xdot / d(bank, alpha)
    e = 1e-6
    fd_bank = (state_derivatives(entry_state, 0.6 + e, 0.7, horus, earth, us76)
               - state_derivatives(entry_state, 0.6 - e, 0.7, horus, earth, us76)) / (2 * e)
    assert np.allclose(grad[:, 0], fd_bank, rtol=1e-6, atol=1e-12)


def test_atmosphere_system_serves_a_dispersed_density(us76, entry_state, earth):
    from drake_entry.models.atmosphere import DispersedAtmosphere

    s = AtmosphereSystem(DispersedAtmosphere(us76, scale=1.1), earth)
    ctx = s.CreateDefaultContext()
    s.get_input_port().FixValue(ctx, entry_state)
    rho, a = s.get_output_port().Eval(ctx)
    assert rho == pytest.approx(1.1 * us76.density(entry_state[0]))
    assert a == pytest.approx(us76.speed_of_sound(entry_state[0]))
    with pytest.raises(ValueError, match="needs scale > 0"):
        DispersedAtmosphere(us76, scale=0.0)


def _simulate_actuator(command, t_end, **kw):
    b = DiagramBuilder()
    src = b.AddSystem(ConstantVectorSource([command]))
    act = b.AddSystem(BankActuator(**kw))
    b.Connect(src.get_output_port(), act.get_input_port())
    rate_log = []
    d = b.Build()
    sim = Simulator(d)
    ctx = act.GetMyContextFromRoot(sim.get_mutable_context())
    ts = np.linspace(0, t_end, 201)
    out = []
    for t in ts:
        sim.AdvanceTo(t)
        out.append(act.get_output_port(0).Eval(ctx)[0])
        rate_log.append(act.GetOutputPort("bank_rate").Eval(ctx)[0])
    return ts, np.array(out), np.array(rate_log)


def test_bank_reversal_respects_rate_and_acceleration_limits():
    rate, accel = np.radians(10.0), np.radians(5.0)
    t, bank, bank_rate = _simulate_actuator(np.radians(-60.0), 40.0, bank_limit=np.radians(80.0), rate_limit=rate,
                                            accel_limit=accel, initial_bank=np.radians(60.0))
    assert np.abs(bank_rate).max() <= rate * (1 + 1e-6)
    assert np.abs(np.diff(bank_rate) / np.diff(t)).max() <= accel * 1.05
    assert bank[-1] == pytest.approx(np.radians(-60.0), abs=np.radians(0.5))
    # a 120 deg reversal at 10 deg/s takes at least 12 s
    assert bank[np.searchsorted(t, 11.0)] > np.radians(-60.0) + np.radians(5.0)


def test_bank_command_is_clipped_to_the_bank_limit():
    _, bank, _ = _simulate_actuator(np.radians(120.0), 60.0, bank_limit=np.radians(89.0), rate_limit=1.0,
                                    accel_limit=1.0)
    assert bank.max() <= np.radians(89.0) + np.radians(0.01)
    assert bank[-1] == pytest.approx(np.radians(89.0), abs=np.radians(0.01))


def test_sampled_actuator_response_equals_the_actuator_system():
    """A command known in advance (a bank reversal and a slow weave, sampled every 1 s):
    ``response`` (the actuator's segments computed before a flight, one Hermite polynomial)
    equals the sampled actuator system's output and rate at every instant to 1e-12 rad,
    through the rate- and acceleration-limited reversal (where the RK2 sub-steps act)."""
    from pydrake.systems.primitives import TrajectorySource
    from pydrake.trajectories import PiecewisePolynomial

    t_cmd = np.linspace(0.0, 60.0, 121)
    cmd = np.where(t_cmd < 20.0, np.radians(60.0), np.radians(-55.0)) + np.radians(5.0) * np.sin(t_cmd / 7.0)
    command = PiecewisePolynomial.FirstOrderHold(t_cmd, cmd[None, :])
    kw = dict(bank_limit=np.radians(80.0), rate_limit=np.radians(10.0), accel_limit=np.radians(5.0),
              initial_bank=np.radians(50.0), period=1.0)
    b = DiagramBuilder()
    src = b.AddSystem(TrajectorySource(command))
    act = b.AddSystem(BankActuator(**kw))
    b.Connect(src.get_output_port(), act.get_input_port())
    sim = Simulator(b.Build())
    ctx = act.GetMyContextFromRoot(sim.get_mutable_context())
    response = BankActuator(**kw).response(lambda t: command.value(t)[0, 0], 50.0)
    ts = np.sort(np.concatenate([np.linspace(0.0, 50.0, 337), np.arange(1.0, 50.0, 1.0) + 0.5e-3]))
    worst, rates = 0.0, []
    for t in ts:
        sim.AdvanceTo(t)
        worst = max(worst, abs(act.get_output_port(0).Eval(ctx)[0] - response.value(t)[0, 0]),
                    abs(act.GetOutputPort("bank_rate").Eval(ctx)[0] - response.EvalDerivative(t, 1)[0, 0]))
        rates.append(act.GetOutputPort("bank_rate").Eval(ctx)[0])
    assert worst < 1e-12, worst
    assert max(np.abs(rates)) == pytest.approx(np.radians(10.0), rel=1e-3)  # the reversal rode the rate limit
    assert response.end_time() >= 50.0
    with pytest.raises(Exception, match="sampled realisation"):
        BankActuator(**{**kw, "period": None}).response(lambda t: 0.0, 10.0)


def test_navigation_noise_is_reproducible_from_the_seed():
    """The same seed gives the same estimates, another seed others; over 4000 updates the
    error has the bias as its mean (within 4 standard errors), each channel's sigma as its
    standard deviation (within 5 %: 2.2 % is the standard error of a sample standard deviation
    of 4000 normals), no correlation from one update to the next (|r| < 4 / sqrt(n)), and a
    channel with sigma 0 carries its bias alone."""
    from pydrake.systems.primitives import LogVectorOutput

    truth, bias = np.arange(6.0), np.array([0.5, -2.0, 0.0, 1e-3, 3.0, -0.25])
    sigma = np.array([1.0, 0.1, 2.0, 1e-4, 0.0, 0.5])
    n, period = 4000, 0.5

    def run(seed):
        b = DiagramBuilder()
        src = b.AddSystem(ConstantVectorSource(truth))
        nav = b.AddSystem(Navigation(bias=bias, noise_sigma=sigma, period=period, seed=seed))
        b.Connect(src.get_output_port(), nav.get_input_port())
        logger = LogVectorOutput(nav.get_output_port(), b, period)
        sim = Simulator(b.Build())
        sim.AdvanceTo(n * period - 0.25)
        return logger.FindLog(sim.get_context()).data().T[1:]  # the samples after each update

    a, again, other = run(7), run(7), run(8)
    assert np.array_equal(a, again) and not np.allclose(a, other)
    error = a - truth
    assert len(error) == n - 1
    noisy = sigma > 0
    standard_error = sigma[noisy] / math.sqrt(len(error))
    assert np.all(np.abs(error[:, noisy].mean(axis=0) - bias[noisy]) < 4 * standard_error)
    assert error[:, noisy].std(axis=0) == pytest.approx(sigma[noisy], rel=0.05)
    assert np.array_equal(error[:, ~noisy], np.broadcast_to(bias[~noisy], (len(error), 1)))
    centred = error[:, noisy] - error[:, noisy].mean(axis=0)
    lag1 = (centred[1:] * centred[:-1]).mean(axis=0) / centred.var(axis=0)
    assert np.all(np.abs(lag1) < 4 / math.sqrt(len(error)))


def test_schedule_sources_native_and_python_agree():
    sch = Schedule.ramp(960.0, 1250.0, np.radians(40), np.radians(15))
    native = make_schedule_source(sch)
    python = ScheduleSource(sch)
    for t in (0.0, 1000.0, 1250.0, 5000.0):
        cn, cp = native.CreateDefaultContext(), python.CreateDefaultContext()
        cn.SetTime(t)
        cp.SetTime(t)
        assert native.get_output_port().Eval(cn)[0] == pytest.approx(python.get_output_port().Eval(cp)[0])
    assert Schedule.ramp(0, 1, 0.0, 1.0, smooth=True)(0.5) == pytest.approx(0.5)


def test_termination_monitor_floor_must_be_below_its_ceiling():
    TerminationMonitor()  # the altitude band alone: the surface and the ceiling
    with pytest.raises(ValueError, match="must be below the ceiling"):
        TerminationMonitor(altitude=2e6)


@pytest.mark.parametrize("smooth", [False, True])
def test_schedule_derivatives_equal_finite_differences(smooth):
    sch = Schedule((-5.0e7, -4.0e7), (0.26, 0.70), "energy", smooth)
    for s in (-4.7e7, -4.3e7):
        v, d1, d2 = sch.derivatives(s)
        e = 1e3
        assert d1 == pytest.approx((sch(s + e) - sch(s - e)) / (2 * e), rel=1e-6)
        assert d2 == pytest.approx((sch(s + e) - 2 * v + sch(s - e)) / e**2, rel=1e-4, abs=1e-20)


def test_sampled_actuator_reproduces_the_continuous_one():
    kw = dict(bank_limit=np.radians(80.0), rate_limit=np.radians(10.0), accel_limit=np.radians(5.0),
              initial_bank=np.radians(60.0))
    t, cont, _ = _simulate_actuator(np.radians(-60.0), 30.0, **kw)
    t, samp, rate = _simulate_actuator(np.radians(-60.0), 30.0, period=1.0, **kw)
    assert np.abs(samp - cont).max() < np.radians(0.05)
    assert np.abs(rate).max() <= np.radians(10.0) * (1 + 1e-3)


def test_segment_integrator_equals_midpoint_steps_of_the_actuator_law():
    """The sampled actuator's segment: RK2 on bank_actuator_rates through a limited reversal,
    and the exact critically damped solution where no limit is active (RK2 agrees to O(h^2))."""
    from drake_entry.models.actuator import actuator_rates, integrate_actuator

    lim = dict(lower=-math.radians(80), upper=math.radians(80), rate_limit=math.radians(10), accel_limit=math.radians(5), bandwidth=2.0)

    def rk2(s, r, cmd, h, n):
        out = [(s, r)]
        for _ in range(n):
            d1 = actuator_rates(s, r, cmd, **lim)
            d2 = actuator_rates(s + 0.5 * h * d1[0], r + 0.5 * h * d1[1], cmd, **lim)
            s, r = s + h * d2[0], r + h * d2[1]
            out.append((s, r))
        return np.array(out)

    h = 0.01
    fast = np.array(integrate_actuator(math.radians(60), 0.0, math.radians(-70), h, 300, **lim)).T
    assert np.abs(fast - rk2(math.radians(60), 0.0, math.radians(-70), h, 300)).max() < 1e-14
    assert np.abs(fast[:, 1]).max() <= lim["rate_limit"] * (1 + 1e-9)
    small = np.array(integrate_actuator(0.30, 0.0, 0.303, h, 100, **lim)).T  # no limit active
    assert np.abs(small - rk2(0.30, 0.0, 0.303, h, 100)).max() < 1e-5  # RK2 O(h^2)
    t = np.arange(101) * h
    assert small[:, 0] == pytest.approx(0.303 - 0.003 * (1 + 4 * t) * np.exp(-4 * t), abs=1e-15)
    assert integrate_actuator(0.3, 0.0, 0.3, h, 5, **lim) == ([0.3] * 6, [0.0] * 6)


@pytest.mark.parametrize("few_limited", [0, 4])
def test_population_actuator_equals_the_scalar_actuator_member_by_member(few_limited, monkeypatch):
    """integrate_actuators (a population, used by the paper-004 evaluator) gives every member
    what integrate_actuator gives it alone: limited reversals, settled members and linear
    tracking mixed in one call; its limited members stepped as arrays (FEW_LIMITED 0) or one
    by one on floats (4, the default) alike."""
    from drake_entry.models import actuator
    from drake_entry.models.actuator import integrate_actuator, integrate_actuators

    monkeypatch.setattr(actuator, "FEW_LIMITED", few_limited)

    lim = dict(lower=math.radians(10), upper=math.radians(20), rate_limit=math.radians(4), accel_limit=math.radians(8),
               bandwidth=2.0)
    x = np.radians([10.0, 20.0, 15.0, 15.0, 12.0])
    rate = np.radians([0.0, 0.0, 1.0, 0.0, -3.0])
    cmd = np.radians([25.0, 20.0, 15.1, 11.0, 19.0])  # above the upper bound, settled, linear, limited, limited
    end, end_rate, positions = integrate_actuators(x, rate, cmd, 0.05, 20, **lim)
    assert positions.shape == (21, 5)
    for i in range(5):
        s, r = integrate_actuator(x[i], rate[i], cmd[i], 0.05, 20, **lim)
        assert positions[:, i] == pytest.approx(s, abs=1e-14)
        assert (end[i], end_rate[i]) == pytest.approx((s[-1], r[-1]), abs=1e-14)
    assert positions[:, 1] == pytest.approx(np.radians(20.0), abs=0)  # settled at the bound


def test_population_actuator_takes_per_member_limits():
    """Two actuators of different limits (alpha and bank, as the paper-004 evaluator stacks
    them) in one call give each member what the scalar actuator gives it with its own limits."""
    from drake_entry.models.actuator import integrate_actuator, integrate_actuators

    alpha = dict(lower=math.radians(10), upper=math.radians(20), rate_limit=math.radians(4),
                 accel_limit=math.radians(8), bandwidth=2.0)
    bank = dict(lower=-math.radians(85), upper=math.radians(85), rate_limit=math.radians(20),
                accel_limit=math.radians(10), bandwidth=2.0)
    x, rate = np.radians([12.0, 15.0, 40.0, -30.0]), np.radians([0.0, 0.5, 5.0, 0.0])
    cmd = np.radians([19.0, 15.1, -40.0, -30.2])
    per = [alpha, alpha, bank, bank]
    stacked = {k: np.array([p[k] for p in per]) for k in ("lower", "upper", "rate_limit", "accel_limit")}
    _, _, positions = integrate_actuators(x, rate, cmd, 0.02, 50, bandwidth=2.0, **stacked)
    for i, lim in enumerate(per):
        s, _ = integrate_actuator(x[i], rate[i], cmd[i], 0.02, 50, **lim)
        assert positions[:, i] == pytest.approx(s, abs=1e-14)


def test_acceleration_ratio_filter_low_passes_sensed_over_modelled_lift_and_drag():
    """Sensed lift 5 % over and drag 3 % under the nominal models at the estimate: after 30 updates
    of 1 s (time constant 30 s) the ratios have closed 1 - (29/30)^30 = 63.8 % of the gap, and
    they converge to 1.05 and 0.97; in thin air (modelled drag under 0.5 m/s^2) they hold."""
    from pydrake.systems.analysis import Simulator
    from pydrake.systems.framework import DiagramBuilder
    from pydrake.systems.primitives import ConstantVectorSource

    from drake_entry.models.acceleration_ratios import filtered_ratios
    from drake_entry.models.dynamics import FLIGHT_CONDITION_NAMES, aero_accelerations, air_data
    from drake_entry.scenario import load_scenario
    from drake_entry.systems.acceleration_ratios import AccelerationRatioFilter

    s = load_scenario("marv_guidance")
    vehicle, planet, atmosphere = s.make_vehicle(), s.make_planet(), s.make_atmosphere()
    x, alpha = np.array([30e3, 0.1, 0.0, 5000.0, -0.05, 1.5]), np.radians(10.0)
    _, L, D = aero_accelerations(x, alpha, *air_data(x, planet, atmosphere), vehicle)
    fc = np.zeros(len(FLIGHT_CONDITION_NAMES))
    fc[FLIGHT_CONDITION_NAMES.index("lift")], fc[FLIGHT_CONDITION_NAMES.index("drag")] = 1.05 * L, 0.97 * D

    builder = DiagramBuilder()
    f = builder.AddSystem(AccelerationRatioFilter(vehicle, planet, atmosphere, period=1.0))
    for port, value in (("estimated_state", x), ("flight_conditions", fc), ("alpha_command", [alpha])):
        builder.Connect(builder.AddSystem(ConstantVectorSource(np.asarray(value, float))).get_output_port(),
                        f.GetInputPort(port))
    simulator = Simulator(builder.Build())
    simulator.AdvanceTo(29.5)  # updates at t = 0, 1, ..., 29
    k = f.GetOutputPort("ratios").Eval(f.GetMyContextFromRoot(simulator.get_context()))
    closed = 1.0 - (29.0 / 30.0) ** 30
    assert k == pytest.approx([1.0 + 0.05 * closed, 1.0 - 0.03 * closed], rel=1e-12)
    far = (1.0, 1.0)
    for _ in range(1000):
        far = filtered_ratios(far, x, alpha, 1.05 * L, 0.97 * D, vehicle, planet, atmosphere, 1.0)
    assert far == pytest.approx((1.05, 0.97), rel=1e-12)
    thin = np.array([90e3, 0.1, 0.0, 7000.0, 0.0, 1.5])
    assert filtered_ratios((1.2, 0.8), thin, alpha, 1.0, 1.0, vehicle, planet, atmosphere, 1.0) == (1.2, 0.8)


def test_sensed_vehicle_scales_the_nominal_coefficients_once():
    """A re-plan's vehicle predicts with C_L k_L and C_D k_D; a plan re-planned again is scaled
    from the nominal coefficients (k of the latest ratios, not their product), and the dispersed
    plant's ScaledAero is never mistaken for a sensed one."""
    from drake_entry.models.acceleration_ratios import sensed_vehicle
    from drake_entry.models.aerodynamics import ScaledAero
    from drake_entry.scenario import load_scenario

    nominal = load_scenario("cav_h_fnpeg").make_vehicle()
    alpha, mach = math.radians(12.0), 15.0
    cl, cd = nominal.aero.coefficients(alpha, mach)
    once = sensed_vehicle(nominal, (1.06, 0.97))
    twice = sensed_vehicle(once, np.array([0.95, 1.10]))
    assert once.aero.coefficients(alpha, mach) == pytest.approx((1.06 * cl, 0.97 * cd), rel=1e-14)
    assert twice.aero.coefficients(alpha, mach) == pytest.approx((0.95 * cl, 1.10 * cd), rel=1e-14)
    assert nominal.aero.coefficients(alpha, mach) == (cl, cd)  # the nominal vehicle is untouched
    dispersed = dc.replace(nominal, aero=ScaledAero(nominal.aero, 1.2, 1.0))
    assert sensed_vehicle(dispersed, (1.0, 0.5)).aero.coefficients(alpha, mach) == pytest.approx(
        (1.2 * cl, 0.5 * cd), rel=1e-14)


def test_sensed_vehicle_holds_q_and_the_heat_rate_in_the_air_it_senses():
    """Lift and drag sensed 1.2 and 1.1 times the nominal models': the density ratio assumed is
    sqrt(1.2 * 1.1); the q limit is divided by it and the heat-rate limit by its root (the
    models compute q and the heat rate with the nominal density), loads untouched; re-scaled
    from the nominal limits, not compounded; thinner air than modelled never loosens them."""
    from drake_entry.models.acceleration_ratios import sensed_density_ratio, sensed_vehicle
    from drake_entry.scenario import load_scenario

    nominal = load_scenario("cav_h_fnpeg").make_vehicle()
    lim = nominal.limits
    k = math.sqrt(1.2 * 1.1)
    assert sensed_density_ratio((1.2, 1.1)) == pytest.approx(k, rel=1e-15)
    dense = sensed_vehicle(nominal, (1.2, 1.1))
    assert dense.limits.dynamic_pressure_max == pytest.approx(lim.dynamic_pressure_max / k, rel=1e-14)
    assert dense.limits.heat_flux_max == pytest.approx(lim.heat_flux_max / math.sqrt(k), rel=1e-14)
    assert (dense.limits.total_load_max, dense.limits.normal_load_max) == (lim.total_load_max, lim.normal_load_max)
    again = sensed_vehicle(dense, (1.2, 1.1))
    assert again.limits == dense.limits and nominal.limits == lim
    assert sensed_vehicle(dense, (0.8, 0.9)).limits == lim  # thinner air: the nominal limits
    assert sensed_density_ratio((1.3, 0.9)) == pytest.approx(math.sqrt(1.17), rel=1e-15)


def test_compiled_actuator_path_is_the_actuator_law():
    """actuator_path (the form numba kernels call, compiled inline) gives integrate_actuator's
    positions and rates: a limited reversal, linear tracking, a settled actuator and a command
    beyond the position limit; run as Python here and compiled in the swarm evaluator's tests."""
    from drake_entry.models.actuator import actuator_path, integrate_actuator

    lim = dict(lower=-math.radians(80), upper=math.radians(80), rate_limit=math.radians(10),
               accel_limit=math.radians(5), bandwidth=2.0)
    for sigma, rate, command, steps in ((math.radians(60), 0.0, math.radians(-70), 300), (0.30, 0.0, 0.303, 100),
                                        (0.3, 0.0, 0.3, 5), (0.2, 0.05, math.radians(120), 50)):
        want = np.array(integrate_actuator(sigma, rate, command, 0.01, steps, **lim))
        got = np.empty((2, steps + 1))
        actuator_path(sigma, rate, command, 0.01, steps, lim["lower"], lim["upper"], lim["rate_limit"],
                      lim["accel_limit"], lim["bandwidth"], got[0], got[1])
        np.testing.assert_allclose(got, want, rtol=0.0, atol=1e-15)
