"""Time-varying LQR tracking of an optimal-control reference (the feedback controller paper
003 adds to both AMPI and NTT without giving it: Sec. VI, "a common tracking controller").

About a reference x_ref(t), u_ref(t) of an ``OptimalControlProblem`` the dynamics are
linearised, dx' = A(t) dx + B(t) du (A = df/dx, B = df/du by automatic differentiation of
the problem's own dynamics at ``samples`` times), and Drake's
``FiniteHorizonLinearQuadraticRegulator`` solves the Riccati equation of

    min  dx(t_f)' Q_f dx(t_f) + int_0^t_f (dx' Q dx + du' R du) dt

backwards on a ``TrajectoryLinearSystem`` (the linearisation as first-order-hold matrix
trajectories, integrated in C++: 0.3-1 s for a 600 s SHEFEX-3 reference, against 4-18 s
for the same solve linearising the Python plant at every Riccati step). The law is

    u(t) = u_ref(t) - K(t) (x(t) - x_ref(t)),   K = R^-1 B' S.

The weights are given per unit of a state scale (``TrackingWeights``): a deviation of one
scale unit costs 1 per second (Q = I in scaled units) times ``state_weight``.
"""
from __future__ import annotations

import dataclasses as dc
import math
import time

import numpy as np
from pydrake.autodiffutils import ExtractGradient, InitializeAutoDiff
from pydrake.systems.analysis import SimulatorConfig
from pydrake.systems.controllers import (
    FiniteHorizonLinearQuadraticRegulator,
    FiniteHorizonLinearQuadraticRegulatorOptions,
)
from pydrake.systems.primitives import TrajectoryLinearSystem
from pydrake.trajectories import PiecewisePolynomial

from drake_entry.errors import ScenarioError

__all__ = ["RICCATI_ACCURACY", "RICCATI_MAX_STEP_S", "TrackingWeights", "TrackingLaw", "CommandFeedback", "lerp",
           "resample", "scaled_linearisation", "linearise", "tvlqr"]

#: Riccati integration (Drake's RK3 with error control): 1e-3 changes K by < 1e-3 of its
#: largest entry against 1e-4 on the SHEFEX-3 nominal, at 60 % of the cost
RICCATI_ACCURACY = 1.0e-3
RICCATI_MAX_STEP_S = 20.0


@dc.dataclass(frozen=True)
class TrackingWeights:
    """LQR weights in scaled units.

    Attributes:
      state_scale: {state name: the deviation that costs 1 [SI / rad]}; states not named
        cost nothing (e.g. the clock).
      control_scale: {control name: the control deviation that costs 1 [SI / rad]}.
      state_weight: Q = state_weight * I on the scaled states [1/s].
      terminal_scale: {state name: the final deviation that costs 1} (Q_f; empty: no
        terminal cost).
    """

    state_scale: dict
    control_scale: dict
    state_weight: float = 1.0e-5
    terminal_scale: dict = dc.field(default_factory=dict)

    @staticmethod
    def entry() -> "TrackingWeights":
        """Defaults for an entry reference with the bank as a state and its rate the control
        (controls 'bank_rate'): 1 km, 0.1 deg, 10 m/s, 1 deg, 1 deg/s; the final position
        weighted by 0.01 deg (1.1 km), the path by state_weight 1e-5: the terminal weight
        steers, the path weight only damps (on SHEFEX-3, 1e-3 pulls back to a reference the
        dispersed entry cannot follow: 5 km miss where 1e-5 gives 1.3 km). (guidance !Ampi's
        defaults are these.)"""
        d = math.radians
        return TrackingWeights(
            state_scale={"h": 1.0e3, "lon": d(0.1), "lat": d(0.1), "V": 10.0, "gamma": d(0.1), "psi": d(0.1),
                         "sigma": d(1.0)},
            control_scale={"u_sigma": d(1.0)},
            terminal_scale={"lon": d(0.01), "lat": d(0.01), "h": 1.0e3, "V": 10.0})

    @staticmethod
    def entry_commands(state_weight: float) -> "TrackingWeights":
        """Weights for feedback on the bank and alpha commands of an entry plan (bank and alpha
        states, their rates 'u_sigma', 'u_alpha' the controls; planning.ocp's 'rates' layout): a
        deviation of 1 km, 0.1 deg of position or path angles, 10 m/s, 1 deg of alpha or bank
        costs 1 per second times ``state_weight``; 1 deg/s of alpha or bank rate costs 1; the
        final position weighted by 0.01 deg (1.1 km), the final speed by 10 m/s and the final
        flight-path angle by 1 deg (the re-solving guidances' feedback between re-plans)."""
        d = math.radians
        return TrackingWeights(
            state_scale={"h": 1.0e3, "lon": d(0.1), "lat": d(0.1), "V": 10.0, "gamma": d(0.1), "psi": d(0.1),
                         "alpha": d(1.0), "sigma": d(1.0)},
            control_scale={"u_alpha": d(1.0), "u_sigma": d(1.0)}, state_weight=state_weight,
            terminal_scale={"lon": d(0.01), "lat": d(0.01), "V": 10.0, "gamma": d(1.0)})

    def matrices(self, state_names, control_names) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(sx, su, Q, R, Qf) for the layout: scales (unnamed states scale 1 and cost 0)."""
        for where, names, given in (("state_scale", state_names, self.state_scale),
                                    ("terminal_scale", state_names, self.terminal_scale),
                                    ("control_scale", control_names, self.control_scale)):
            for k, v in given.items():
                if k not in names:
                    raise ScenarioError(f"TrackingWeights.{where}: unknown name '{k}'; allowed {', '.join(names)}")
                if not (v > 0 and math.isfinite(v)):
                    raise ScenarioError(f"TrackingWeights.{where}['{k}'] = {v}: must be > 0")
        for k in control_names:
            if k not in self.control_scale:
                raise ScenarioError(f"TrackingWeights.control_scale needs every control; missing '{k}'")
        if not self.state_weight > 0:
            raise ScenarioError(f"TrackingWeights.state_weight = {self.state_weight}: must be > 0")
        sx = np.array([self.state_scale.get(n, 1.0) for n in state_names])
        su = np.array([self.control_scale[n] for n in control_names])
        q = np.array([self.state_weight if n in self.state_scale else 0.0 for n in state_names])
        qf = np.array([(self.state_scale.get(n, 1.0) / self.terminal_scale[n]) ** 2 if n in self.terminal_scale
                       else 0.0 for n in state_names])
        return sx, su, np.diag(q), np.eye(len(control_names)), np.diag(qf)


@dc.dataclass(frozen=True)
class TrackingLaw:
    """u = u_ref(t) - K(t) (x - x_ref(t)), everything linear in t between the samples and
    held after the last one.

    Attributes:
      time [s] (n,); states (n, n_x), controls (n, n_u): the reference (SI);
      gain_time [s] (m,), gains (m, n_u, n_x): K in SI; wall_s: time to compute K [s].
    """

    time: np.ndarray
    states: np.ndarray
    controls: np.ndarray
    gain_time: np.ndarray
    gains: np.ndarray
    wall_s: float = 0.0

    def reference(self, t: float) -> tuple[np.ndarray, np.ndarray]:
        """(x_ref(t), u_ref(t))."""
        return self.state(t), lerp(self.time, self.controls, t)

    def state(self, t: float) -> np.ndarray:
        """x_ref(t) alone (what a tracker reads every period)."""
        return lerp(self.time, self.states, t)

    def gain(self, t: float) -> np.ndarray:
        return lerp(self.gain_time, self.gains, t)

    def command(self, t: float, x) -> np.ndarray:
        """u(t, x) [SI] (before any limits)."""
        xr, ur = self.reference(t)
        return ur - self.gain(t) @ (np.asarray(x, float) - xr)


@dc.dataclass(frozen=True)
class CommandFeedback:
    """A TrackingLaw used as feedback on commands that follow a reference in time: the
    navigation estimate gives the law's first six states (the entry states), the commanded
    states (e.g. alpha and sigma of the 'rates' layout) are the reference's plus the offsets the
    feedback has built up, and the law's rate controls change those offsets.

    Attributes:
      law: the TrackingLaw (its clock: 0 where the reference begins);
      commanded: for each offset, (index of its state, index of its rate control) in the law.
    """

    law: TrackingLaw
    commanded: tuple

    def rates(self, s: float, estimate, offsets) -> np.ndarray:
        """d(offsets)/dt [SI/s] at ``s`` [s of the reference], the estimate [6] and the offsets."""
        x_ref = self.law.state(s)
        x = x_ref.copy()
        x[:6] = np.asarray(estimate, float)[:6]
        for (i, _), d in zip(self.commanded, offsets):
            x[i] += d
        du = -self.law.gain(s) @ (x - x_ref)
        return np.array([du[j] for _, j in self.commanded])


def lerp(times: np.ndarray, values: np.ndarray, t: float) -> np.ndarray:
    """values linearly interpolated at t (held outside [times[0], times[-1]]).

    Clamped with min/max on Python numbers: np.clip on a scalar cost about 6 us a call, which made
    this a tenth of a closed-loop AMPI flight."""
    k = min(max(int(np.searchsorted(times, t, side="right")) - 1, 0), times.size - 2)
    w = float(min(max((t - times[k]) / (times[k + 1] - times[k]), 0.0), 1.0))
    return (1.0 - w) * values[k] + w * values[k + 1]


def resample(ts, time_s, values) -> np.ndarray:
    """values (n, m) given at time_s (n,) linearly interpolated at ts [s] -> (len(ts), m)."""
    return np.array([np.interp(ts, time_s, c) for c in np.asarray(values, float).T]).T


def scaled_linearisation(problem, ts, states, controls, sx, su) -> tuple[np.ndarray, np.ndarray]:
    """(A_s, B_s): ``linearise`` at the samples, in the scaled variables x / sx, u / su:
    d(x/sx)/dt = A_s (x/sx) + B_s (u/su)."""
    A, B = linearise(problem, ts, states, controls)
    return A * sx[None, None, :] / sx[None, :, None], B * su[None, None, :] / sx[None, :, None]


def linearise(problem, time_s, states, controls) -> tuple[np.ndarray, np.ndarray]:
    """(A (n, n_x, n_x), B (n, n_x, n_u)): df/dx and df/du of ``problem.dynamics`` at the
    given reference samples [SI] (automatic differentiation)."""
    nx = states.shape[1]
    A, B = [], []
    for x, u in zip(states, controls):
        z = InitializeAutoDiff(np.concatenate([x, u]))[:, 0]
        J = ExtractGradient(np.asarray(problem.dynamics(z[:nx], z[nx:])))
        A.append(J[:, :nx])
        B.append(J[:, nx:])
    return np.array(A), np.array(B)


def tvlqr(problem, time_s, states, controls, weights: TrackingWeights, samples: int = 120) -> TrackingLaw:
    """The time-varying LQR about a reference of ``problem`` (module docstring).

    Args: time_s (n,) increasing from the reference's start [s]; states (n, n_x) and
    controls (n, n_u) in the problem's layout [SI]; weights; samples: equally spaced times
    the dynamics are linearised at (the Riccati equation sees them first-order held).
    """
    t0 = time.perf_counter()
    time_s, states, controls = (np.asarray(a, float) for a in (time_s, states, controls))
    if time_s.ndim != 1 or time_s.size < 2 or np.any(np.diff(time_s) <= 0):
        raise ScenarioError("tvlqr: time_s must be increasing with at least two samples")
    if states.shape != (time_s.size, problem.n_states) or controls.shape != (time_s.size, problem.n_controls):
        raise ScenarioError(f"tvlqr: states {states.shape} and controls {controls.shape} must be "
                            f"({time_s.size}, {problem.n_states}) and ({time_s.size}, {problem.n_controls})")
    if samples < 2:
        raise ScenarioError(f"tvlqr: samples = {samples}; allowed >= 2")
    sx, su, Q, R, Qf = weights.matrices(problem.state_names, problem.control_names)
    ts = np.linspace(time_s[0], time_s[-1], samples)
    A_s, B_s = scaled_linearisation(problem, ts, resample(ts, time_s, states), resample(ts, time_s, controls), sx, su)
    nx, nu = problem.n_states, problem.n_controls
    system = TrajectoryLinearSystem(PiecewisePolynomial.FirstOrderHold(ts, list(A_s)),
                                    PiecewisePolynomial.FirstOrderHold(ts, list(B_s)),
                                    PiecewisePolynomial(np.eye(nx)), PiecewisePolynomial(np.zeros((nx, nu))))
    context = system.CreateDefaultContext()
    system.get_input_port().FixValue(context, np.zeros(nu))
    options = FiniteHorizonLinearQuadraticRegulatorOptions()
    options.Qf = Qf
    options.simulator_config = SimulatorConfig(integration_scheme="runge_kutta3", max_step_size=RICCATI_MAX_STEP_S,
                                               accuracy=RICCATI_ACCURACY, use_error_control=True)
    result = FiniteHorizonLinearQuadraticRegulator(system, context, float(ts[0]), float(ts[-1]), Q, R, options)
    K_s = np.array([result.K.value(t) for t in ts])  # scaled -> SI: du = su K_s dx / sx
    gains = K_s * su[None, :, None] / sx[None, None, :]
    return TrackingLaw(time_s, states, controls, ts, gains, time.perf_counter() - t0)
