"""Settings a guidance method derives from a mission: every method on any mission.

A method's folder may hold ``derive.py`` with ``derive(scenario) -> Derivation``: pure
computation from the mission (the vehicle and its limits, the entry, the target, the terminal
box, the mission's alpha schedule), no flight and no solver. A ``Derivation`` is the method's
spec with each setting it took from the mission (a ``Choice`` saying how), plus its free
settings as a ``search``: candidates the comparison layer flies in order on the nominal flight
and a few dispersed draws, keeping the best (drake_entry.comparison.derive). Derivation is
deterministic: the same mission gives the same settings. A method that cannot fly a mission
raises ``CannotFly`` with the figures that show why.

The mission facts every method shares are here: the terminal interface (the box centre),
the mission's alpha schedule rewritten in speed, the vehicle's limits with a margin, and the
reversal corridor.
"""
import dataclasses as dc
import importlib
import math
from typing import Callable

import numpy as np
import scipy.optimize

from drake_entry.errors import ScenarioError
from drake_entry.guidance.spec import ReversingBankSpec
from drake_entry.models.planet import G0
from drake_entry.scenario import stated_guidance

__all__ = ["Choice", "SearchStep", "Derivation", "CannotFly", "Interface", "derivation_for",
           "terminal_interface", "box_altitude_tolerance_km", "geodetic_interface_km", "mission_alpha", "alpha_rewritten", "ALTITUDE_STEPS", "ALTITUDE_WHY",
           "interface_altitudes", "reversal_corridor", "LIMIT_MARGIN", "require_alpha_window", "q_limit_speed",
           "box_mach_window", "load_limit_speed", "FORCE_SIGMAS", "FINAL_DESCENT_DEG", "Q_SPEED_FRACTION", "terminal_speed", "interface_speeds", "PATH_GAIN",
           "PATH_LIMIT_FRACTION", "path_gain", "alpha_actuator"]

#: the fraction of a vehicle limit a method's own limit feedback enforces (the rest is the margin
#: for dispersions; FNPEG's hand-set HORUS-2B values were 0.90-0.94 of the limits)
LIMIT_MARGIN = 0.93
#: a plan that a re-plan or re-solve predicts with the forces sensed keeps room for forces this
#: many standard deviations of the mission's force dispersions above the nominal
#: (models.dispersions.force_ratio_high): SCvx's Mach window reaches down to where they meet the
#: planned load bound, the LGL terminal speed stays under it
FORCE_SIGMAS = 3.0
#: a method's plans end descending at least this steeply [deg] where the mission's box gives no
#: flight-path angle (the flight stops where it first crosses the interface altitude): paper 004's
#: CAV-H planned by SCvx to a shallow glide at its stop altitude crossed it 90 s (140 km) late in
#: 5 of 10 dispersed flights; its LGL plans, levelling off to +0.05 deg in their last 40 s, were
#: crossed up to 39 s (75 km) early
FINAL_DESCENT_DEG = 1.0
#: Lu 2014's path-limit feedback gain a method flies where the vehicle has limits and nothing else
#: holds them (the swarm bank under a mission's alpha schedule: HORUS-2B's heat rate was 0.3-2.8 %
#: over in 43 of 100 runs without it; the AMPI tracker: the capsule's final dive passed q in 21 of
#: 100 runs without it). Not searched: the search's three flights succeeded with and without it
#: on HORUS-2B (box ratios 0.80 and 0.79), and kept the gain of 0 that 43 % of the runs fail with
PATH_GAIN = 40.0
#: the fraction of the vehicle's limits that feedback holds (HORUS-2B's swarm bank, 100 runs: 100 of
#: 100 at 0.95; at 0.9, 14 of 20: the flights lofted over the heat peak end steeper, q 0.1-1.6 %
#: over in the last 30 s, where the first-order prediction sees q falling)
PATH_LIMIT_FRACTION = 0.95


def path_gain(vehicle) -> float:
    """The derived path-limit feedback gain: PATH_GAIN where ``vehicle`` limits its load, heat rate
    or dynamic pressure (a finite limit), else 0 (nothing to hold)."""
    lim = vehicle.limits
    limited = any(math.isfinite(x) for x in (lim.heat_flux_max, lim.dynamic_pressure_max, lim.load_bound_max))
    return PATH_GAIN if limited else 0.0


def alpha_actuator(scenario, fields: tuple[str, str], own: tuple[float, float], whose: str):
    """The alpha actuator a method commanding alpha flies on the mission: the vehicle's rate
    [deg/s] and acceleration [deg/s^2] limits where its file states them, else the method's own
    paper's (``own``, named by ``whose``). Returns (rate, acceleration, the Choice for
    ``fields``): a plan flown at its own paper's 1 deg/s where the vehicle's actuator gives 5
    lags the mission's alpha (SHEFEX-3's SCvx plan flown 20.8 km from itself, 2.1 km at 5)."""
    v = scenario.make_vehicle()
    stated = (v.alpha_rate_limit, v.alpha_accel_limit)
    rate, accel = (own[i] if x is None else round(math.degrees(x), 9) for i, x in enumerate(stated))
    if all(x is not None for x in stated):
        how = "the vehicle's alpha actuator (its file's limits)"
    elif any(x is not None for x in stated):
        how = f"the vehicle's alpha actuator where its file states a limit, else {whose}"
    else:
        how = f"{whose}: the vehicle states no alpha actuator limits"
    return rate, accel, Choice(", ".join(fields), f"{rate:g} deg/s, {accel:g} deg/s^2", how)


@dc.dataclass
class Choice:
    """One setting taken from the mission: the dotted field, its value, and how it was chosen."""

    field: str
    value: object
    how: str


@dc.dataclass
class SearchStep:
    """One free setting: ``name`` (what is searched), ``candidates`` tried in order, each the
    dotted fields it sets ({'guidance.bank_end_deg': 45.0}; the first is the derivation's own
    value), and why it is free. ``exhaustive``: every candidate is flown and the best kept (a
    setting whose effect is graded, such as one that moves the terminal altitude), instead of
    the first good enough. ``calibrate``: a candidate measured, tried before ``candidates``: the
    fields it returns from the campaign row (drake_entry.campaign.sample.campaign_row) of the
    nominal flight with the settings chosen before this step. ``over`` builds the step of one
    field, ``calibrated`` one whose value is measured."""

    name: str
    candidates: tuple
    why: str
    exhaustive: bool = False
    calibrate: Callable[[dict], dict] | None = None

    @classmethod
    def over(cls, field: str, values, why: str, *, exhaustive: bool = False) -> "SearchStep":
        return cls(field, tuple({field: v} for v in values), why, exhaustive)

    @classmethod
    def calibrated(cls, field: str, measure: Callable[[dict], float], fallbacks, why: str) -> "SearchStep":
        """``field`` at ``measure(row)`` of the nominal flight first, then at each of ``fallbacks``."""
        return cls(field, tuple({field: v} for v in fallbacks), why, calibrate=_Measured(field, measure))


@dc.dataclass(frozen=True)
class _Measured:
    """A calibrated step's measure: {field: measure(row)} (comparable, so that the same mission
    derives equal steps)."""

    field: str
    measure: Callable[[dict], float]

    def __call__(self, row: dict) -> dict:
        return {self.field: self.measure(row)}


@dc.dataclass
class Derivation:
    """A method's settings for a mission: ``spec`` (its guidance block, the search's fields at
    their first candidates), the ``choices`` taken from the mission, the ``search`` steps
    (flown one after the other, each at the best values of the ones before), and ``alpha``: the
    mission's open-loop alpha schedule rewritten for a method that flies it (a ScheduleSpec;
    None: the mission's as it is)."""

    spec: object
    choices: list[Choice]
    search: list[SearchStep] = dc.field(default_factory=list)
    alpha: object = None


class CannotFly(ScenarioError):
    """A method cannot fly a mission; the message says why, with its figures."""


@dc.dataclass(frozen=True)
class Interface:
    """The mission's terminal interface, the centre of its acceptance box: altitude [km] as a
    guidance block states it (the scenario's altitude datum), speed [m/s], its Mach number there,
    the speed of sound there [m/s], whether the mission gives the Mach number (else the speed),
    the box's altitude tolerance about it [km] (None: the box checks no altitude), and whether
    the speed is where the mission's own method stops (the box checks none)."""

    altitude_km: float
    speed_m_s: float
    mach: float
    speed_of_sound: float
    mach_given: bool
    altitude_tolerance_km: float | None = None
    speed_from_own_method: bool = False

    @property
    def speed_words(self) -> str:
        """Where the interface's speed comes from, in words."""
        if self.speed_from_own_method:
            return "the speed where the mission's own method stops (its box checks no speed)"
        return "the box's centre speed"


def derivation_for(scenario, spec_type) -> Derivation:
    """The Derivation of method ``spec_type`` (a registered spec class) for ``scenario``'s
    mission: the mission's own block when the mission states one of this method, else
    ``guidance/<folder>/derive.py``'s ``derive`` (another method's mission, or none stated);
    CannotFly when the method has no derive.py or cannot fly the mission."""
    from drake_entry.guidance import folder_of

    folder = folder_of(spec_type)
    name = f"drake_entry.guidance.{folder}.derive"
    try:
        module = importlib.import_module(name)
    except ModuleNotFoundError as e:
        if e.name != name:
            raise
        raise CannotFly(f"!{spec_type.__name__} derives no settings from a mission (guidance/{folder}/derive.py "
                        f"is not written): give its guidance block in the comparison") from None
    own = stated_guidance(scenario)  # a mission file's guidance block, None when it states none
    if type(own) is spec_type:  # the mission's own method flies the mission's settings
        return Derivation(dc.replace(own), [Choice("guidance", f"!{spec_type.__name__}", "the mission's own settings")])
    derivation = module.derive(scenario)
    if type(derivation.spec) is not spec_type:
        raise TypeError(f"{name}.derive returned a {type(derivation.spec).__name__}, not a {spec_type.__name__}")
    return derivation


def require_alpha_window(scenario, widen_deg: float = 0.0) -> None:
    """CannotFly when the mission's box asks an alpha window at the interface that no alpha of the
    mission's alpha schedule (widened by ``widen_deg`` each side: a law moving alpha between
    bounds) falls in: a method flying that schedule cannot end inside the box, whatever its bank."""
    t = scenario.terminal
    if t.alpha_deg is None or t.alpha_tolerance_deg is None:  # no alpha criterion in the box
        return
    tol = t.alpha_tolerance_deg
    alpha, source = mission_alpha(scenario)
    lo, hi = min(alpha.values_deg) - widen_deg, max(alpha.values_deg) + widen_deg
    if hi < t.alpha_deg - tol or lo > t.alpha_deg + tol:
        flown = f"{lo:g} deg" if lo == hi else f"{lo:g} to {hi:g} deg"
        raise CannotFly(f"the mission's box asks alpha {t.alpha_deg:g} +- {tol:g} deg at its interface, and this "
                        f"method flies {source} alpha schedule ({flown}), with the bank its only control")


def terminal_interface(scenario) -> Interface:
    """The centre of the mission's acceptance box (terminal.altitude_km, or its
    geodetic_altitude_km at the target's latitude, and its mach or velocity_m_s; where the box
    checks no speed, the speed at which the mission's own method stops); CannotFly when the
    mission gives no altitude, or no speed and no method of its own that stops at one."""
    t = scenario.terminal
    altitude_km = t.altitude_km
    if altitude_km is None and t.geodetic_altitude_km is not None:
        altitude_km = geodetic_interface_km(scenario)
    tolerance_km = box_altitude_tolerance_km(t)
    if altitude_km is None:
        raise CannotFly("the mission's terminal block gives neither altitude_km nor geodetic_altitude_km: no "
                        "terminal interface to aim at")
    a = float(scenario.make_atmosphere().speed_of_sound(scenario.air_altitude(altitude_km * 1e3)))
    if t.mach is not None:
        return Interface(altitude_km, float(t.mach) * a, float(t.mach), a, True, tolerance_km)
    if t.velocity_m_s is not None:
        return Interface(altitude_km, float(t.velocity_m_s), float(t.velocity_m_s) / a, a, False, tolerance_km)
    own = stated_guidance(scenario)
    if own is not None and not own.stops_at_altitude:
        # the box checks no speed: aim at the speed where the mission's own method stops (SHEFEX-3's
        # AMPI: 620 m/s, the corner of paper 003's window its database ends at)
        own_a = float(scenario.make_atmosphere().speed_of_sound(scenario.air_altitude(own.terminal_altitude_km * 1e3)))
        speed = float(own.terminal_speed(own_a))
        return Interface(altitude_km, speed, speed / a, a, False, tolerance_km, speed_from_own_method=True)
    raise CannotFly("the mission's terminal block gives neither mach nor velocity_m_s, and its own method stops at "
                    "no speed: no terminal speed to aim at")


def box_altitude_tolerance_km(terminal) -> float | None:
    """The box's tolerance [km] about the altitude a method aims at: altitude_tolerance_km, or
    geodetic_altitude_tolerance_km when the box gives its altitude geodetically only."""
    if terminal.altitude_km is None and terminal.geodetic_altitude_km is not None:
        return terminal.geodetic_altitude_tolerance_km
    return terminal.altitude_tolerance_km


def geodetic_interface_km(scenario) -> float:
    """The box's geodetic altitude (terminal.geodetic_altitude_km) as the terminal altitude a
    guidance block states [km]: the geodetic altitude itself with altitude_datum 'ellipsoid', else
    the state altitude at the target's latitude (paper 001's DRS box is geodetic: 11.5 km there
    is a 3.8-km state altitude at the Azores site)."""
    geodetic = scenario.terminal.geodetic_altitude_km * 1e3
    if scenario.altitude_datum == "ellipsoid":
        return geodetic / 1e3
    lat = math.radians(scenario.target.latitude_deg)
    return float(scenario.make_planet().state_altitude(geodetic, lat)) / 1e3


def _altitude_at_energy(E: float, E0: float, h0: float, Ef: float, hf: float) -> float:
    """The altitude [m] at specific energy E [J/kg], linear in energy between the entry (E0, h0)
    and the terminal interface (Ef, hf) (``alpha_rewritten``'s approximation)."""
    return hf + (h0 - hf) * (E - Ef) / (E0 - Ef)


def mission_alpha(scenario):
    """The mission's alpha schedule (a ScheduleSpec) and whose it is: the mission's own method's
    profile when it flies a fixed one of its own (``alpha_profile``), else the scenario's
    ``alpha`` block."""
    stated = stated_guidance(scenario)
    own = stated.alpha_profile() if stated is not None else None
    if own is None:
        return scenario.alpha, "the mission's"
    variable, breakpoints, values = own
    return (dc.replace(scenario.alpha, variable=variable, breakpoints=list(breakpoints), values_deg=list(values)),
            f"the mission's own method's (!{type(scenario.guidance).__name__})")


def alpha_rewritten(scenario, interface: Interface, variable: str) -> tuple[list[float], list[float], str]:
    """The mission's alpha schedule as values [deg] at increasing breakpoints of ``variable``
    ('velocity' [m/s]: FNPEG's profile; 'normalized_energy': e = (E0 - E)/(E0 - Ef) with Ef at
    ``interface``, the drag-energy planner's), and how it was rewritten.

    A schedule already in ``variable`` is taken as it is. Otherwise each breakpoint is mapped
    with the altitude taken linear in specific energy between the entry and the interface: the
    kinetic energy dominates, so the speeds are close (an altitude 5 km off moves a speed of
    2.5 km/s by 0.8 %); between breakpoints the profile stays linear (a smooth schedule keeps its
    blend only where it is not rewritten). A schedule in time has no equivalent before a flight:
    CannotFly."""
    s, source = mission_alpha(scenario)
    values = [float(v) for v in s.values_deg]
    if len(set(values)) == 1:
        return [0.0], values[:1], f"{source} alpha, constant"
    if s.variable == variable:
        return [float(b) for b in s.breakpoints], values, f"{source} alpha schedule in {variable}, as it is"
    if s.variable == "time":
        raise CannotFly(f"the mission's alpha schedule is in time; this method needs it in {variable} (write the "
                        f"mission's schedule in speed, energy, normalised energy or Mach)")
    planet = scenario.make_planet().with_(j2=0.0)
    atmosphere = scenario.make_atmosphere()
    x0 = scenario.initial_state()
    h0, E0 = float(x0[0]), float(planet.specific_energy(x0[0], x0[3]))
    hf = interface.altitude_km * 1e3
    Ef = float(planet.specific_energy(hf, interface.speed_m_s))

    def state_at_energy(E: float) -> tuple[float, float]:
        h = _altitude_at_energy(E, E0, h0, Ef, hf)
        return E, math.sqrt(max(2.0 * (E - float(planet.specific_energy(h, 0.0))), 0.0))

    points = []  # (E [J/kg], V [m/s]) of each breakpoint
    for b in s.breakpoints:
        if s.variable == "normalized_energy":
            points.append(state_at_energy(E0 - b * (E0 - Ef)))
        elif s.variable == "energy":
            points.append(state_at_energy(b))
        else:  # speed or Mach: the altitude on the energy line at that speed (fixed-point passes)
            h = hf
            for _ in range(30):
                a = float(atmosphere.speed_of_sound(min(max(h, atmosphere.h_min), atmosphere.h_max)))
                V = b * a if s.variable == "mach" else float(b)
                h = _altitude_at_energy(float(planet.specific_energy(h, V)), E0, h0, Ef, hf)
            points.append((float(planet.specific_energy(h, V)), V))
    new = [V for _, V in points] if variable == "velocity" else [(E0 - E) / (E0 - Ef) for E, _ in points]
    order = np.argsort(new)
    new, values = [float(new[i]) for i in order], [values[i] for i in order]
    if any(b <= a for a, b in zip(new, new[1:])):
        raise CannotFly(f"the mission's alpha schedule in {s.variable} does not map to increasing {variable} "
                        f"({', '.join(f'{v:.4g}' for v in new)})")
    return new, values, (f"{source} alpha schedule in {s.variable} rewritten in {variable} at its breakpoints "
                         f"(altitude linear in energy from the entry to the interface)")


#: terminal altitudes a method tries, as fractions of the box's altitude tolerance above its
#: centre (a lower interface meets the dynamic-pressure limit first: HORUS-2B's 25 km at Mach 2.5
#: breaches 10 kPa; 26.5 km, three quarters up, is where paper 000's guidance aims)
ALTITUDE_STEPS = (0.0, 0.25, 0.5, 0.75, -0.25, -0.5)


#: why the terminal altitude is searched
ALTITUDE_WHY = "the interface inside the box where the path limits hold to the end"


def interface_altitudes(scenario, interface: Interface) -> tuple[float, ...]:
    """The terminal altitudes [km] to try inside the mission's box (ALTITUDE_STEPS; the centre
    alone when the box has no altitude tolerance), never below the ground."""
    tol = interface.altitude_tolerance_km
    if not tol:
        return (interface.altitude_km,)
    return tuple(h for h in (round(interface.altitude_km + k * tol, 4) for k in ALTITUDE_STEPS) if h >= 0.0)


def box_mach_window(scenario, interface: Interface) -> tuple[tuple[float, float], str] | None:
    """The Mach window the mission's box checks at the interface ((low, high), and how it was
    read: the box's Mach window, or its speed window as Mach numbers at the interface), None
    when the box checks no speed."""
    t = scenario.terminal
    if t.mach is not None and t.mach_tolerance:
        return (t.mach - t.mach_tolerance, t.mach + t.mach_tolerance), "the box's Mach window"
    if t.velocity_m_s is not None and t.velocity_tolerance_m_s:
        a = interface.speed_of_sound
        return (((t.velocity_m_s - t.velocity_tolerance_m_s) / a, (t.velocity_m_s + t.velocity_tolerance_m_s) / a),
                f"the box's speed window as Mach at {interface.altitude_km:g} km")
    return None


def q_limit_speed(scenario, altitude_km: float, fraction: float = 1.0) -> float:
    """The speed [m/s] at which the vehicle meets ``fraction`` of its dynamic-pressure limit at
    ``altitude_km`` (in the mission's datum; the mission's atmosphere read there over the target,
    Scenario.air_altitude; inf when the vehicle limits none): a plan ending there faster breaches it."""
    q_max = scenario.make_vehicle().limits.dynamic_pressure_max
    if not math.isfinite(q_max):
        return math.inf
    rho = float(scenario.make_atmosphere().density(scenario.air_altitude(altitude_km * 1e3)))
    return math.sqrt(2.0 * fraction * q_max / rho)


def load_limit_speed(scenario, altitude_km: float, alpha_deg, fraction: float = 1.0) -> float:
    """The speed [m/s] at which the vehicle meets ``fraction`` of the load it limits (total or
    normal: PathLimits.planned_load) at ``altitude_km`` (the mission's atmosphere), flying
    ``alpha_deg(V)`` [deg] at speed V (inf when it limits neither, or meets it at no speed below
    orbital speed): a plan ending there faster breaches it."""
    vehicle = scenario.make_vehicle()
    kind, limit = vehicle.limits.planned_load()
    if not math.isfinite(limit):
        return math.inf
    atmosphere = scenario.make_atmosphere()
    air = scenario.air_altitude(altitude_km * 1e3)
    rho, a = float(atmosphere.density(air)), float(atmosphere.speed_of_sound(air))

    def excess(V: float) -> float:
        alpha = math.radians(float(alpha_deg(V)))
        CL, CD = (float(c) for c in vehicle.aero.coefficients(alpha, V / a))
        C = math.hypot(CL, CD) if kind == "total" else CL * math.cos(alpha) + CD * math.sin(alpha)
        return 0.5 * rho * V * V * vehicle.area_over_mass * C / G0 - fraction * limit

    low, high = 0.5 * a, 8000.0
    if excess(high) < 0.0:
        return math.inf
    if excess(low) >= 0.0:
        return low
    return float(scipy.optimize.brentq(excess, low, high, xtol=1e-3))


#: the final speed is at most this fraction of the speed where the planned dynamic-pressure
#: bound is met at the terminal altitude (HORUS-2B's box centre, Mach 2.5 at 25 km, is 11 kPa
#: against its 10 kPa limit)
Q_SPEED_FRACTION = 0.97


def terminal_speed(scenario, interface, altitude_km: float, path_margin: float, *, load_alpha_deg: float | None = None,
                   force_high: float = 1.0) -> float:
    """The final speed [m/s] planned at ``altitude_km``: the box's centre speed, or below the
    planned dynamic-pressure bound (Q_SPEED_FRACTION of its speed) where that is lower, and, with
    ``load_alpha_deg`` [deg], at most the speed where forces ``force_high`` times the nominal meet
    the planned load bound flying that alpha (a plan re-solved with the forces sensed keeps its
    last node inside the bound: paper 004's CAV-H at 30.5 km and 2000 m/s is over 0.92 x 2 g with
    8 % more lift and density); CannotFly when that is below the box's speed window."""
    q_speed = Q_SPEED_FRACTION * q_limit_speed(scenario, altitude_km, 1.0 - path_margin)
    load_speed = (math.inf if load_alpha_deg is None else
                  load_limit_speed(scenario, altitude_km, lambda V: load_alpha_deg, (1.0 - path_margin) / force_high))
    V = min(interface.speed_m_s, q_speed, load_speed)
    window = box_mach_window(scenario, interface)
    low = window[0][0] * interface.speed_of_sound if window is not None else 0.0
    if V < low:
        limit = (f"the vehicle's dynamic-pressure limit, planned at {1 - path_margin:g} of it, is met at "
                 f"{q_speed / Q_SPEED_FRACTION:.0f} m/s" if q_speed <= load_speed else
                 f"the vehicle's load limit, planned at {1 - path_margin:g} of it with forces {force_high:.3g} x the "
                 f"nominal at alpha {load_alpha_deg:g} deg, is met at {load_speed:.0f} m/s")
        raise CannotFly(f"at {altitude_km:g} km {limit}, below the box's {low:.0f} m/s")
    return round(V, 3)


def interface_speeds(scenario, interface: Interface, path_margin: float, *, load_alpha_deg: float | None = None,
                     force_high: float = 1.0) -> list[tuple[float, float]]:
    """(altitude [km], terminal_speed [m/s]) at each of ``interface_altitudes`` where the planned
    dynamic-pressure bound (and the load bound, with ``load_alpha_deg`` and ``force_high``: see
    terminal_speed) leaves a speed in the box, in their order; the last CannotFly when none does."""
    out, refused = [], None
    for h in interface_altitudes(scenario, interface):
        try:
            out.append((h, terminal_speed(scenario, interface, h, path_margin, load_alpha_deg=load_alpha_deg,
                                          force_high=force_high)))
        except CannotFly as e:
            refused = e
    if not out:
        raise refused
    return out


def reversal_corridor(scenario) -> tuple[list[float], list[float], Choice]:
    """The bank-reversal corridor (half-widths [deg] at speeds [m/s]) and its Choice: the
    mission's own method's when it reverses the bank, else the shared default (paper 000
    Sec. VI.D)."""
    own = stated_guidance(scenario)
    if isinstance(own, ReversingBankSpec):
        heading, velocity = list(own.reversal_heading_deg), list(own.reversal_velocity_m_s)
        how = f"the corridor of the mission's own method (!{type(own).__name__})"
    else:
        default = ReversingBankSpec()
        heading, velocity = list(default.reversal_heading_deg), list(default.reversal_velocity_m_s)
        how = "the shared default corridor (paper 000 Sec. VI.D)"
    return heading, velocity, Choice("guidance.reversal_heading_deg, reversal_velocity_m_s",
                                     f"{heading} deg at {velocity} m/s", how)
