"""SwarmBankGuidance: paper 004's guidance law on board (drake_entry.guidance.swarm_bank).

Every ``period`` seconds the law gives |sigma| (eq. 17 from sigma_0 with the QEG compensation,
eqs. 46-48) and the alpha command (eq. 31, or eq. 21 until Mach_shift) from the navigation
estimate and the sensed flight conditions; the shared reversal logic signs |sigma| and the
shared actuators fly both. With ``replan_period`` > 0, sigma_0 is re-solved on board from
the estimate (guidance.swarm_bank.search.resolve_sigma0: predicted trajectories of the same law;
with ``end_bounds_deg``, sigma_f too where sigma_0 alone brackets no root: resolve_bank_end)
on the shared schedule (systems/replan_scheduler.py: the first one ``replan_period`` after
entry) until the normalised energy ``replan_until_e`` (a re-solution due past it is skipped).
The predictions fly the nominal models with the lift and drag scaled by the ratios of the
sensed to the modelled accelerations, low-passed over 30 s (``acceleration_scaling``): a density or aerodynamic error the flight has shown is then
predicted for the rest of it (with the nominal models the 1-sigma range miss of 100 dispersed
flights was 31 km; scaled, see docs/methods/swarm-bank.md).

Ports:
  - input  "estimated_state"    [6]  navigation estimate [h m, lon, lat rad, V m/s, gamma, psi rad]
  - input  "flight_conditions"  [9]  sensed rho, Mach, q, heat flux, loads, L, D, E (true vehicle)
  - input  "bank_command"       [1]  the signed bank command [rad] (its sign starts the on-board
                                   predictions; read only when re-solving, so no feedthrough)
  - input  "bank_flown"         [2]  the bank actuator's position [rad] and rate [rad/s], where the
                                   predictions' actuator starts (a reversal under way is flown on
                                   in them); optional: unconnected, they start at the command, at rest
  - output "bank_magnitude"     [1]  |sigma| [rad]
  - output "alpha_command"      [1]  alpha [rad]
  - output "sigma0"             [1]  the sigma_0 in use [rad]
  - output "sigma_f"            [1]  the sigma_f in use [rad] (re-solved with ``end_bounds_deg``)
  - output "plan_stats"         [3]  re-solutions, re-solutions without a bracketed root (or that
                                   raised: the sigma_0 in use flies on), wall time [s]
  - output "replan_stats"       [4]  the schedule's account (systems/replan_scheduler.py)

The commands are computed from the inputs and the law's memory (previous alpha command, Case 2
switch) at each sample: the actuators sample them at the same instant, as the planner's
evaluation assumes (guidance/swarm_bank/evaluator.py).
"""
from __future__ import annotations

import dataclasses as dc
import math

import numpy as np
from pydrake.systems.framework import BasicVector

from drake_entry.errors import ScenarioError
from drake_entry.guidance.swarm_bank.evaluator import SwarmProblem
from drake_entry.guidance.swarm_bank.guidance_law import LawMemory, law_commands
from drake_entry.guidance.swarm_bank.search import resolve_bank_end, resolve_sigma0
from drake_entry.models.acceleration_ratios import filtered_ratios, sensed_vehicle
from drake_entry.models.dynamics import FLIGHT_CONDITION_NAMES
from drake_entry.systems.lifetime import weak_element, weak_method
from drake_entry.systems.replan_scheduler import ReplanScheduler

__all__ = ["SwarmBankGuidance"]

_FC = {name: i for i, name in enumerate(FLIGHT_CONDITION_NAMES)}
# discrete state: law memory (3), sigma_0, filtered sensed/modelled lift and drag ratios, sigma_f
_ALPHA, _ABOVE, _SWITCHED, _SIGMA0, _KL, _KD, _SIGMAF = range(7)


class SwarmBankGuidance(ReplanScheduler):
    def __init__(self, problem: SwarmProblem, sigma0: float, *, period: float = 1.0, replan_period: float = 0.0,
                 replan_until_e: float = 0.95, bounds_deg=(0.0, 89.0), acceleration_scaling: bool = True,
                 latency_s: float = 0.0, latency_factor: float = 0.0, end_bounds_deg=None):
        """Args: problem (the mission and law, nominal models); sigma0 [rad] planned; period [s];
        replan_period [s] (0 = fly sigma0); replan_until_e: last normalised energy of a
        re-solution; bounds_deg: sigma_0 bounds of a re-solution (eq. 17 stays anchored at the
        entry energy); acceleration_scaling: the predictions fly the nominal lift and drag times the
        filtered ratios of the sensed to the modelled accelerations (a density or aerodynamic
        error the flight has shown), instead of the nominal models; latency_s [s], latency_factor:
        each re-solution's computing latency (systems/replan_scheduler.py); end_bounds_deg:
        when a re-solution's sigma_0 brackets no root, sigma_f is re-solved within these bounds
        with that sigma_0 held (search.resolve_bank_end; None: sigma_f stays the planned one)."""
        super().__init__()
        if not period > 0:
            raise ScenarioError(f"SwarmBankGuidance.period must be > 0 s, got {period}")
        if not math.isfinite(sigma0):
            raise ScenarioError(f"SwarmBankGuidance.sigma0 = {sigma0} must be finite (the plan found no sigma_0)")
        self.problem, self.law = problem, problem.law()
        self.replan_until_e, self.bounds_deg, self.end_bounds_deg = replan_until_e, bounds_deg, end_bounds_deg
        self.acceleration_scaling, self.period = acceleration_scaling, period
        self.est_port = self.DeclareVectorInputPort("estimated_state", 6)
        self.fc_port = self.DeclareVectorInputPort("flight_conditions", len(FLIGHT_CONDITION_NAMES))
        self.bank_port = self.DeclareVectorInputPort("bank_command", 1)
        self.flown_port = self.DeclareVectorInputPort("bank_flown", 2)
        alpha0 = problem.entry_alpha
        self._state = self.DeclareDiscreteState(BasicVector([alpha0, 0.0, 0.0, sigma0, 1.0, 1.0, problem.sigma_f]))
        self.DeclareReplanSchedule(replan_period_s=replan_period,
                                   first_due_s=replan_period if replan_period > 0 else math.inf,
                                   latency_s=latency_s, latency_factor=latency_factor, pending_size=2)
        self.DeclarePeriodicDiscreteUpdateEvent(period, 0.0, weak_method(self._update))
        deps = {self.xd_ticket(), self.est_port.ticket(), self.fc_port.ticket()}
        self.DeclareVectorOutputPort("bank_magnitude", 1, weak_element(self.commands, 0),
                                     prerequisites_of_calc=deps)
        self.DeclareVectorOutputPort("alpha_command", 1, weak_element(self.commands, 1),
                                     prerequisites_of_calc=deps)
        self.DeclareVectorOutputPort("sigma0", 1, weak_element(self._memory, _SIGMA0),
                                     prerequisites_of_calc={self.xd_ticket()})
        self.DeclareVectorOutputPort("sigma_f", 1, weak_element(self._memory, _SIGMAF),
                                     prerequisites_of_calc={self.xd_ticket()})
        self.DeclareVectorOutputPort("plan_stats", 3, weak_method(self._plan_stats),
                                     prerequisites_of_calc={self.xd_ticket()})

    def _plan_stats(self, context, output):
        s = self.replan_stats(context)
        output.SetFromVector([s.attempts, s.flawed, s.wall_s])

    def _memory(self, context) -> np.ndarray:
        return context.get_discrete_state(self._state).get_value()

    def commands(self, context):
        """(|sigma| [rad], alpha command [rad], next LawMemory) at this sample."""
        m = self._memory(context)
        x = np.asarray(self.est_port.Eval(context), float)[:, None]
        fc = self.fc_port.Eval(context)
        v = {k: np.array([fc[_FC[k]]]) for k in ("rho", "mach", "lift", "drag", "heat_flux", "dynamic_pressure")}
        memory = LawMemory(np.array([m[_ALPHA]]), np.array([m[_ABOVE] > 0.5]), np.array([m[_SWITCHED] > 0.5]))
        veh = self.problem.vehicle
        magnitude, alpha, nxt = law_commands(self.law, np.array([m[_SIGMA0]]), x, self.problem.planet.radius(x[0]),
                                             v["rho"], v["mach"], v["lift"], v["drag"], v["heat_flux"],
                                             v["dynamic_pressure"], veh.aero, veh.area_over_mass, memory,
                                             sigma_f=np.array([m[_SIGMAF]]))
        return float(magnitude[0]), float(alpha[0]), nxt

    def _update(self, context, discrete_state):
        m = self._memory(context).copy()
        _, alpha, nxt = self.commands(context)
        m[_ALPHA], m[_ABOVE], m[_SWITCHED] = alpha, float(nxt.mach_was_above[0]), float(nxt.switched[0])
        if self.acceleration_scaling and self.replan_period_s > 0:  # only re-solutions read the ratios
            self._update_ratios(context, m)
        t = context.get_time()
        held = self.take_held(context, discrete_state)
        if held is not None:  # a sigma_0 (and sigma_f) solved one latency ago flies from now
            m[_SIGMA0], m[_SIGMAF] = held[0], held[1]
        if self.replan_due(context):
            x = np.asarray(self.est_port.Eval(context), float)
            p = self.problem
            e = p.energy(x[0], x[3])
            if (e - p.start_energy) / (p.ef - p.start_energy) > self.replan_until_e:
                self.skip(discrete_state, t)
            else:
                bank = float(self.bank_port.Eval(context)[0])
                flown = self.flown_port.Eval(context) if self.flown_port.HasValue(context) else (bank, 0.0)

                def solve():
                    vehicle = sensed_vehicle(p.vehicle, (m[_KL], m[_KD])) if self.acceleration_scaling else p.vehicle
                    here = dc.replace(p, vehicle=vehicle, x0=x, e0=p.start_energy, origin=(p.x0[1], p.x0[2]),
                                      initial_alpha=alpha, initial_bank=float(flown[0]),
                                      initial_bank_rate=float(flown[1]), initial_sign=1.0 if bank >= 0 else -1.0,
                                      memory=(bool(nxt.mach_was_above[0]), bool(nxt.switched[0])),
                                      max_time_s=max(p.max_time_s - t, p.guidance_step_s), sigma_f=float(m[_SIGMAF]))
                    r = resolve_sigma0(here, math.degrees(m[_SIGMA0]), self.bounds_deg)
                    if not r.bracketed and math.isfinite(r.sigma0_deg) and self.end_bounds_deg is not None:
                        end = resolve_bank_end(here, r.sigma0_deg, self.end_bounds_deg)
                        r = dc.replace(end, trajectories=end.trajectories + r.trajectories)
                    finite = math.isfinite(r.sigma0_deg)
                    return r, finite, "" if finite and r.bracketed else "no bracketed root"

                def numbers(r):
                    sigma_f = m[_SIGMAF] if math.isnan(r.sigma_f_deg) else math.radians(r.sigma_f_deg)
                    return [math.radians(r.sigma0_deg), sigma_f]

                outcome = self.attempt(context, discrete_state, solve, encode=numbers)
                if outcome.apply_now:
                    m[_SIGMA0], m[_SIGMAF] = numbers(outcome.result)
        discrete_state.get_mutable_vector(self._state).SetFromVector(m)

    def _update_ratios(self, context, m):
        """Low-pass the ratios of the sensed lift and drag to the nominal models' at the
        estimate (alpha: the previous command) into m[_KL], m[_KD]."""
        p = self.problem
        x = np.asarray(self.est_port.Eval(context), float)
        fc = self.fc_port.Eval(context)
        m[_KL], m[_KD] = filtered_ratios((m[_KL], m[_KD]), x, float(m[_ALPHA]), float(fc[_FC["lift"]]),
                                         float(fc[_FC["drag"]]), p.vehicle, p.planet, p.atmosphere, self.period)
