"""Example 1: build the open-loop entry diagram by hand and fly it with Drake's Simulator.

The systems are the library's Drake LeafSystems; the wiring is ordinary pydrake:

    alpha schedule --------------------------------> EntryVehicle "alpha"
    bank schedule --> BankActuator (rate/accel limits) --> EntryVehicle "bank"
    EntryVehicle "state" --> AtmosphereSystem --air_data--> TerminationMonitor
    loggers on the state and the flight conditions

The models come from the packaged HORUS-2B scenario (paper 000); change the scenario name,
the schedules or the stop condition and run it again. Writes an altitude-velocity plot and
a heat-flux plot.

    python examples/01_open_loop_diagram.py [--quick] [--out out/examples/01]
"""
import os

import numpy as np
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import LogVectorOutput

from drake_entry.claims import Claims, run_example
from drake_entry.figures import plt, save_figure
from drake_entry.models.dynamics import FLIGHT_CONDITION_NAMES
from drake_entry.scenario import load_scenario
from drake_entry.systems.actuators import BankActuator
from drake_entry.systems.atmosphere import AtmosphereSystem
from drake_entry.systems.monitors import TerminationMonitor
from drake_entry.systems.schedule import make_schedule_source
from drake_entry.systems.vehicle import EntryVehicle


def main(quick: bool = False, out_dir: str = "out/examples/01") -> dict:
    scenario = load_scenario("horus2b")  # or a path to your own scenario YAML
    vehicle, planet, atmosphere = scenario.make_vehicle(), scenario.make_planet(), scenario.make_atmosphere()

    builder = DiagramBuilder()
    plant = builder.AddNamedSystem("vehicle", EntryVehicle(vehicle, planet, atmosphere,
                                                           initial_state=scenario.initial_state()))
    air = builder.AddNamedSystem("atmosphere", AtmosphereSystem(atmosphere, planet))
    # the scenario's schedules: alpha(E) (energy scheduled, needs the state) and bank(t)
    alpha = builder.AddNamedSystem("alpha_schedule", make_schedule_source(scenario.schedule("alpha"), planet))
    bank = builder.AddNamedSystem("bank_schedule", make_schedule_source(scenario.schedule("bank"), planet))
    actuator = builder.AddNamedSystem("bank_actuator", BankActuator(
        bank_limit=vehicle.bank_limit, rate_limit=vehicle.bank_rate_limit, accel_limit=vehicle.bank_accel_limit))
    # stop at Mach 2.5 (the HORUS-2B terminal interface) or on the ground, whichever comes first
    monitor = builder.AddNamedSystem("termination", TerminationMonitor(mach=2.5, planet=planet))

    state, conditions = plant.GetOutputPort("state"), plant.GetOutputPort("flight_conditions")
    builder.Connect(state, air.get_input_port())
    for source in (alpha, bank):  # schedules in energy, Mach or speed read the vehicle
        if source.HasInputPort("state"):
            builder.Connect(state, source.GetInputPort("state"))
        if source.HasInputPort("flight_conditions"):
            builder.Connect(conditions, source.GetInputPort("flight_conditions"))
    builder.Connect(alpha.get_output_port(), plant.GetInputPort("alpha"))
    builder.Connect(bank.get_output_port(), actuator.get_input_port())
    builder.Connect(actuator.GetOutputPort("bank"), plant.GetInputPort("bank"))
    builder.Connect(state, monitor.GetInputPort("state"))
    builder.Connect(air.GetOutputPort("air_data"), monitor.GetInputPort("air_data"))
    state_log = LogVectorOutput(state, builder, 2.0)  # every 2 s
    conditions_log = LogVectorOutput(conditions, builder, 2.0)
    diagram = builder.Build()

    simulator = Simulator(diagram)
    context = simulator.get_mutable_context()
    context.SetAccuracy(1e-6)  # witness functions (the stop conditions) localise to this accuracy
    simulator.get_mutable_integrator().set_target_accuracy(1e-6)
    simulator.Initialize()
    status = simulator.AdvanceTo(300.0 if quick else scenario.simulation.max_time_s)
    print(f"stopped at t = {context.get_time():.1f} s: {status.message() or 'time limit'}")

    x = state_log.FindLog(context).data()  # rows: h, lon, lat, V, gamma, psi
    fc = conditions_log.FindLog(context).data()
    heat = fc[FLIGHT_CONDITION_NAMES.index("heat_flux")]
    t = state_log.FindLog(context).sample_times()
    print(f"final altitude {x[0, -1] / 1e3:.1f} km, speed {x[3, -1]:.0f} m/s, "
          f"peak heat flux {heat.max() / 1e3:.0f} kW/m^2 (limit {vehicle.limits.heat_flux_max / 1e3:.0f})")

    os.makedirs(out_dir, exist_ok=True)
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 4))
    ax1.plot(x[3] / 1e3, x[0] / 1e3)
    ax1.set(xlabel="velocity [km/s]", ylabel="altitude [km]", title="altitude-velocity")
    ax2.plot(t, heat / 1e3, label="heat flux")
    ax2.axhline(vehicle.limits.heat_flux_max / 1e3, color="r", ls="--", label="limit")
    ax2.set(xlabel="time [s]", ylabel="heat flux [kW/m^2]", title="stagnation-point heat flux")
    ax2.legend()
    path = save_figure(fig, out_dir, "open_loop.png")
    print(f"wrote {path}")
    return {"time_s": float(context.get_time()), "final_state": x[:, -1], "peak_heat_flux_W_m2": float(heat.max()),
            "stop": status.message() or "time limit",
            "plot": path}

def check(r: dict, quick: bool = False) -> Claims:
    """What this example shows, checked."""
    c = Claims("example 01: an open-loop diagram built by hand")
    if quick:
        c.check("the diagram flies the first 300 s", abs(r["time_s"] - 300.0) < 1e-6, f"{r['time_s']:.1f} s")
    else:
        c.check("the flight stops at its Mach 2.5 witness", "mach" in r["stop"].lower(), r["stop"])
    c.check("the logged state stays finite", bool(np.all(np.isfinite(r["final_state"]))))
    c.check("the plot is written", os.path.exists(r["plot"]), r["plot"])
    return c


if __name__ == "__main__":
    raise SystemExit(run_example(__doc__, main, check, out="out/examples/01", quick="fly the first 300 s only"))
