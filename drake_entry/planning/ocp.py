"""Entry optimal-control problems: the description the NLP path (planning/nlp.py) solves.

A problem holds the models (vehicle, planet, atmosphere), the state and control layout,
boundary conditions, bounds, path constraints and an objective of Mayer and Lagrange
terms (paper 002 eqs. 1-11). Everything is SI and radians; users build it in Python or
read it from YAML (``load_problem``, fields with units in their names). Model functions
and user callables are evaluated with floats and with Drake AutoDiffXd.

State order: [h, lon, lat, V, gamma, psi] (the canonical order, docs/architecture.md), then, with
``controls='rates'``, [alpha, sigma] driven by the controls [u_alpha, u_sigma]
(paper 002 eq. 6); with ``controls='direct'`` the controls are [alpha, sigma]; with
``controls='bank_rate'`` alpha follows ``alpha_schedule`` in time (paper 003 Table 2) and
the states end with [sigma, t] (sigma' = u_sigma, the control, paper 003 eq. 2; t' = 1, a
clock that starts at initial['t'], default 0 s).
"""
from __future__ import annotations

import dataclasses as dc
import functools
import math
from typing import Callable

import numpy as np

from drake_entry.errors import ScenarioError
from drake_entry.models.atmosphere import Atmosphere
from drake_entry.models.dynamics import (
    STATE_NAMES,
    FlightConditions,
    air_data,
    flight_conditions,
    specific_energy,
    state_derivatives,
)
from drake_entry.models.geodesy import central_angle_smooth, crossrange_from_great_circle
from drake_entry.models.planet import Earth
from drake_entry.models.schedules import Schedule
from drake_entry.models.vehicles import Vehicle

__all__ = ["PATH_QUANTITIES", "LAGRANGE_KINDS", "MAYER_KINDS", "CONTROL_LAYOUTS", "DEVIATION_STATES",
           "PathConstraint", "ObjectiveTerm", "CustomProblem", "OptimalControlProblem"]

PATH_QUANTITIES = {  # name -> (FlightConditions field, unit)
    "dynamic_pressure": ("dynamic_pressure", "Pa"), "heat_flux": ("heat_flux", "W/m^2"),
    "normal_load": ("normal_load", "g"), "total_load": ("total_load", "g"),
    "sensed_acceleration": ("total_load", "g"),  # paper 002 eq. 7, a = sqrt(L^2 + D^2), in g
    "mach": ("mach", "-"),
    # geodetic altitude above the ellipsoid (the atmosphere's altitude, planet.atmospheric_altitude)
    "geodetic_altitude": (None, "m"),
    # V^2/2 - mu/r: the central-gravity specific energy at which a closed loop stops
    # (Scenario.guidance_terminal_state), without the J2 term of FlightConditions.energy
    "central_energy": (None, "J/kg"),
}
#: the smoothing of |sigma| in a centred bank effort [rad]
BANK_SMOOTHING = math.radians(1.0)
LAGRANGE_KINDS = ("control_margin", "bank_effort", "flight_path_effort", "heat_load", "lagrange")
MAYER_KINDS = ("final_time", "miss_distance", "final_latitude", "final_crossrange", "final_velocity",
               "terminal_deviation", "mayer")
CONTROL_LAYOUTS = ("rates", "direct", "bank_rate")
#: the states terminal_deviation may weigh
DEVIATION_STATES = ("h", "lon", "lat", "V", "gamma", "psi")


@dc.dataclass
class PathConstraint:
    """min <= value(x, u) <= max at every node (in a problem's ``terminal`` list: at the final
    node only).

    quantity: a PATH_QUANTITIES name (SI units as listed) or a callable
    ``f(x, u, env) -> scalar`` with env the node's FlightConditions; ``scale`` is the
    value's typical size (default: the finite bound), used to scale the NLP row."""

    quantity: str | Callable
    min: float = -math.inf
    max: float = math.inf
    scale: float | None = None
    name: str = ""

    def __post_init__(self):
        if not callable(self.quantity) and self.quantity not in PATH_QUANTITIES:
            raise ScenarioError(f"path constraint quantity '{self.quantity}' is unknown; allowed: "
                             f"{', '.join(PATH_QUANTITIES)} or a callable f(x, u, env)")
        if not self.min <= self.max or (math.isinf(self.min) and math.isinf(self.max)):
            raise ScenarioError(f"path constraint '{self.label}' needs min <= max with one finite, got "
                             f"[{self.min}, {self.max}]")
        if self.scale is None:
            finite = [abs(v) for v in (self.min, self.max) if math.isfinite(v) and v != 0.0]
            self.scale = max(finite) if finite else 1.0

    @property
    def label(self) -> str:
        return self.name or (self.quantity if isinstance(self.quantity, str) else "user")

    def value(self, x, u, env: FlightConditions, planet: Earth | None = None):
        if callable(self.quantity):
            return self.quantity(x, u, env)
        if self.quantity == "geodetic_altitude":
            return planet.atmospheric_altitude(x[0], x[2])
        if self.quantity == "central_energy":
            return 0.5 * x[3] * x[3] - planet.mu / planet.radius(x[0])
        return getattr(env, PATH_QUANTITIES[self.quantity][0])


@dc.dataclass
class ObjectiveTerm:
    """One weighted term of J = sum(weight * term).

    Lagrange kinds (integrated over time):
      control_margin  paper 002 eq. 11: k1 ((alpha - alpha_bar)/alpha_max)^2
                      + k2 (u_alpha/u_alpha_max)^2 + k3 (u_sigma/u_sigma_max)^2 [1/s]
      bank_effort     (sigma/bank_max)^2 + rate_weight (u_sigma/u_sigma_max)^2 [1/s] (bank a
                      state: controls 'rates' or 'bank_rate'); a unique minimiser among the
                      bankings that meet hard terminal conditions (paper 003 database). With
                      ``bank_centre`` > 0 [rad] the first term is ((|sigma|_s - bank_centre) /
                      bank_max)^2, |sigma|_s = sqrt(sigma^2 + BANK_SMOOTHING^2) (smooth): the
                      least deviation of the bank's magnitude from the centre, so that a tracker
                      has lift to shed and to gain on either side of the plan
      flight_path_effort  (gamma/scale)^2 [1/s], ``scale`` in rad: damps the phugoid, so that
                      a long glide's least-bank flight does not skip (a mission's AMPI database)
      heat_load       heat flux [W/m^2] (J = heat load [J/m^2])
      lagrange        ``function(x, u, env)``
    Mayer kinds (at the final node): final_time [s]; miss_distance [m] to ``target``
      (lon, lat rad), squared and divided by ``scale`` unless ``squared=False``;
      final_latitude [rad]; final_crossrange [m] from the great circle through the initial
      position along the initial heading; final_velocity [m/s]; terminal_deviation
      (paper 003 eq. 1): sum over ``weights`` {state: w} of w ((x_f - reference[state]) / unit)^2,
      reference SI, unit 1 (rad, m, m/s) with units='si' or canonical (h / R_ref,
      V / sqrt(mu / R_ref), angles in rad) with units='canonical'; mayer ``function(xf, tf)``.
    Use a negative weight to maximise (e.g. final_latitude with weight -1).
    """

    kind: str
    weight: float = 1.0
    k: tuple = (1.0, 18.0, 20.0)  # paper 002 eq. 19
    alpha_bar: float | None = None  # default: the vehicle's max-L/D alpha
    alpha_max: float = math.radians(25.0)
    u_alpha_max: float = math.radians(10.0)
    u_sigma_max: float = math.radians(30.0)
    target: tuple | None = None
    scale: float = 1.0
    squared: bool = True
    function: Callable | None = None
    bank_max: float = math.radians(60.0)
    rate_weight: float = 0.1
    bank_centre: float = 0.0
    reference: dict | None = None
    weights: dict | None = None
    units: str = "si"

    def __post_init__(self):
        if self.kind not in LAGRANGE_KINDS + MAYER_KINDS:
            raise ScenarioError(f"objective kind '{self.kind}' is unknown; allowed: "
                             f"{', '.join(LAGRANGE_KINDS + MAYER_KINDS)}")
        if self.kind in ("lagrange", "mayer") and self.function is None:
            raise ScenarioError(f"objective kind '{self.kind}' needs a function")
        if self.kind == "miss_distance" and self.target is None:
            raise ScenarioError("objective 'miss_distance' needs target = (lon, lat) [rad]")
        if not math.isfinite(self.weight):
            raise ScenarioError(f"objective '{self.kind}': weight = {self.weight} must be finite")
        if self.kind == "control_margin":
            if len(self.k) != 3 or not all(0 <= v < math.inf for v in self.k):
                raise ScenarioError(f"objective 'control_margin': k = {list(self.k)} needs three finite weights >= 0")
            for name in ("alpha_max", "u_alpha_max", "u_sigma_max"):
                if not 0 < getattr(self, name) < math.inf:
                    raise ScenarioError(f"objective 'control_margin': {name} = {getattr(self, name)} must be "
                                        f"finite and > 0")
        if not 0 < self.scale < math.inf:
            raise ScenarioError(f"objective '{self.kind}': scale = {self.scale} must be finite and > 0")
        if self.kind == "bank_effort":
            for name in ("bank_max", "u_sigma_max"):
                if not 0 < getattr(self, name) < math.inf:
                    raise ScenarioError(f"objective 'bank_effort': {name} = {getattr(self, name)} must be finite and > 0")
            if not 0 <= self.rate_weight < math.inf:
                raise ScenarioError(f"objective 'bank_effort': rate_weight = {self.rate_weight} must be finite and >= 0")
            if not 0 <= self.bank_centre < self.bank_max:
                raise ScenarioError(f"objective 'bank_effort': bank_centre = {math.degrees(self.bank_centre):g} deg; "
                                    f"allowed 0 to below bank_max ({math.degrees(self.bank_max):g} deg)")
        if self.kind == "terminal_deviation":
            if not self.weights or not self.reference:
                raise ScenarioError("objective 'terminal_deviation' needs weights and reference {state: value}")
            for name, w in self.weights.items():
                if name not in DEVIATION_STATES:
                    raise ScenarioError(f"objective 'terminal_deviation': weights.{name} is not a state; allowed: "
                                        f"{', '.join(DEVIATION_STATES)}")
                if name not in self.reference:
                    raise ScenarioError(f"objective 'terminal_deviation': weights.{name} has no reference.{name}")
                if not 0 <= w < math.inf:
                    raise ScenarioError(f"objective 'terminal_deviation': weights.{name} = {w} must be finite and >= 0")
            if self.units not in ("si", "canonical"):
                raise ScenarioError(f"objective 'terminal_deviation': units = '{self.units}'; allowed: si, canonical")

    @property
    def is_lagrange(self) -> bool:
        return self.kind in LAGRANGE_KINDS


class _ProblemLayout:
    """Bounds and layout shared by every problem class (needs state_names, control_names,
    initial, final, final_time, state_bounds, control_bounds, path)."""

    @property
    def n_states(self) -> int:
        return len(self.state_names)

    @property
    def n_controls(self) -> int:
        return len(self.control_names)

    @property
    def final_time_bounds(self) -> tuple:
        """(min, max) of t_f [s]: a number is fixed; None is free, (0, inf); (min, max) with
        either end None (0 or inf) is an interval."""
        t = self.final_time
        if t is None:
            return 0.0, math.inf
        if isinstance(t, (int, float, np.integer, np.floating)) and not isinstance(t, bool):
            return float(t), float(t)
        lo, hi = t
        return (0.0 if lo is None else float(lo)), (math.inf if hi is None else float(hi))

    def _check_layout(self):
        for where, d in (("initial", self.initial), ("final", self.final), ("state_bounds", self.state_bounds)):
            for k in d:
                if k not in self.state_names:
                    raise ScenarioError(f"{where}: unknown state '{k}'; states are {', '.join(self.state_names)}")
        for k in self.control_bounds:
            if k not in self.control_names:
                raise ScenarioError(f"control_bounds: unknown control '{k}'; controls are {', '.join(self.control_names)}")
        try:
            lo, hi = self.final_time_bounds
        except (TypeError, ValueError):
            raise ScenarioError(f"final_time = {self.final_time!r}: allowed a number [s], (min, max) with None for an "
                                f"open end, or None (free)") from None
        if math.isnan(lo) or math.isnan(hi) or not (0.0 <= lo <= hi and hi > 0.0):
            raise ScenarioError(f"final_time = {self.final_time!r}: allowed 0 <= min <= max, max > 0 [s]")

    def _default_state_bounds(self) -> tuple[np.ndarray, np.ndarray]:
        return np.full(self.n_states, -np.inf), np.full(self.n_states, np.inf)

    def bounds_arrays(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(x_lo, x_hi, u_lo, u_hi) path bounds; +-inf where unbounded."""
        xl, xh = self._default_state_bounds()
        for i, n in enumerate(self.state_names):
            if n in self.state_bounds:
                xl[i], xh[i] = max(xl[i], self.state_bounds[n][0]), min(xh[i], self.state_bounds[n][1])
        ul, uh = np.full(self.n_controls, -np.inf), np.full(self.n_controls, np.inf)
        for i, n in enumerate(self.control_names):
            if n in self.control_bounds:
                ul[i], uh[i] = self.control_bounds[n]
        return xl, xh, ul, uh

    def boundary_bounds(self, which: str) -> tuple[np.ndarray, np.ndarray]:
        """(lower, upper) of the 'initial' or 'final' state; +-inf where free."""
        spec = self.initial if which == "initial" else self.final
        lo, hi = (b.copy() for b in self.bounds_arrays()[:2])
        for i, name in enumerate(self.state_names):
            v = spec.get(name)
            if v is None:
                continue
            if isinstance(v, (tuple, list)):
                lo[i], hi[i] = max(lo[i], v[0]), min(hi[i], v[1])
            else:
                lo[i] = hi[i] = float(v)
        return lo, hi


@dc.dataclass
class CustomProblem(_ProblemLayout):
    """A general optimal-control problem given by functions (any state and control layout);
    the same transcriptions and solvers as the entry problem.

    Attributes:
      state_names, control_names: names (their order is the vector order).
      dynamics_function: f(x, u) -> xdot. lagrange_function: L(x, u) or None.
      mayer_function: M(xf, tf) or None. path: PathConstraint list whose quantity is a
        callable f(x, u, env) (env is None here); terminal: the same at the final node.
      initial, final, final_time, state_bounds, control_bounds: as OptimalControlProblem.
      state_scale, control_scale, time_scale: typical sizes [SI] the NLP divides by; None
        (default) lets the solver choose them from the guess and bounds (nlp.scaling).
    """

    state_names: tuple
    control_names: tuple
    dynamics_function: Callable
    initial: dict
    final: dict
    final_time: float | tuple | None
    lagrange_function: Callable | None = None
    mayer_function: Callable | None = None
    state_bounds: dict = dc.field(default_factory=dict)
    control_bounds: dict = dc.field(default_factory=dict)
    path: list = dc.field(default_factory=list)
    terminal: list = dc.field(default_factory=list)
    state_scale: tuple | None = None
    control_scale: tuple | None = None
    time_scale: float | None = None
    name: str = "custom"

    def __post_init__(self):
        self._check_layout()
        if self.lagrange_function is None and self.mayer_function is None:
            raise ScenarioError("CustomProblem needs a lagrange_function or a mayer_function")

    def dynamics(self, x, u):
        return np.asarray(self.dynamics_function(x, u))

    def lagrangian(self, x, u):
        return self.lagrange_function(x, u) if self.lagrange_function is not None else 0.0

    def mayer(self, xf, tf):
        return self.mayer_function(xf, tf) if self.mayer_function is not None else 0.0

    @property
    def has_lagrange(self) -> bool:
        return self.lagrange_function is not None

    @property
    def has_mayer(self) -> bool:
        return self.mayer_function is not None

    def path_values(self, x, u) -> list:
        return [c.quantity(x, u, None) for c in self.path]

    def terminal_values(self, x, u) -> list:
        return [c.quantity(x, u, None) for c in self.terminal]

    def scales(self) -> tuple:
        """(state, control, time) scales the user gave [SI]; None where nlp.scaling chooses."""
        sx = None if self.state_scale is None else np.asarray(self.state_scale, float)
        su = None if self.control_scale is None else np.asarray(self.control_scale, float)
        return sx, su, (None if self.time_scale is None else float(self.time_scale))


@dc.dataclass
class OptimalControlProblem(_ProblemLayout):
    """An entry optimal-control problem (paper 002 Sec. 'Optimal Control Problem').

    Attributes:
      vehicle, planet, atmosphere: the models.
      initial, final: state name -> fixed value, (min, max) or None (free), SI / rad.
        States not named are free.
      final_time: fixed t_f [s], (min, max) (None for an open end) or None (free); t_0 = 0.
      controls: 'rates' (alpha, sigma are states, controls are their rates), 'direct', or
        'bank_rate' (alpha = alpha_schedule(s); sigma and a clock t are states, u_sigma the
        control).
      alpha_schedule: the angle-of-attack law [rad] for 'bank_rate' (schedules.Schedule) over
        time [s] (the clock state; paper 003 Table 2: 42 deg to 58 s, linear to 17.5 deg at
        88 s), speed [m/s], specific energy [J/kg, central gravity, as the closed loop's
        schedule reads it] or Mach (the speed over the speed of sound at the geodetic
        altitude): the law a mission flies, whatever its variable.
      state_bounds, control_bounds: name -> (min, max) along the whole trajectory.
      path: path constraints. objective: terms (at least one).
      terminal: constraints on the final node (PathConstraint: the same quantities or a
        callable f(x, u, env)), e.g. a geodetic altitude window, a Mach bound, a landing cone.
    """

    vehicle: Vehicle
    planet: Earth
    atmosphere: Atmosphere
    initial: dict
    final: dict
    final_time: float | tuple | None
    objective: list
    controls: str = "rates"
    state_bounds: dict = dc.field(default_factory=dict)
    control_bounds: dict = dc.field(default_factory=dict)
    path: list = dc.field(default_factory=list)
    terminal: list = dc.field(default_factory=list)
    name: str = "problem"
    alpha_schedule: Schedule | None = None

    def __post_init__(self):
        if self.controls not in CONTROL_LAYOUTS:
            raise ScenarioError(f"controls must be one of {', '.join(CONTROL_LAYOUTS)}, got '{self.controls}'")
        if (self.controls == "bank_rate") != (self.alpha_schedule is not None):
            raise ScenarioError("alpha_schedule is given exactly with controls='bank_rate' (alpha scheduled)")
        if self.alpha_schedule is not None:
            if "t" not in self.initial:  # the clock starts at 0 s unless told
                self.initial = {**self.initial, "t": 0.0}
        self._check_layout()
        self._check_physical()
        if not self.objective:
            raise ScenarioError("objective needs at least one term")
        for term in self.objective:
            if term.kind == "control_margin" and self.controls != "rates":
                raise ScenarioError("objective 'control_margin' (paper 002 eq. 11) needs controls='rates'")
            if term.kind == "bank_effort" and self.controls == "direct":
                raise ScenarioError("objective 'bank_effort' needs the bank as a state: controls='rates' or 'bank_rate'")

    # states an entry vehicle can have (SI / rad): fixed boundary values must lie inside
    PHYSICAL = {"h": (-5e3, 1e6), "lon": (-4 * math.pi, 4 * math.pi), "lat": (-math.pi / 2, math.pi / 2),
                "V": (1.0, 2e4), "gamma": (-math.pi / 2, math.pi / 2), "psi": (-4 * math.pi, 4 * math.pi),
                "alpha": (-math.pi, math.pi), "sigma": (-4 * math.pi, 4 * math.pi), "t": (0.0, 1e6)}

    def _check_physical(self):
        for where, d in (("initial", self.initial), ("final", self.final)):
            for name, v in d.items():
                lo, hi = self.PHYSICAL[name]
                values = v if isinstance(v, (tuple, list)) else (v,)
                for x in values:
                    if not (isinstance(v, (tuple, list)) and math.isinf(x)) and not lo <= x <= hi:
                        raise ScenarioError(f"{where}.{name} = {x} is out of range for an entry state; "
                                            f"allowed [{lo:g}, {hi:g}] (SI / rad)")

    # -- layout -------------------------------------------------------------------------
    @staticmethod
    def layout_names(controls: str) -> tuple:
        """(state names, control names) of a control layout."""
        extra = {"rates": ("alpha", "sigma"), "direct": (), "bank_rate": ("sigma", "t")}[controls]
        return STATE_NAMES + extra, {"rates": ("u_alpha", "u_sigma"), "direct": ("alpha", "sigma"),
                                     "bank_rate": ("u_sigma",)}[controls]

    @property
    def state_names(self) -> tuple:
        return self.layout_names(self.controls)[0]

    @property
    def control_names(self) -> tuple:
        return self.layout_names(self.controls)[1]

    @property
    def bank_index(self) -> tuple:
        """Where the bank is: ('state', i) or ('control', j)."""
        return {"rates": ("state", 7), "direct": ("control", 1), "bank_rate": ("state", 6)}[self.controls]

    def bank_and_rate(self, x, u):
        """(sigma [rad], u_sigma [rad/s]) for the layouts with the bank as a state."""
        return (x[7], u[1]) if self.controls == "rates" else (x[6], u[0])

    def _default_state_bounds(self):
        xl, xh = np.full(self.n_states, -np.inf), np.full(self.n_states, np.inf)
        # altitude within the atmosphere model's range (a solver step never leaves it)
        xl[0] = max(getattr(self.atmosphere, "h_min", -np.inf), -4000.0)
        xh[0] = min(getattr(self.atmosphere, "h_max", np.inf), 1.0e6)
        xl[2], xh[2] = -math.radians(89.99), math.radians(89.99)  # the poles are singular (1 / cos lat)
        xl[3] = 1.0  # speed stays positive (the equations divide by V)
        xl[4], xh[4] = -math.radians(89.99), math.radians(89.99)  # gamma = +-90 deg is singular
        return xl, xh

    def scales(self) -> tuple[np.ndarray, np.ndarray, float]:
        """NLP scaling (canonical units, paper 002 'Application', with altitude in 10 km):
        state scales, control scales (the control bound where finite) and the time unit
        T = R / V_c (the period of a circular orbit at one radius divided by 2 pi) [SI]."""
        R = self.planet.reference_radius
        Vc = math.sqrt(self.planet.mu / R)
        sx = np.ones(self.n_states)
        sx[0], sx[3] = 1.0e4, Vc
        if self.controls == "bank_rate":
            sx[7] = R / Vc  # the clock in time units
        _, _, ul, uh = self.bounds_arrays()
        su = np.array([max(abs(lo), abs(hi)) if np.isfinite(lo) and np.isfinite(hi) else 1.0
                       for lo, hi in zip(ul, uh)])
        return sx, su, R / Vc

    # -- models (float and AutoDiffXd) ---------------------------------------------------
    def scheduled_alpha(self, x):
        """alpha [rad] of the 'bank_rate' layout's schedule at state x (any scalar type)."""
        s = self.alpha_schedule
        if s.variable == "time":
            return s.at(x[7])
        if s.variable == "velocity":
            return s.at(x[3])
        if s.variable == "energy":
            return s.at(specific_energy(x, self._energy_planet))
        return s.at(x[3] / air_data(x, self.planet, self.atmosphere)[1])  # Mach

    @functools.cached_property
    def _energy_planet(self) -> Earth:
        """The planet an energy schedule is read with: central gravity (the closed loop's)."""
        return self.planet.with_(j2=0.0)

    def alpha_sigma(self, x, u):
        if self.controls == "bank_rate":
            return self.scheduled_alpha(x), x[6]
        return (x[6], x[7]) if self.controls == "rates" else (u[0], u[1])

    def dynamics(self, x, u) -> np.ndarray:
        """xdot [SI] (paper 002 eqs. 1 and 6, in the canonical state order)."""
        alpha, sigma = self.alpha_sigma(x, u)
        xdot = state_derivatives(x[:6], sigma, alpha, self.vehicle, self.planet, self.atmosphere)
        if self.controls == "rates":
            return np.concatenate([xdot, [u[0], u[1]]])
        if self.controls == "bank_rate":
            return np.concatenate([xdot, [u[0], 1.0 + 0.0 * x[7]]])  # sigma' = u_sigma, t' = 1
        return xdot

    def conditions(self, x, u) -> FlightConditions:
        """Flight conditions at (x, u): q, heat flux, load factors, L, D, ..."""
        alpha, sigma = self.alpha_sigma(x, u)
        return flight_conditions(x[:6], sigma, alpha, self.vehicle, self.planet, self.atmosphere)

    def lagrangian(self, x, u):
        """Sum of the weighted Lagrange terms at (x, u) [cost units / s]."""
        total, env = 0.0, None
        for term in self.objective:
            if not term.is_lagrange:
                continue
            if term.kind == "control_margin":  # paper 002 eq. 11
                k1, k2, k3 = term.k
                a_bar = self.alpha_bar if term.alpha_bar is None else term.alpha_bar
                v = (k1 * ((x[6] - a_bar) / term.alpha_max) ** 2 + k2 * (u[0] / term.u_alpha_max) ** 2
                     + k3 * (u[1] / term.u_sigma_max) ** 2)
            elif term.kind == "bank_effort":
                sigma, rate = self.bank_and_rate(x, u)
                if term.bank_centre > 0.0:
                    sigma = np.sqrt(sigma * sigma + BANK_SMOOTHING ** 2) - term.bank_centre
                v = (sigma / term.bank_max) ** 2 + term.rate_weight * (rate / term.u_sigma_max) ** 2
            elif term.kind == "flight_path_effort":
                v = (x[4] / term.scale) ** 2
            else:
                env = env if env is not None else self.conditions(x, u)
                v = env.heat_flux if term.kind == "heat_load" else term.function(x, u, env)
            total = total + term.weight * v
        return total

    def mayer(self, xf, tf):
        """Sum of the weighted Mayer terms at the final state xf and time tf [s]."""
        total = 0.0
        for term in self.objective:
            if term.is_lagrange:
                continue
            if term.kind == "final_time":
                v = tf
            elif term.kind == "miss_distance":
                d = central_angle_smooth(xf[1], xf[2], *term.target) * self.planet.reference_radius
                v = d * d / term.scale if term.squared else d
            elif term.kind == "final_latitude":
                v = xf[2]
            elif term.kind == "final_velocity":
                v = xf[3]
            elif term.kind == "final_crossrange":
                v = self.crossrange(xf)
            elif term.kind == "terminal_deviation":  # paper 003 eq. 1
                v = self.terminal_deviation(xf, term)
            else:
                v = term.function(xf, tf)
            total = total + term.weight * v
        return total

    @property
    def has_lagrange(self) -> bool:
        return any(t.is_lagrange for t in self.objective)

    @property
    def has_mayer(self) -> bool:
        return any(not t.is_lagrange for t in self.objective)

    @functools.cached_property
    def alpha_bar(self) -> float:
        """alpha at maximum L/D [rad]: the aero model's own (paper 002: sqrt(C_D0/K) for the
        drag polar), else the largest C_L/C_D over 0-60 deg at the initial Mach number
        (0.01 deg grid; found once per problem: the eq. 11 cost reads it at every evaluation),
        else 10 deg when the initial state is not fixed."""
        a = getattr(self.vehicle.aero, "alpha_max_lift_to_drag", None)
        if a is not None:
            return float(a)
        h0, v0 = self.initial.get("h"), self.initial.get("V")
        if not isinstance(h0, (int, float)) or not isinstance(v0, (int, float)):
            return math.radians(10.0)
        mach = v0 / self.atmosphere.air_data(float(h0))[1]
        alphas = np.radians(np.arange(0.0, 60.0 + 1e-9, 0.01))
        cl, cd = (np.asarray(c, float) for c in self.vehicle.aero.coefficients(alphas, np.full_like(alphas, mach)))
        return float(alphas[int(np.argmax(np.where(cd > 0, cl / np.where(cd > 0, cd, 1.0), -np.inf)))])

    def terminal_deviation(self, xf, term: ObjectiveTerm):
        """Paper 003 eq. 1: sum of w ((x_f - reference) / unit)^2 over the weighted states."""
        R = self.planet.reference_radius
        unit = {"h": R, "V": math.sqrt(self.planet.mu / R)} if term.units == "canonical" else {}
        total = 0.0
        for name, w in term.weights.items():
            d = (xf[STATE_NAMES.index(name)] - term.reference[name]) / unit.get(name, 1.0)
            total = total + w * d * d
        return total

    def crossrange(self, x):
        """Signed distance [m] of x from the great circle through the initial position along
        the initial heading (+ right of the initial heading)."""
        x0 = [self._initial_value(i) for i in range(6)]
        return crossrange_from_great_circle(x[1], x[2], x0[1], x0[2], x0[5], self.planet.reference_radius)

    def _initial_value(self, i: int) -> float:
        v = self.initial.get(self.state_names[i])
        if v is None or isinstance(v, (tuple, list)):
            raise ScenarioError(f"crossrange needs a fixed initial {self.state_names[i]}")
        return float(v)

    def path_values(self, x, u) -> list:
        env = self.conditions(x, u)
        return [c.value(x, u, env, self.planet) for c in self.path]

    def terminal_values(self, x, u) -> list:
        env = self.conditions(x, u)
        return [c.value(x, u, env, self.planet) for c in self.terminal]

    def with_(self, **changes) -> "OptimalControlProblem":
        return dc.replace(self, **changes)
