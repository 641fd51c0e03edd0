"""Open-loop entry diagram: schedules -> bank actuator -> EntryVehicle <- AtmosphereSystem,
with a termination monitor and loggers; ``simulate`` flies it and returns a Trajectory. The
vehicle and atmosphere are the native or the Python plant by ``simulation.plant``
(systems/native_plant.py).

    alpha schedule ---------------------------> alpha
    bank schedule --> BankActuator -----------> bank      EntryVehicle --> state, flight_conditions
    AtmosphereSystem(state) --air_data--> TerminationMonitor (Mach witness)
    TerminationMonitor(state, flight_conditions): witness functions stop the run
"""
from __future__ import annotations

from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import LogVectorOutput

from drake_entry.diagrams.common import run
from drake_entry.models.trajectory import Trajectory
from drake_entry.scenario import Scenario
from drake_entry.systems.actuators import BankActuator
from drake_entry.systems.lifetime import release_system
from drake_entry.systems.monitors import TerminationMonitor
from drake_entry.systems.native_plant import add_plant
from drake_entry.systems.schedule import make_schedule_source

__all__ = ["build_open_loop", "simulate"]


def build_open_loop(scenario: Scenario):
    """Diagram and the handles ``simulate`` needs."""
    vehicle = scenario.make_vehicle()
    planet = scenario.make_planet()
    atmosphere = scenario.make_atmosphere()
    builder = DiagramBuilder()
    # the atmosphere's air data feed the vehicle and the Mach witness
    plant, air, _ = add_plant(builder, vehicle, planet, atmosphere, initial_state=scenario.initial_state(),
                           plant=scenario.simulation.plant)
    alpha = builder.AddNamedSystem("alpha_schedule", make_schedule_source(scenario.schedule("alpha"), planet))
    bank = builder.AddNamedSystem("bank_schedule", make_schedule_source(scenario.schedule("bank"), planet))
    actuator = builder.AddNamedSystem("bank_actuator", BankActuator(
        bank_limit=vehicle.bank_limit, rate_limit=vehicle.bank_rate_limit, accel_limit=vehicle.bank_accel_limit,
        initial_bank=float(scenario.schedule("bank")(0.0)) if scenario.bank.variable == "time" else 0.0))
    t = scenario.terminal
    monitor = builder.AddNamedSystem("termination", TerminationMonitor(
        altitude=None if t.altitude_km is None else t.altitude_km * 1e3, mach=t.mach,
        velocity=t.velocity_m_s, energy=None if t.energy_MJ_kg is None else t.energy_MJ_kg * 1e6, planet=planet,
        geodetic=scenario.altitude_datum == "ellipsoid"))
    state = plant.GetOutputPort("state")
    conditions = plant.GetOutputPort("flight_conditions")
    sources = {"state": state, "flight_conditions": conditions, "air_data": air.GetOutputPort("air_data")}
    for src in (alpha, bank):
        for port, source in sources.items():
            if src.HasInputPort(port):
                builder.Connect(source, src.GetInputPort(port))
    builder.Connect(alpha.get_output_port(), plant.GetInputPort("alpha"))
    builder.Connect(bank.get_output_port(), actuator.get_input_port())
    builder.Connect(actuator.GetOutputPort("bank"), plant.GetInputPort("bank"))
    builder.Connect(state, monitor.GetInputPort("state"))
    builder.Connect(air.GetOutputPort("air_data"), monitor.GetInputPort("air_data"))
    period = scenario.simulation.log_period_s
    loggers = {
        "state": LogVectorOutput(state, builder, period),
        "conditions": LogVectorOutput(conditions, builder, period),
        "bank": LogVectorOutput(actuator.GetOutputPort("bank"), builder, period),
        "alpha": LogVectorOutput(alpha.get_output_port(), builder, period),
    }
    diagram = builder.Build()
    diagram.set_name(f"open_loop_{scenario.name}")
    return diagram, loggers


def simulate(scenario: Scenario, *, initial_state=None) -> Trajectory:
    """Fly the open-loop diagram until a terminal condition or max_time_s."""
    diagram, loggers = build_open_loop(scenario)
    sources = {"state": ("vehicle", "state"), "conditions": ("vehicle", "flight_conditions"),
               "bank": ("bank_actuator", "bank"), "alpha": ("alpha_schedule", 0)}
    try:
        return run(diagram, loggers, scenario, sources=sources, initial_state=initial_state)[0]
    finally:
        release_system(diagram)
