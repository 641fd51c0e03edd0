"""Open-loop entry diagram: schedules -> bank actuator -> EntryVehicle <- AtmosphereSystem,
with a termination monitor and loggers; ``simulate`` flies it and returns a Trajectory.

    alpha schedule ---------------------------> alpha
    bank schedule --> BankActuator -----------> bank      EntryVehicle --> state, flight_conditions
    AtmosphereSystem(state) ------------------> air_data
    TerminationMonitor(state, flight_conditions): witness functions stop the run
"""
from __future__ import annotations

import dataclasses as dc
import time as _time

import numpy as np
from pydrake.systems.analysis import ResetIntegratorFromFlags, Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import LogVectorOutput

from drake_entry.dynamics import FLIGHT_CONDITION_NAMES, STATE_NAMES
from drake_entry.scenario import Scenario
from systems.actuators import BankActuator
from systems.atmosphere import AtmosphereSystem
from systems.monitors import TerminationMonitor
from systems.schedule import make_schedule_source
from systems.vehicle import EntryVehicle


@dc.dataclass
class Trajectory:
    """A simulated trajectory sampled at the log period (plus the final instant).

    Attributes:
      time: [s], shape (n,). state: (n, 6) [h, lon, lat, V, gamma, psi] SI.
      conditions: (n, 9) FlightConditions columns. bank, alpha: (n,) [rad].
      reason: why the run stopped. wall_time: [s].
    """

    time: np.ndarray
    state: np.ndarray
    conditions: np.ndarray
    bank: np.ndarray
    alpha: np.ndarray
    reason: str
    wall_time: float

    def column(self, name: str) -> np.ndarray:
        if name in STATE_NAMES:
            return self.state[:, STATE_NAMES.index(name)]
        if name in FLIGHT_CONDITION_NAMES:
            return self.conditions[:, FLIGHT_CONDITION_NAMES.index(name)]
        return {"time": self.time, "bank": self.bank, "alpha": self.alpha}[name]

    def table(self) -> dict:
        """Columns with units in the names (for Parquet / CSV)."""
        out = {"time_s": self.time,
               "altitude_m": self.state[:, 0], "longitude_deg": np.degrees(self.state[:, 1]),
               "latitude_deg": np.degrees(self.state[:, 2]), "velocity_m_s": self.state[:, 3],
               "flight_path_deg": np.degrees(self.state[:, 4]), "heading_deg": np.degrees(self.state[:, 5]),
               "bank_deg": np.degrees(self.bank), "alpha_deg": np.degrees(self.alpha)}
        units = {"rho": "density_kg_m3", "mach": "mach", "dynamic_pressure": "dynamic_pressure_Pa",
                 "heat_flux": "heat_flux_W_m2", "normal_load": "normal_load_g", "total_load": "total_load_g",
                 "lift": "lift_m_s2", "drag": "drag_m_s2", "energy": "energy_J_kg"}
        for i, name in enumerate(FLIGHT_CONDITION_NAMES):
            out[units[name]] = self.conditions[:, i]
        return out


def build_open_loop(scenario: Scenario):
    """Diagram and the handles ``simulate`` needs."""
    vehicle = scenario.make_vehicle()
    planet = scenario.make_planet()
    atmosphere = scenario.make_atmosphere()
    builder = DiagramBuilder()
    plant = builder.AddNamedSystem("vehicle", EntryVehicle(vehicle, planet, atmosphere,
                                                           initial_state=scenario.initial_state(),
                                                           air_data_input=True))
    air = builder.AddNamedSystem("atmosphere", AtmosphereSystem(atmosphere, planet))
    alpha = builder.AddNamedSystem("alpha_schedule", make_schedule_source(scenario.schedule("alpha"), planet))
    bank = builder.AddNamedSystem("bank_schedule", make_schedule_source(scenario.schedule("bank"), planet))
    actuator = builder.AddNamedSystem("bank_actuator", BankActuator(
        bank_limit=vehicle.bank_limit, rate_limit=vehicle.bank_rate_limit, accel_limit=vehicle.bank_accel_limit,
        initial_bank=float(scenario.schedule("bank")(0.0)) if scenario.bank.variable == "time" else 0.0))
    t = scenario.terminal
    monitor = builder.AddNamedSystem("termination", TerminationMonitor(
        altitude=None if t.altitude_km is None else t.altitude_km * 1e3, mach=t.mach,
        velocity=t.velocity_m_s, energy=None if t.energy_MJ_kg is None else t.energy_MJ_kg * 1e6, planet=planet))
    state = plant.GetOutputPort("state")
    conditions = plant.GetOutputPort("flight_conditions")
    builder.Connect(state, air.get_input_port())
    builder.Connect(air.GetOutputPort("air_data"), plant.GetInputPort("air_data"))
    for src in (alpha, bank):
        for port in ("state", "flight_conditions"):
            if src.HasInputPort(port):
                builder.Connect(state if port == "state" else conditions, src.GetInputPort(port))
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


def configure_integrator(simulator: Simulator, scenario: Scenario):
    """Integrator, accuracy and maximum step from the scenario (RK5 by default; see DESIGN.md)."""
    sim = scenario.simulation
    integrator = ResetIntegratorFromFlags(simulator, sim.integrator, sim.max_step_s)
    integrator.set_target_accuracy(sim.accuracy)
    integrator.set_maximum_step_size(sim.max_step_s)
    # witness functions need the context accuracy set explicitly (DESIGN.md)
    simulator.get_mutable_context().SetAccuracy(sim.accuracy)
    return integrator


def simulate(scenario: Scenario, *, initial_state=None) -> Trajectory:
    """Fly the open-loop diagram until a terminal condition or max_time_s."""
    diagram, loggers = build_open_loop(scenario)
    simulator = Simulator(diagram)
    context = simulator.get_mutable_context()
    plant = diagram.GetSubsystemByName("vehicle")
    if initial_state is not None:
        plant.set_initial_state(plant.GetMyMutableContextFromRoot(context), initial_state)
    configure_integrator(simulator, scenario)
    simulator.Initialize()
    t0 = _time.perf_counter()
    status = simulator.AdvanceTo(scenario.simulation.max_time_s)
    wall = _time.perf_counter() - t0
    reason = status.message() if status.reason() != status.ReturnReason.kReachedBoundaryTime else "max_time"
    logs = {k: v.FindLog(context) for k, v in loggers.items()}
    # append the exact final instant (the witness-located terminal point)
    plant_ctx = plant.GetMyContextFromRoot(context)
    t_end = context.get_time()
    final = {
        "state": plant.GetOutputPort("state").Eval(plant_ctx),
        "conditions": plant.GetOutputPort("flight_conditions").Eval(plant_ctx),
        "bank": diagram.GetSubsystemByName("bank_actuator").GetOutputPort("bank").Eval(
            diagram.GetSubsystemByName("bank_actuator").GetMyContextFromRoot(context)),
        "alpha": diagram.GetSubsystemByName("alpha_schedule").get_output_port().Eval(
            diagram.GetSubsystemByName("alpha_schedule").GetMyContextFromRoot(context)),
    }
    times = logs["state"].sample_times()
    keep = times < t_end - 1e-9
    data = {k: np.column_stack([logs[k].data()[:, keep], final[k]]) for k in logs}
    return Trajectory(
        time=np.append(times[keep], t_end),
        state=data["state"].T,
        conditions=data["conditions"].T,
        bank=data["bank"][0],
        alpha=data["alpha"][0],
        reason=reason,
        wall_time=wall,
    )
