"""FNPEG's predictor (Lu 2014 Sec. III): the full 3-DOF equations over the rotating spherical
Earth with the range integrated, ds/dt = V cos(gamma) R0 / r, flown with the baseline bank
profile and its altitude-rate feedback (guidance/fnpeg/law.py) from the current state until
the terminal energy e_f.

The equations are built once from the same model code as the plant (drake_entry.models:
dynamics, atmosphere, aerodynamics, heat flux) called with symbolic scalars, as Drake
``SymbolicVectorSystem``s that Drake integrates in C++ (fixed ``step_s`` Runge-Kutta 3 steps: a
fixed grid keeps the corrector's finite differences free of step-size noise). The prediction's
inputs (sigma_0, e_0, the sign, k_L, k_D) are held as constant states of the motion system.

Drake evaluates an expression tree without reusing its shared parts, and the bank law holds L,
D and the air data several times over. Where that repetition is large, the prediction runs in
two stages, an algebraic "aerodynamics" system (k_L L, k_D D, rho) feeding the "motion" system,
so each is evaluated once per derivative; otherwise in one system, as a second system costs
its own evaluation. ``STAGED_SIZE_RATIO`` decides, on the trees' expanded sizes. Measured per
prediction: CAV-H (Mach tables, US76; expanded 3.6 times larger in one system) 39-47 -> 27 ms
staged; Lu 2008's capsule (1.7 times) 8.0 ms in one system against 9.6-10.2 staged. Both forms
end at the same state to 3e-14 (relative).

Time, not energy, is the independent variable: a high-lift glider's phugoid climbs where drag,
and so de/dt, nearly vanishes (the pitfall of energy-domain prediction). The prediction stops
exactly at e_f (Newton on time from the last step, de/dt from the equations), below
``floor_m``, above ``ceiling_m`` or at ``max_time_s``.
"""
from __future__ import annotations

import dataclasses as dc
import math

import numpy as np
from pydrake.symbolic import Expression, Variable
from pydrake.systems.analysis import ResetIntegratorFromFlags, Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import SymbolicVectorSystem

from drake_entry.errors import ScenarioError
from drake_entry.guidance.fnpeg import predicted_flight
from drake_entry.guidance.fnpeg.law import FeedbackSettings, commanded_bank
from drake_entry.models import dynamics
from drake_entry.models.atmosphere import piecewise
from drake_entry.models.kernels import Kernel, compile_kernels
from drake_entry.models.schedules import Schedule, linear_bank
from drake_entry.models.symbolic_system import stateless

__all__ = ["STAGED_SIZE_RATIO", "ENGINES", "Prediction", "alpha_expression", "Predictor"]

_STATE = [Variable(n) for n in ("h", "lon", "lat", "V", "gamma", "psi", "s")]
#: the inputs held through a prediction; sigma_f and e_f among them, so the kernels of one vehicle,
#: alpha profile and law serve every end bank and terminal energy (a derivation's search) unrecompiled
_INPUT = [Variable(n) for n in ("sigma0", "e0", "sign", "lift_scale", "drag_scale", "sigma_f", "e_f")]
#: the aerodynamic stage's outputs (scaled lift and drag accelerations [m/s^2], density [kg/m^3])
_AERO = [Variable(n) for n in ("L", "D", "rho")]
#: two stages when one system's expanded expressions are at least this many times the stages'
STAGED_SIZE_RATIO = 2.0
#: how a prediction is computed: "compiled" (the default: the whole flight in one compiled call of
#: kernels generated from the same expressions, models.kernels) or "drake" (Drake's Simulator
#: integrating the SymbolicVectorSystems: the reference the compiled flight is tested against)
ENGINES = ("compiled", "drake")
#: prediction steps advanced per Simulator call (the energy is checked between calls)
_STEPS_PER_CALL = 10


@dc.dataclass(frozen=True)
class Prediction:
    """One predicted trajectory.

    Attributes:
      range_m: ground range flown [m] (at the reference radius) until the stop: nan when the
        stop says nothing about the range at e_f (skip-out, time-out); below the floor it is the
        range to the impact (short, whatever the rest).
      state: [h, lon, lat, V, gamma, psi] at the stop. time_s: flight time to the stop [s].
      reached: the stop is the terminal energy e_f; otherwise ``reason`` says which stop.
    """

    range_m: float
    state: np.ndarray
    time_s: float
    reached: bool
    reason: str = ""


def alpha_expression(alpha: Schedule, V):
    """The angle-of-attack profile alpha(V) [rad] (a 'velocity' Schedule, linear between its
    breakpoints, held outside) as a symbolic expression of V."""
    if alpha.variable != "velocity":
        raise ScenarioError(f"FNPEG's predictor flies an alpha profile in velocity, got variable '{alpha.variable}'")
    bp, v = alpha.breakpoints, alpha.values
    if len(bp) == 1:
        return Expression(float(v[0]))
    edges = [-math.inf, *bp, math.inf]

    def piece(i):
        if i == 0:
            return Expression(float(v[0]))
        if i == len(bp):
            return Expression(float(v[-1]))
        return v[i - 1] + (V - bp[i - 1]) * ((v[i] - v[i - 1]) / (bp[i] - bp[i - 1]))

    return piecewise(V, edges, piece)


class Predictor:
    """Predicts FNPEG trajectories of one vehicle (module docstring).

    Args: vehicle, planet, atmosphere (the on-board models); law: the feedback settings;
    sigma_f [rad]: the profile's terminal bank; e_f [J/kg]: the terminal energy (mu/r - V^2/2);
    constant: fly |sigma| = sigma_0 to e_f (Lu 2008's constant-bank profile) instead of the
    linear profile to sigma_f;
    alpha: the angle-of-attack profile (Schedule in velocity); step_s: the fixed integration step
    [s]; floor_m, ceiling_m: altitudes that end a prediction; max_time_s: the longest prediction.
    Attribute ``staged``: whether the aerodynamics run as a stage of their own (module docstring).
    """

    def __init__(self, vehicle, planet, atmosphere, law: FeedbackSettings, *, sigma_f: float, e_f: float,
                 alpha: Schedule, step_s: float = 2.0, floor_m: float = 0.0, ceiling_m: float = 200e3,
                 max_time_s: float = 10000.0, constant: bool = False, engine: str = "compiled"):
        if not step_s > 0:
            raise ScenarioError(f"FNPEG predictor step_s = {step_s}; allowed > 0 s")
        if engine not in ENGINES:
            raise ScenarioError(f"FNPEG predictor engine = {engine!r}; allowed: {', '.join(ENGINES)}")
        self.planet, self.mu, self.e_f, self.sigma_f, self.engine = planet, planet.mu, e_f, sigma_f, engine
        self.step_s, self.floor_m, self.ceiling_m, self.max_time_s = step_s, floor_m, ceiling_m, max_time_s
        aero, motion = _equations(vehicle, planet, atmosphere, law, alpha, constant)
        one = [f.Substitute(dict(zip(_AERO, aero))) for f in motion]
        self.staged = _size(one) >= STAGED_SIZE_RATIO * (_size(aero) + _size(motion))
        self.evaluations = 0
        self.predictions = 0
        if engine == "compiled":
            e = self.energy([Expression(v) for v in _STATE])
            rate = e.Differentiate(_STATE[0]) * one[0] + e.Differentiate(_STATE[3]) * one[3]
            variables = (*_STATE, *_INPUT)
            self.kernels = compile_kernels([Kernel("rhs", tuple(one), variables),
                                            Kernel("energy", (e,), variables),
                                            Kernel("energy_rate", (e, rate), variables)],
                                           predicted_flight, tag="fnpeg_prediction")
            return
        self.system, self._motion = _build(aero, motion) if self.staged else _build(None, one)
        self.simulator = Simulator(self.system)
        integrator = ResetIntegratorFromFlags(self.simulator, "runge_kutta3", step_s)
        integrator.set_fixed_step_mode(True)
        integrator.set_maximum_step_size(step_s)
        self.context = self.simulator.get_mutable_context()
        self._motion_context = self._motion.GetMyMutableContextFromRoot(self.context)

    def energy(self, x) -> float:
        """e = mu/r - V^2/2 [J/kg] of a state."""
        return self.mu / self.planet.radius(x[0]) - 0.5 * x[3] * x[3]

    def _state(self) -> np.ndarray:
        return self._motion_context.get_continuous_state_vector().CopyToVector()

    def _set_state(self, y) -> None:
        self._motion_context.SetContinuousState(y)

    def derivatives(self, y, params) -> np.ndarray:
        """d/dt of the 7 states [h, lon, lat, V, gamma, psi, s] (SI) at ``y`` with the inputs
        ``params`` = [sigma_0 rad, e_0 J/kg, sign, k_L, k_D] (sigma_f and e_f the predictor's), by
        the predictor's engine."""
        v = np.array([*map(float, y), *map(float, params), self.sigma_f, self.e_f])
        if self.engine == "compiled":
            out = np.empty(len(_STATE))
            self.kernels["rhs"](v, out)
            return out
        self._set_state(v)
        return self._xdot()

    def _xdot(self) -> np.ndarray:
        return self._motion.EvalTimeDerivatives(self._motion_context).CopyToVector()[:len(_STATE)]

    def predict(self, x, sigma0: float, sign: float = 1.0, scales=(1.0, 1.0)) -> Prediction:
        """Fly the profile from sigma0 [rad] at state ``x`` [6] (its energy is e_0) with the bank
        sign ``sign`` held and the modelled lift and drag times ``scales`` (k_L, k_D: what the
        flight has shown, models.acceleration_ratios), until e_f or another stop (class docstring)."""
        x = np.asarray(x, float)
        self.predictions += 1
        if self.engine == "compiled":
            return self._predict_compiled(x, sigma0, sign, scales)
        ctx = self.context
        ctx.SetTime(0.0)
        self._set_state(self._start(x, sigma0, sign, scales))
        integrator = self.simulator.get_mutable_integrator()
        n0 = integrator.get_num_derivative_evaluations()
        self.simulator.Initialize()
        try:
            return self._fly()
        except ValueError as err:  # a NaN reaching a sqrt or log inside the native evaluation
            return Prediction(math.nan, self._state()[:6], ctx.get_time(), False,
                              f"the prediction left the models' domain ({str(err).splitlines()[0]})")
        finally:
            self.evaluations += integrator.get_num_derivative_evaluations() - n0

    def _predict_compiled(self, x, sigma0, sign, scales) -> Prediction:
        v0 = self._start(x, sigma0, sign, scales)
        code, t, v, evaluations = self.kernels["predict_flight"](
            v0, self.step_s, self.e_f, self.floor_m, self.ceiling_m, self.max_time_s, _STEPS_PER_CALL)
        self.evaluations += evaluations
        if code == predicted_flight.REACHED:
            return Prediction(v[6], v[:6].copy(), t, True)
        if code == predicted_flight.NOT_FINITE:
            return Prediction(math.nan, v[:6].copy(), t, False,
                              "the prediction left the models' domain (a state became NaN or infinite)")
        flown = v[6] if code == predicted_flight.FLOOR else math.nan
        return Prediction(flown, v[:6].copy(), t, False, self._stop(v, t))

    def _start(self, x, sigma0, sign, scales) -> np.ndarray:
        """The states and inputs (_STATE, _INPUT) a prediction from ``x`` starts with."""
        return np.array([*x, 0.0, float(sigma0), self.energy(x), 1.0 if sign >= 0 else -1.0, *map(float, scales),
                         self.sigma_f, self.e_f])

    def _fly(self) -> Prediction:
        ctx, sim, e_f = self.context, self.simulator, self.e_f
        chunk = _STEPS_PER_CALL * self.step_s
        while True:
            t0, before = ctx.get_time(), self._state()
            sim.AdvanceTo(t0 + chunk)
            y = self._state()
            if self.energy(y) >= e_f:
                return self._finish(t0, before)
            stop = self._stop(y, ctx.get_time())
            if stop:
                flown = y[6] if y[0] < self.floor_m else math.nan
                return Prediction(flown, y[:6], ctx.get_time(), False, stop)

    def _stop(self, y, t) -> str:
        if y[0] < self.floor_m:
            return f"below {self.floor_m / 1e3:.0f} km before the terminal energy"
        if y[0] > self.ceiling_m:
            return f"above {self.ceiling_m / 1e3:.0f} km (skip-out)"
        if t >= self.max_time_s:
            return f"the terminal energy is not reached in {self.max_time_s:.0f} s"
        return ""

    def _finish(self, t0: float, before) -> Prediction:
        """Step again from ``before`` (at t0) one step at a time to the step that crosses e_f,
        then Newton on time to e_f."""
        ctx, sim = self.context, self.simulator
        ctx.SetTime(t0)
        self._set_state(before)
        sim.Initialize()
        while True:
            t, y = ctx.get_time(), self._state()
            sim.AdvanceTo(t + self.step_s)
            if self.energy(self._state()) >= self.e_f:
                break
        ctx.SetTime(t)
        self._set_state(y)
        sim.Initialize()
        for _ in range(3):
            y = self._state()
            xdot = self._xdot()
            r = self.planet.radius(y[0])
            edot = -self.mu * xdot[0] / (r * r) - y[3] * xdot[3]
            dt = (self.e_f - self.energy(y)) / edot
            if not edot > 0 or not dt > 1e-6:
                break
            sim.AdvanceTo(ctx.get_time() + dt)
        y = self._state()
        return Prediction(y[6], y[:6], ctx.get_time(), True)


def _equations(vehicle, planet, atmosphere, law, alpha, constant):
    """(aerodynamics, motion): [k_L L, k_D D, rho] of the 7 states and 7 inputs, and the 7
    derivatives of the states reading those three as the Variables _AERO (module docstring)."""
    x = [Expression(v) for v in _STATE[:6]]
    sigma0, e0, sign, k_lift, k_drag, sigma_f, e_f = (Expression(u) for u in _INPUT)
    L, D, rho = (Expression(v) for v in _AERO)  # the aerodynamic stage's outputs
    h, V, gamma = x[0], x[3], x[4]
    r = planet.radius(h)
    with np.errstate(all="ignore"):  # numpy's object loops report stray FP flags as warnings
        a = alpha_expression(alpha, V)
        air = dynamics.air_data(x, planet, atmosphere)
        _, lift, drag = dynamics.aero_accelerations(x, a, *air, vehicle)
        aero = [k_lift * lift, k_drag * drag, air[0]]
        e = planet.mu / r - 0.5 * V * V
        base = sigma0 if constant else linear_bank(e, e0, e_f, sigma0, sigma_f)
        load = np.sqrt(L * L + D * D)
        q = dynamics.dynamic_pressure(rho, V)
        heat = vehicle.heat_flux(rho, V, a)
        bank = sign * commanded_bank(base, V, gamma, L, D, load, heat, q, law)
        xdot = dynamics.equations_of_motion(x, bank, L, D, planet)
        sdot = V * np.cos(gamma) * planet.reference_radius / r
    return aero, [*xdot, sdot]


def _size(expressions) -> int:
    """The expanded size of expression trees (characters of their text: what an evaluation
    walks, shared parts counted each time they occur)."""
    return sum(len(str(f)) for f in expressions)


def _build(aerodynamics, motion: list):
    """(Diagram, its motion system): the motion system integrates the 7 states and holds the 7
    inputs (_INPUT) as constant states; with ``aerodynamics`` ([k_L L, k_D D, rho] of those 14)
    an algebraic system computes them for it (``motion`` then reads _AERO), else ``motion``
    holds them itself."""
    held = [*_STATE, *_INPUT]
    builder = DiagramBuilder()
    body = builder.AddNamedSystem("motion", SymbolicVectorSystem(
        state=held, input=_AERO if aerodynamics else [], dynamics=[*motion, *[Expression(0.0)] * len(_INPUT)],
        output=[Expression(v) for v in held]))
    if aerodynamics:
        aero = builder.AddNamedSystem("aerodynamics", stateless(held, aerodynamics))
        builder.Connect(body.get_output_port(), aero.get_input_port())
        builder.Connect(aero.get_output_port(), body.get_input_port())
    return builder.Build(), body
