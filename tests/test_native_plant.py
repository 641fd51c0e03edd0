"""The native plant (SymbolicVectorSystems built from the models' symbolic form) against the
Python reference systems: the same numbers at every state, and the same flight."""
import dataclasses as dc
import math

import numpy as np
import pytest
from pydrake.symbolic import Expression, Variable
from pydrake.systems.analysis import ResetIntegratorFromFlags, Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import ConstantVectorSource

from drake_entry.errors import ModelRangeError, NonFiniteStateError, ScenarioError
from drake_entry.models.aerodynamics import ScaledAero, TableAero
from drake_entry.models.atmosphere import (
    DispersedAtmosphere,
    ExponentialAtmosphere,
    TableAtmosphere,
    US76Atmosphere,
)
from drake_entry.models.planet import Earth
from drake_entry.models.vehicles import load_vehicle
from drake_entry.systems.monitors import PlantGuard
from drake_entry.systems.native_plant import (
    NativeAtmosphere,
    NativeEntryVehicle,
    PlantProbe,
    add_plant,
    flight_stop,
)
from drake_entry.systems.vehicle import EntryVehicle

VEHICLES = ("horus2b", "sphynx", "shefex3", "cav_h", "marv")


def _atmospheres():
    us76 = US76Atmosphere()
    z = np.linspace(0.0, 150e3, 40)
    table = TableAtmosphere(z, us76.density(z), us76.temperature(z), source="US76 sampled every 3.8 km (test)")
    return {"us76": us76, "exponential": ExponentialAtmosphere(),
            "dispersed": DispersedAtmosphere(us76, scale=1.12, amplitude=0.08, wavelength=9000.0, phase=0.7),
            "table": table}


def test_symbolic_us76_equals_the_float_model_across_layers_and_the_upper_table():
    """Every layer below 86 km (both sides of each base), the 86-km seam and the upper splines."""
    us76 = US76Atmosphere()
    h = Variable("h")
    rho, T, a = us76.properties(Expression(h))
    bases_m = [0.0, 11019.1, 20063.1, 32161.9, 47350.1, 51412.5, 71802.0, 86000.0]
    z = np.concatenate([np.linspace(-5e3, 1e6, 3001), np.add.outer(bases_m, [-1e-3, 0.0, 1e-3]).ravel()])
    worst = 0.0
    for zi in z:
        ref = us76.properties(float(zi))
        got = [e.Evaluate({h: float(zi)}) for e in (rho, T, a)]
        worst = max(worst, max(abs(g / r - 1.0) for g, r in zip(got, ref)))
    assert worst < 1e-13


@pytest.mark.parametrize("name", list(_atmospheres()))
def test_native_atmosphere_equals_atmosphere_system(name):
    atm = _atmospheres()[name]
    earth = Earth.spherical()
    system = NativeAtmosphere(atm, earth)
    ctx = system.CreateDefaultContext()
    for h in np.linspace(1e3, 140e3, 57):
        x = np.array([h, 0.1, 0.2, 5000.0, -0.01, 1.0])
        system.GetInputPort("state").FixValue(ctx, x)
        got = system.GetOutputPort("air_data").Eval(ctx)
        ref = atm.air_data(float(h))
        assert np.allclose(got, ref, rtol=1e-12, atol=0.0), (name, h)


@pytest.mark.parametrize("vehicle_name", VEHICLES)
@pytest.mark.parametrize("planet", ["spherical", "oblate"])
def test_native_derivatives_and_conditions_equal_the_python_plant(vehicle_name, planet):
    """Derivatives and flight conditions to 1e-9 relative (measured: about 1e-15), for every
    packaged vehicle, a dispersed copy (aero scales, mass), both planets, over a grid of states
    and controls."""
    earth = Earth.spherical() if planet == "spherical" else Earth.oblate()
    atm = _atmospheres()["dispersed"]
    base = load_vehicle(vehicle_name)
    for vehicle in (base, _dispersed(base)):
        probes = [PlantProbe(vehicle, earth, atm, plant=kind) for kind in ("python", "native")]
        assert [p.plant for p in probes] == ["python", "native"]
        rng = np.random.default_rng(3)
        for _ in range(25):
            x = np.array([rng.uniform(20e3, 90e3), rng.uniform(-3, 3), rng.uniform(-1.2, 1.2),
                          rng.uniform(1500.0, 7500.0), rng.uniform(-0.2, 0.1), rng.uniform(-3, 3)])
            bank, alpha = rng.uniform(-1.4, 1.4), rng.uniform(0.0, 0.8)
            (xd_py, fc_py), (xd_nat, fc_nat) = (probe(x, bank, alpha) for probe in probes)
            assert np.all(np.abs(xd_nat - xd_py) <= 1e-9 * np.abs(xd_py) + 1e-300), (vehicle_name, x)
            assert np.all(np.abs(fc_nat - fc_py) <= 1e-9 * np.abs(fc_py) + 1e-300), (vehicle_name, x)


def test_native_flight_ends_within_a_millimetre_of_the_python_flight():
    """A 900-s HORUS-2B glide at constant bank and alpha (fixed RK3 steps of 0.5 s, the closed
    loop's) ends at the same state: measured 2e-10 m apart; asserted 1 m and 1e-6 m/s."""
    horus, earth = load_vehicle("horus2b"), Earth.spherical()
    atm = US76Atmosphere()
    ends = []
    for native in (False, True):
        diagram, plant = _plant_diagram(native, horus, earth, atm, bank=0.9, alpha=math.radians(40.0),
                                        initial_state=[120e3, -2.6, 0.3, 7400.0, math.radians(-1.3), 1.2])
        simulator = Simulator(diagram)
        ResetIntegratorFromFlags(simulator, "runge_kutta3", 0.5).set_fixed_step_mode(True)
        simulator.AdvanceTo(900.0)
        ends.append(plant.GetOutputPort("state").Eval(plant.GetMyContextFromRoot(simulator.get_context())).copy())
    py, nat = ends
    assert py[0] < 75e3 and py[3] < 6500.0  # it flew down into the sensible atmosphere and slowed
    assert abs(py[0] - nat[0]) < 1.0 and abs(py[3] - nat[3]) < 1e-6
    assert earth.great_circle_distance(py[1], py[2], nat[1], nat[2]) < 1.0


def test_native_plant_resets_to_its_entry_state():
    """Drake's RandomSimulation resets every context to its defaults: the native plant's
    default is the entry state it was built with (its state is the deviation from it)."""
    x0 = np.array([100e3, 0.1, 0.2, 7000.0, -0.02, 0.5])
    plant = NativeEntryVehicle(load_vehicle("horus2b"), Earth.spherical(), initial_state=x0)
    ctx = plant.CreateDefaultContext()
    assert np.array_equal(plant.GetOutputPort("state").Eval(ctx), x0)
    plant.set_initial_state(ctx, x0 + 1.0)
    assert np.allclose(plant.GetOutputPort("state").Eval(ctx), x0 + 1.0, rtol=0, atol=1e-9)
    plant.SetDefaultContext(ctx)
    assert np.array_equal(plant.GetOutputPort("state").Eval(ctx), x0)


def test_a_model_without_symbolic_form_flies_the_python_plant_unless_native_is_demanded():
    """plant 'auto' takes the Python plant for an aerodynamic table (no symbolic form); 'native'
    refuses it naming the model; an unknown name names the field and the allowed values."""
    horus = load_vehicle("horus2b")
    alpha_deg, mach = np.array([0.0, 20.0, 40.0, 60.0]), np.array([1.0, 5.0, 10.0, 25.0])
    cl = np.outer(np.sin(np.radians(alpha_deg)), np.ones(4))
    vehicle = dc.replace(horus, aero=TableAero(alpha_deg=alpha_deg, mach=mach, CL=cl, CD=0.1 + cl**2))
    plant, _, used = add_plant(DiagramBuilder(), vehicle, Earth.spherical(), US76Atmosphere(), initial_state=None)
    assert isinstance(plant, EntryVehicle) and used == "python"
    plant, _, used = add_plant(DiagramBuilder(), horus, Earth.spherical(), US76Atmosphere(), initial_state=None)
    assert isinstance(plant, NativeEntryVehicle) and used == "native"
    with pytest.raises(ScenarioError, match="simulation.plant = 'native' needs models with a symbolic form: "
                                            "this model is a table look-up"):
        add_plant(DiagramBuilder(), vehicle, Earth.spherical(), US76Atmosphere(), initial_state=None, plant="native")
    with pytest.raises(ScenarioError, match="simulation.plant = 'fortran'; allowed: auto, native, python"):
        add_plant(DiagramBuilder(), horus, Earth.spherical(), US76Atmosphere(), initial_state=None, plant="fortran")


def test_a_campaign_row_names_the_plant_it_flew(tmp_path):
    from drake_entry.campaign.sample import run_sample
    from drake_entry.diagrams.closed_loop import ClosedLoopSetup
    from drake_entry.scenario import load_scenario

    scenario = load_scenario("horus2b")
    scenario.simulation.max_time_s = 30.0  # a short flight: only the row's bookkeeping is checked
    for plant in ("python", "auto"):
        scenario.simulation.plant = plant
        row, _ = run_sample(ClosedLoopSetup.from_scenario(scenario), 1, 0, trajectory_step_s=0.0)
        assert row["plant"] == {"python": "python", "auto": "native"}[plant]
        assert row["stop"] == "max_time" and not row["success"]


def test_plant_guard_stops_a_native_flight_where_the_python_plant_would_raise():
    """The native plant cannot raise our errors: the PlantGuard's witness stops a flight at the end
    of the step where it left the atmosphere model (ModelRangeError, as US76 raises); a NaN
    state that reaches a sqrt inside a stage is Drake's ValueError, which the flight runners
    turn into the NonFiniteStateError the Python plant raises (flight_stop); any other ValueError
    is a bug the runners re-raise."""
    horus, earth, us76 = load_vehicle("horus2b"), Earth.spherical(), US76Atmosphere()
    for bank, x0, error, words in (
            (0.3, [999.5e3, 0.1, 0.2, 7000.0, 0.5, 1.0], ModelRangeError, "outside the PlantGuard range"),
            (math.nan, [60e3, 0.1, 0.2, 6000.0, -0.02, 1.0], ValueError, "numerical argument out of domain")):
        builder = DiagramBuilder()
        plant, _, used = add_plant(builder, horus, earth, us76, initial_state=x0, plant="native")
        guard = builder.AddSystem(PlantGuard(h_min=us76.h_min, h_max=us76.h_max, model="PlantGuard", planet=earth))
        builder.Connect(plant.GetOutputPort("state"), guard.get_input_port())
        for port, v in (("bank", bank), ("alpha", 0.6)):
            builder.Connect(builder.AddSystem(ConstantVectorSource([v])).get_output_port(), plant.GetInputPort(port))
        simulator = Simulator(builder.Build())
        ResetIntegratorFromFlags(simulator, "runge_kutta3", 0.1).set_fixed_step_mode(True)
        with pytest.raises(error, match=words) as raised:
            simulator.AdvanceTo(30.0)
        assert used == "native" and simulator.get_context().get_time() < 5.0
        # a NaN reaches the atmosphere's sqrt inside an integrator stage, where Drake's symbolic
        # evaluation refuses it: the flight runners take that as the non-finite state it is
        stop = flight_stop(raised.value)
        assert isinstance(stop, error if error is ModelRangeError else NonFiniteStateError), stop
    assert flight_stop(ValueError("any other ValueError")) is None  # a bug: re-raised by the runners


def test_a_verified_flight_that_leaves_the_atmosphere_model_stops_with_the_reason():
    """Controls that dive the vehicle into the ground, flown by the verifier: the flight stops
    below the atmosphere model with that reason (a failed flight), not an exception."""
    from drake_entry.diagrams.verification import fly_controls
    from drake_entry.planning.verification import EntryControls

    horus, earth, us76 = load_vehicle("horus2b"), Earth.spherical(), US76Atmosphere()
    controls = EntryControls(horus, earth, us76, np.array([2e3, 0.1, 0.2, 800.0, -0.5, 1.0]), 300.0,
                             np.array([0.0, 300.0]), np.array([0.0, 0.0]), np.array([0.0, 0.0]))
    flown = fly_controls(controls)
    assert "the flight stopped at t = " in flown.failure and "outside the" in flown.failure
    assert flown.time[-1] < 100.0


def test_ocp_controls_fly_the_same_on_the_native_dynamics_and_stop_where_the_python_plant_raises():
    """An NLP's controls (Betts' shuttle, its propagated guess) flown by the verifier on the
    problem's dynamics as a SymbolicVectorSystem and as the Python OptimalControlPlant: the same
    final state (1e-6 relative; the same RK5 steps up to rounding); a bank of 80 deg at zero
    alpha dives below the exponential model's -5 km, and both flights stop there with the same
    reason (the native one by its PlantGuard, within one integrator step of the other)."""
    from drake_entry.diagrams.verification import fly_controls
    from drake_entry.planning.nlp import catalogue
    from drake_entry.planning.nlp.guess import initial_guess
    from drake_entry.planning.ocp_system import native_ocp_plant
    from drake_entry.planning.verification import OcpControls

    problem, _ = catalogue.shuttle_crossrange()
    assert native_ocp_plant(problem) is not None  # "auto" flies it natively
    t, X, U = initial_guess(problem)
    flown = {k: fly_controls(OcpControls(problem, X[0], float(t[-1]), t, U, "linear"), plant=k)
             for k in ("python", "native")}
    assert not flown["python"].failure and not flown["native"].failure
    end_py, end_native = flown["python"].states[-1], flown["native"].states[-1]
    assert end_py[0] > 20e3  # a real flight to the guess's end, not a stop
    np.testing.assert_allclose(end_native, end_py, rtol=1e-6, atol=1e-6)
    dive = U.copy()
    dive[:, 0], dive[:, 1] = 0.0, math.radians(80.0)
    stopped = {k: fly_controls(OcpControls(problem, X[0], 3 * float(t[-1]), 3 * t, dive, "linear"), plant=k)
               for k in ("python", "native")}
    for f in stopped.values():
        assert "outside the exponential range [-5000, 1e+07] m" in f.failure, f.failure
    assert abs(stopped["native"].time[-1] - stopped["python"].time[-1]) < 0.1
    assert stopped["native"].time[-1] < float(t[-1])


def test_a_native_ocp_flight_is_refused_for_a_model_without_a_symbolic_form():
    """plant='native' on a problem whose vehicle's aerodynamics are a table look-up: a
    ScenarioError saying so; 'auto' flies it on the Python plant."""
    from drake_entry.diagrams.verification import fly_controls
    from drake_entry.planning.nlp import catalogue
    from drake_entry.planning.nlp.guess import initial_guess
    from drake_entry.planning.ocp_system import native_ocp_plant
    from drake_entry.planning.verification import OcpControls

    problem, _ = catalogue.shuttle_crossrange()
    alpha_deg, mach = np.array([0.0, 20.0, 40.0, 60.0]), np.array([1.0, 5.0, 10.0, 30.0])
    cl = np.outer(np.sin(np.radians(alpha_deg)), np.ones(4))
    problem = dc.replace(problem, vehicle=dc.replace(problem.vehicle, aero=TableAero(alpha_deg=alpha_deg, mach=mach,
                                                                                      CL=cl, CD=0.1 + cl**2)))
    assert native_ocp_plant(problem) is None
    t, X, U = initial_guess(problem)
    controls = OcpControls(problem, X[0], 100.0, t, U, "linear")
    with pytest.raises(ScenarioError, match="needs the problem's models in a symbolic form"):
        fly_controls(controls, plant="native")
    assert fly_controls(controls, plant="auto").time[-1] == pytest.approx(100.0)


# -- helpers ----------------------------------------------------------------------------
def _dispersed(vehicle):
    return dc.replace(vehicle, mass=vehicle.mass * 1.04, aero=ScaledAero(vehicle.aero, 0.93, 1.07))


def _plant_diagram(native, vehicle, earth, atm, *, bank, alpha, initial_state):
    builder = DiagramBuilder()
    x0 = np.asarray(initial_state, float)
    plant, _, _ = add_plant(builder, vehicle, earth, atm, initial_state=x0, plant="native" if native else "python")
    for port, v in (("bank", bank), ("alpha", alpha)):
        builder.Connect(builder.AddSystem(ConstantVectorSource([v])).get_output_port(), plant.GetInputPort(port))
    return builder.Build(), plant
