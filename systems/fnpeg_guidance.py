"""FnpegGuidance: Lu (2014)'s predictor-corrector on board (drake_entry.guidance.fnpeg).

Every ``period`` seconds, from the navigation estimate and the sensed flight conditions:
before engagement |sigma| holds ``bank_before``; the guidance engages when the sensed
aerodynamic acceleration sqrt(L^2 + D^2) reaches ``engage_acceleration``. Engaged, at once and
then every ``replan_period`` seconds on the shared schedule (systems/replan_scheduler.py; while V
is above the setup's hold speed) the corrector solves sigma_0 from the estimate with the current
bank sign held in the predictions; every period
|sigma| is the profile's sigma_0 with the altitude-rate feedback on the navigated hdot and the
sensed L, D, heat rate and q. The shared reversal logic signs |sigma|; the shared actuators fly
it and the alpha profile's command. The commands computed at a sample are output from the
next (one guidance period of computing delay).

Ports:
  - input  "estimated_state"    [6]  [h m, lon, lat rad, V m/s, gamma, psi rad]
  - input  "flight_conditions"  [9]  sensed rho, Mach, q, heat flux, loads, L, D, E
  - input  "bank_command"       [1]  the signed bank command [rad] (its sign is held in the predictions)
  - output "bank_magnitude"     [1]  |sigma| [rad]
  - output "alpha_command"      [1]  alpha [rad]
  - output "sigma0"             [1]  the sigma_0 in use [rad]
  - output "range_error"        [1]  the last corrector's predicted range error z [m] (nan before)
  - output "stats"              [6]  engaged (0/1), engagement time [s], corrections, predictions,
                                   corrections not converged, wall time correcting [s]
  - output "replan_stats"       [4]  the schedule's account (systems/replan_scheduler.py)
"""
from __future__ import annotations

import math

import numpy as np
from pydrake.systems.framework import BasicVector

from drake_entry.errors import ScenarioError
from drake_entry.guidance.fnpeg.onboard import FnpegSetup
from drake_entry.models.acceleration_ratios import filtered_ratios
from drake_entry.models.dynamics import FLIGHT_CONDITION_NAMES
from drake_entry.systems.lifetime import weak_element, weak_method
from drake_entry.systems.replan_scheduler import ReplanScheduler

__all__ = ["FnpegGuidance"]

_FC = {name: i for i, name in enumerate(FLIGHT_CONDITION_NAMES)}
(_ENGAGED, _T_ENGAGE, _PREDICTIONS, _SIGMA0, _SLOPE, _MAGNITUDE, _ALPHA, _Z, _KL, _KD) = range(10)


class FnpegGuidance(ReplanScheduler):
    def __init__(self, setup: FnpegSetup, *, sigma0_guess: float, bank_before: float, initial_alpha: float,
                 engage_acceleration: float, period: float = 1.0, replan_period: float = 1.0,
                 scaling: bool = True, latency_s: float = 0.0, latency_factor: float = 0.0):
        """Args: setup (the mission's predictor, corrector and law); sigma0_guess [rad] (the first
        corrector's start); bank_before [rad] (|sigma| before engagement); initial_alpha [rad] (the
        alpha command before the first sample); engage_acceleration [m/s^2]; period [s];
        replan_period [s] of the corrector (0: at engagement only); scaling: the
        predictions fly the nominal lift and drag times the low-passed ratios of the sensed to the
        modelled accelerations (models.acceleration_ratios), else the nominal models; latency_s [s],
        latency_factor: each correction's computing latency (systems/replan_scheduler.py)."""
        super().__init__()
        if not period > 0 or not (replan_period == 0 or replan_period >= period):
            raise ScenarioError(f"FnpegGuidance: period = {period} s must be > 0 and replan_period = "
                                f"{replan_period} s 0 or at least the period")
        self.setup, self.engage_acceleration = setup, engage_acceleration
        self.scaling, self.period = scaling, period
        self.est_port = self.DeclareVectorInputPort("estimated_state", 6)
        self.fc_port = self.DeclareVectorInputPort("flight_conditions", len(FLIGHT_CONDITION_NAMES))
        self.bank_port = self.DeclareVectorInputPort("bank_command", 1)
        start = np.zeros(10)
        start[[_KL, _KD]] = 1.0
        start[[_T_ENGAGE, _SLOPE, _Z]] = math.nan
        start[_SIGMA0], start[_MAGNITUDE] = sigma0_guess, bank_before
        start[_ALPHA] = initial_alpha
        self._state = self.DeclareDiscreteState(BasicVector(start))
        self.DeclareReplanSchedule(replan_period_s=replan_period, latency_s=latency_s,  # the first: at engagement
                                   latency_factor=latency_factor, pending_size=3)
        self.DeclarePeriodicDiscreteUpdateEvent(period, 0.0, weak_method(self._update))
        deps = {self.xd_ticket()}
        for name, index in (("bank_magnitude", _MAGNITUDE), ("alpha_command", _ALPHA), ("sigma0", _SIGMA0),
                            ("range_error", _Z)):
            self.DeclareVectorOutputPort(name, 1, weak_element(self._memory, index),
                                         prerequisites_of_calc=deps)
        self.DeclareVectorOutputPort("stats", 6, weak_method(self._stats), prerequisites_of_calc=deps)

    def _stats(self, context, output):
        m, s = self._memory(context), self.replan_stats(context)
        output.SetFromVector([m[_ENGAGED], m[_T_ENGAGE], s.attempts, m[_PREDICTIONS], s.flawed, s.wall_s])

    def _memory(self, context) -> np.ndarray:
        return context.get_discrete_state(self._state).get_value()

    def _update(self, context, discrete_state):
        m = self._memory(context).copy()
        s = self.setup
        t = context.get_time()
        x = np.asarray(self.est_port.Eval(context), float)
        fc = self.fc_port.Eval(context)
        L, D = float(fc[_FC["lift"]]), float(fc[_FC["drag"]])
        if self.scaling:
            m[_KL], m[_KD] = filtered_ratios((m[_KL], m[_KD]), x, float(m[_ALPHA]), L, D, s.vehicle, s.planet,
                                             s.atmosphere, self.period)
        held = self.take_held(context, discrete_state)
        if held is not None:  # a correction computed one latency ago flies from now
            m[_SIGMA0], m[_SLOPE], m[_Z] = held
        if not m[_ENGAGED] and math.hypot(L, D) >= self.engage_acceleration:
            m[_ENGAGED], m[_T_ENGAGE] = 1.0, t
            self.due_now(discrete_state, t)
            due = True
        else:
            due = self.replan_due(context)
        if m[_ENGAGED]:
            if due and x[3] > s.hold_speed:
                self._correct(context, discrete_state, x, m)
            m[_MAGNITUDE] = s.bank_magnitude(x, float(m[_SIGMA0]), L, D, float(fc[_FC["heat_flux"]]),
                                             float(fc[_FC["dynamic_pressure"]]))
        m[_ALPHA] = s.alpha_command(x[3])
        discrete_state.get_mutable_vector(self._state).SetFromVector(m)

    def _correct(self, context, discrete_state, x, m):
        sign = 1.0 if float(self.bank_port.Eval(context)[0]) >= 0 else -1.0
        slope = None if not math.isfinite(m[_SLOPE]) else float(m[_SLOPE])
        n0 = self.setup.predictor.predictions

        def solve():
            c = self.setup.correct(x, float(m[_SIGMA0]), sign, slope, (float(m[_KL]), float(m[_KD])))
            finite = math.isfinite(c.z)
            return c, finite, "" if finite and c.converged else "not converged"

        outcome = self.attempt(context, discrete_state, solve, encode=lambda c: [c.sigma0, c.slope, c.z])
        m[_PREDICTIONS] += self.setup.predictor.predictions - n0
        if outcome.apply_now:
            c = outcome.result
            m[_SIGMA0], m[_SLOPE], m[_Z] = c.sigma0, c.slope, c.z
