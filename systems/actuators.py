"""Second-order actuators with position, rate and acceleration limits: BankActuator and
AlphaActuator (one LeafSystem, ``LimitedActuator``, named per use).

The law is drake_entry.models.actuator.actuator_rates: the command is clipped to [lower, upper]
and tracked with rate and acceleration limits, so a bank reversal (a sign flip of the
command) rotates through wings-level at the rate limit. Two realisations:

  continuous  (period=None) the actuator state [x, x_dot] is continuous state.
              Its inner loop (4 x bandwidth rad/s) bounds the step of explicit integrators.
  sampled     (period=T) the command is sampled every T seconds; the same law is integrated
              over the coming period in ``substep`` steps (RK2) and the output is the C1
              Hermite interpolant of (x, x_dot) in time. No continuous state, so the vehicle
              integrator takes steps as long as the flight allows, and the limits act inside
              the guidance period (a limiter updated once per period would limit-cycle).

Ports (``name`` = "bank" or "alpha"):
  - input  "<name>_command"  [1]  command [rad]
  - output "<name>"          [1]  actuator position [rad] (no direct feedthrough)
  - output "<name>_rate"     [1]  its rate [rad/s]
"""
from __future__ import annotations

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.systems.framework import BasicVector, LeafSystem
from pydrake.trajectories import PiecewisePolynomial

from drake_entry.errors import ScenarioError
from drake_entry.models.actuator import BANDWIDTH_RAD_S, SUBSTEP_S, actuator_rates, integrate_actuator
from drake_entry.systems.lifetime import weak_element, weak_method

__all__ = ["LimitedActuator", "BankActuator", "AlphaActuator"]


class LimitedActuator(LeafSystem):
    def __init__(self, *, name: str, lower: float, upper: float, rate_limit: float, accel_limit: float,
                 bandwidth: float = BANDWIDTH_RAD_S, initial: float = 0.0, period: float | None = None,
                 substep: float = SUBSTEP_S):
        """Args: name of the ports; lower, upper [rad] position limits; rate_limit [rad/s];
        accel_limit [rad/s^2]; bandwidth omega [rad/s] of the position loop (the rate loop
        runs at 4 omega); initial position [rad]; period [s] for the sampled realisation
        (None = continuous); substep [s] (RK2 at 0.02 s follows a 120 deg HORUS reversal
        within 5e-4 deg of a 1e-3 s integration)."""
        super().__init__()
        for field, v in (("rate_limit", rate_limit), ("accel_limit", accel_limit), ("bandwidth", bandwidth)):
            if not v > 0:
                raise ScenarioError(f"{type(self).__name__}.{field} must be > 0, got {v}")
        if not lower < upper:
            raise ScenarioError(f"{type(self).__name__} needs lower < upper, got [{lower}, {upper}]")
        self.limits = dict(lower=lower, upper=upper, rate_limit=rate_limit, accel_limit=accel_limit,
                           bandwidth=bandwidth)
        self.cmd_port = self.DeclareVectorInputPort(f"{name}_command", 1)
        self.period, self.initial = period, float(initial)
        if period is None:
            self.DeclareContinuousState(BasicVector([initial, 0.0]))
            state = {self.all_state_ticket()}
            self.DeclareVectorOutputPort(name, 1, lambda c, o: o.SetAtIndex(0, c.get_continuous_state_vector()[0]),
                                         prerequisites_of_calc=state)
            self.DeclareVectorOutputPort(f"{name}_rate", 1,
                                         lambda c, o: o.SetAtIndex(0, c.get_continuous_state_vector()[1]),
                                         prerequisites_of_calc=state)
            return
        if not 0 < substep <= period:
            raise ScenarioError(f"{type(self).__name__}.substep must be in (0, period], got {substep}")
        self.n_sub = max(1, int(round(period / substep)))
        self._segment = self.DeclareAbstractState(AbstractValue.Make(_constant_segment(initial)))
        self.DeclarePeriodicUnrestrictedUpdateEvent(period, 0.0, weak_method(self._plan_segment))
        deps = {self.abstract_state_ticket(self._segment), self.time_ticket()}
        self.DeclareVectorOutputPort(name, 1, weak_element(self._sample, 0),
                                     prerequisites_of_calc=deps)
        self.DeclareVectorOutputPort(f"{name}_rate", 1, weak_element(self._sample, 1),
                                     prerequisites_of_calc=deps)

    def DoCalcTimeDerivatives(self, context, derivatives):
        if self.period is not None:  # sampled: no continuous state
            return
        x, rate = context.get_continuous_state_vector().CopyToVector()
        derivatives.get_mutable_vector().SetFromVector(actuator_rates(
            x, rate, self.cmd_port.Eval(context)[0], **self.limits))

    # -- sampled realisation -------------------------------------------------------------
    def _sample(self, context):
        return context.get_abstract_state(int(self._segment)).get_value().at(context.get_time())

    def response(self, command, t_end: float) -> PiecewisePolynomial:
        """The sampled realisation's output from t = 0 to ``t_end`` [s] when the command is known
        in advance (``command(t)`` [rad], e.g. a plan's spline): the segments ``_plan_segment``
        makes at every period, from the same law and start, joined into one C1 cubic Hermite
        PiecewisePolynomial (x [rad] and its rate). Flown by a TrajectorySource it is this
        actuator without a Python call per integrator stage (the plan verifier's open-loop
        flights); tests hold the two to each other."""
        if self.period is None:
            raise ScenarioError(f"{type(self).__name__}.response needs the sampled realisation (a period)")
        times, xs, rates = [0.0], [self.initial], [0.0]
        x, rate, k = self.initial, 0.0, 0
        while k * self.period < t_end:
            seg = self._next_segment(k * self.period, x, rate, command(k * self.period))
            times.extend(seg.t0 + seg.h * np.arange(1, self.n_sub + 1))
            xs.extend(seg.sigma[1:])
            rates.extend(seg.rate[1:])
            x, rate, k = seg.sigma[-1], seg.rate[-1], k + 1
        return PiecewisePolynomial.CubicHermite(np.array(times), np.array(xs)[None, :], np.array(rates)[None, :])

    def _next_segment(self, t0: float, x: float, rate: float, command: float) -> "_Segment":
        """The segment of the period starting at t0 [s] from position x [rad] and rate [rad/s]
        under ``command`` [rad]: the law integrated over n_sub sub-steps."""
        h = self.period / self.n_sub
        return _Segment(t0, h, *integrate_actuator(x, rate, float(command), h, self.n_sub, **self.limits))

    def _plan_segment(self, context, state):
        segment = self._next_segment(context.get_time(), *self._sample(context), self.cmd_port.Eval(context)[0])
        state.get_mutable_abstract_state(int(self._segment)).set_value(segment)


class BankActuator(LimitedActuator):
    """Bank actuator: |sigma| <= bank_limit, ports "bank_command" -> "bank", "bank_rate"."""

    def __init__(self, *, bank_limit: float, rate_limit: float, accel_limit: float,
                 bandwidth: float = BANDWIDTH_RAD_S, initial_bank: float = 0.0, period: float | None = None,
                 substep: float = SUBSTEP_S):
        """Args: bank_limit [rad] (> 0), the rest as LimitedActuator."""
        if not bank_limit > 0:
            raise ScenarioError(f"BankActuator.bank_limit must be > 0, got {bank_limit}")
        super().__init__(name="bank", lower=-bank_limit, upper=bank_limit, rate_limit=rate_limit,
                         accel_limit=accel_limit, bandwidth=bandwidth, initial=initial_bank, period=period,
                         substep=substep)


class AlphaActuator(LimitedActuator):
    """Angle-of-attack actuator: alpha in [alpha_min, alpha_max] with rate and acceleration
    limits (papers 001 and 004 command alpha), ports "alpha_command" -> "alpha", "alpha_rate"."""

    def __init__(self, *, alpha_min: float, alpha_max: float, rate_limit: float, accel_limit: float,
                 bandwidth: float = BANDWIDTH_RAD_S, initial_alpha: float = 0.0, period: float | None = None,
                 substep: float = SUBSTEP_S):
        """Args: alpha_min < alpha_max [rad], the rest as LimitedActuator."""
        super().__init__(name="alpha", lower=alpha_min, upper=alpha_max, rate_limit=rate_limit,
                         accel_limit=accel_limit, bandwidth=bandwidth, initial=initial_alpha, period=period,
                         substep=substep)


class _Segment:
    """(sigma, sigma_dot) samples from t0 every h seconds; C1 cubic Hermite between them,
    held after the last sample."""

    def __init__(self, t0: float, h: float, sigma: list, rate: list):
        self.t0, self.h, self.sigma, self.rate = t0, h, sigma, rate

    def at(self, t: float):
        n = len(self.sigma) - 1
        k = (t - self.t0) / self.h  # fractional sample index
        if n == 0 or k >= n:
            return self.sigma[-1], self.rate[-1]
        i = min(max(int(k), 0), n - 1)
        h = self.h
        u = k - i
        p0, p1 = self.sigma[i], self.sigma[i + 1]
        m0, m1 = self.rate[i] * h, self.rate[i + 1] * h
        u2, u3 = u * u, u * u * u
        val = (2 * u3 - 3 * u2 + 1) * p0 + (u3 - 2 * u2 + u) * m0 + (-2 * u3 + 3 * u2) * p1 + (u3 - u2) * m1
        der = ((6 * u2 - 6 * u) * p0 + (3 * u2 - 4 * u + 1) * m0 + (-6 * u2 + 6 * u) * p1 + (3 * u2 - 2 * u) * m1) / h
        return val, der

    def __deepcopy__(self, memo):
        return self  # immutable once built


def _constant_segment(sigma: float) -> _Segment:
    return _Segment(0.0, 1.0, [sigma], [0.0])
