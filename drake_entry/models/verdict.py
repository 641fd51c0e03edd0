"""The one verdict of a flight: it succeeds only if it reached its terminal interface, ended
inside every criterion of the acceptance box, and held every path limit.

Path limits are the vehicle's (heat flux, dynamic pressure, normal and total load, bank
limit) and the mission's own (e.g. paper 001's flight-path-angle bounds, eq. 70), given as
``PathLimit``s. They are checked on every sample of the flown trajectory: the log samples and,
where the runner logged them (``Trajectory.steps``), the integrator's own steps
(``Trajectory.flown``), so a peak
between two log samples is not missed.

A limit holds when ``lower - tol |lower| <= value <= upper + tol |upper|`` at every sample, with
``tol`` the scenario's ``terminal.path_limit_tolerance`` (relative; default 0: a limit is a
limit). The margin of a limit is its worst relative distance to the bound,
``(upper - peak) / |upper|`` (``1 - peak/limit`` for a positive upper limit; negative =
breached), the smaller of the two sides for a two-sided limit.
"""
from __future__ import annotations

import dataclasses as dc
import math

import numpy as np

from drake_entry.models.constraints import PathLimits

__all__ = ["ALTITUDE_FLOOR_M", "altitude_floor", "PathLimit", "DISPLAY_UNITS", "vehicle_path_limits", "LimitCheck", "check_limits", "breaches_text", "BOX_MISSED",
           "LIMITS_BREACHED", "failure_message", "failure_clauses", "ROUNDING", "margin_breached",
           "BoxCriterion", "BOX_CRITERIA", "acceptance_box", "box_text", "Verdict", "judge"]

#: the crash guard of a flight that stops at the terminal energy [m]: below it the flight is
#: stopped and has not reached its interface; at most half the terminal altitude (altitude_floor)
ALTITUDE_FLOOR_M = 5000.0


def altitude_floor(terminal_altitude_m: float) -> float:
    """The crash guard [m] of a flight stopping at the terminal energy: ALTITUDE_FLOOR_M, never
    above half the terminal altitude (a floor above the interface stops every flight short of it:
    paper 001's DRS box lies at a 3.83-km state altitude at the Azores site)."""
    return min(ALTITUDE_FLOOR_M, 0.5 * max(terminal_altitude_m, 0.0))


@dc.dataclass(frozen=True)
class PathLimit:
    """A bound on one flown quantity.

    Attributes:
      name: what the row and report call it ('heat_flux', 'flight_path', ...).
      column: the Trajectory column it reads (a state name, a flight condition, 'bank', 'alpha').
      upper, lower: bounds in SI (rad for angles); +-inf when one-sided.
      absolute: bound |value| instead of value (the bank limit).
      unit, scale: the display unit and the factor from SI to it (e.g. 'kW/m^2', 1e-3).
    """

    name: str
    column: str
    upper: float = math.inf
    lower: float = -math.inf
    absolute: bool = False
    unit: str = ""
    scale: float = 1.0

    def bound_text(self) -> str:
        """The limit as printed in reports, e.g. '<= 530 kW/m^2', 'in [-30, 0.5] deg'."""
        s = self.scale
        if math.isfinite(self.lower) and math.isfinite(self.upper):
            return f"in [{self.lower * s:.4g}, {self.upper * s:.4g}] {self.unit}".rstrip()
        if math.isfinite(self.upper):
            return f"{'|.| ' if self.absolute else ''}<= {self.upper * s:.4g} {self.unit}".rstrip()
        return f">= {self.lower * s:.4g} {self.unit}".rstrip()


#: SI unit -> (the unit reports print a path limit in, its factor from SI); other units print as they are
DISPLAY_UNITS = {"Pa": ("kPa", 1e-3), "W/m^2": ("kW/m^2", 1e-3)}


def vehicle_path_limits(limits: PathLimits, bank_limit: float | None = None) -> list[PathLimit]:
    """The vehicle's finite path limits (and |bank| <= ``bank_limit`` [rad] when given)."""
    out = []
    for name, si_unit in (("heat_flux", "W/m^2"), ("dynamic_pressure", "Pa"), ("normal_load", "g"),
                          ("total_load", "g")):
        unit, scale = DISPLAY_UNITS.get(si_unit, (si_unit, 1.0))
        value = getattr(limits, f"{name}_max")
        if math.isfinite(value):
            out.append(PathLimit(name, name, upper=float(value), unit=unit, scale=scale))
    if bank_limit is not None:
        out.append(PathLimit("bank", "bank", upper=float(bank_limit), absolute=True, unit="deg",
                             scale=180.0 / math.pi))
    return out


@dc.dataclass(frozen=True)
class LimitCheck:
    """One path limit evaluated on a flight.

    Attributes:
      limit: the PathLimit. peak: the flown value nearest to (or furthest past) the binding
        bound [SI]. time: when [s]. margin: relative margin (negative = breached).
      held: within the bound widened by the tolerance.
    """

    limit: PathLimit
    peak: float
    time: float
    margin: float
    held: bool

    def text(self) -> str:
        s = self.limit.scale
        return (f"{self.limit.name} {self.peak * s:.4g} {self.limit.unit} at t = {self.time:.1f} s "
                f"(limit {self.limit.bound_text()}, margin {100 * self.margin:+.2f} %)")


def check_limits(time, column, limits, tolerance: float = 0.0) -> list[LimitCheck]:
    """Evaluate each PathLimit on the samples ``column(name)`` at ``time`` [s] (NaN samples are
    ignored; a limit with no finite sample does not hold). ``tolerance``: relative widening of
    every bound (>= 0)."""
    if not tolerance >= 0.0:
        raise ValueError(f"path-limit tolerance must be >= 0, got {tolerance}")
    t = np.asarray(time, float)
    out = []
    for lim in limits:
        v = np.asarray(column(lim.column), float)
        v = np.abs(v) if lim.absolute else v
        ok = np.isfinite(v)
        if not ok.any():
            out.append(LimitCheck(lim, math.nan, math.nan, math.nan, False))
            continue
        tv, vv = t[ok], v[ok]
        candidates = []
        if math.isfinite(lim.upper):
            i = int(np.argmax(vv))
            candidates.append(((lim.upper - vv[i]) / _scale(lim.upper), vv[i], tv[i]))
        if math.isfinite(lim.lower):
            i = int(np.argmin(vv))
            candidates.append(((vv[i] - lim.lower) / _scale(lim.lower), vv[i], tv[i]))
        margin, peak, when = min(candidates, key=lambda c: c[0])
        out.append(LimitCheck(lim, float(peak), float(when), float(margin),
                              not bool(margin_breached(margin, tolerance))))
    return out


def breaches_text(checks) -> str:
    """Each breached limit of ``checks`` (LimitChecks) with its peak, time and margin, '; '
    apart ('' when every limit held)."""
    return "; ".join(c.text() for c in checks if not c.held)


#: how a flight's verdict message opens its two failure clauses (failure_message)
BOX_MISSED, LIMITS_BREACHED = "outside the acceptance box", "path limits breached"


def failure_message(missed: list[str], breaches: str, where: str) -> str:
    """The verdict message of a flight that reached its interface: the acceptance-box criteria
    ``missed`` (each 'name ...', box_text's), the ``breaches`` (breaches_text's; '' when none)
    and ``where`` it ended; ``where`` alone when nothing failed. failure_clauses reads it back."""
    parts = [f"{BOX_MISSED}: {'; '.join(missed)}"] if missed else []
    if breaches:
        parts.append(f"{LIMITS_BREACHED}: {breaches}")
    return f"{' | '.join(parts)} ({where})" if parts else where


def failure_clauses(message: str) -> tuple[list[str], list[str], str]:
    """(the box criteria missed, the path limits breached, by name, and the message's first
    clause, up to 80 characters) of a verdict ``message``: failure_message's inverse; any other
    message (a flight stopped before its interface, a guidance that never engaged, an exception)
    has no criteria and no limits, only its first clause."""
    missed, breached = [], []
    for clause in message.split(" | "):
        clause = clause.split(" (reached")[0]
        for prefix, names in ((BOX_MISSED, missed), (LIMITS_BREACHED, breached)):
            if clause.startswith(prefix + ": "):
                names += [part.split()[0] for part in clause[len(prefix) + 2:].split("; ") if part]
    return missed, breached, message.split(":")[0][:80]


#: relative slack for floating-point rounding at a bound a clamp holds exactly (the bank limit)
ROUNDING = 1e-12


def margin_breached(margin, tolerance: float = 0.0):
    """True where a relative margin (LimitCheck.margin: negative past the bound) breaches its
    limit widened by ``tolerance`` and ROUNDING: the one test the verdict and every report count
    breaches with (a bank clamped at its limit reads a margin of -1e-16 and holds)."""
    return np.asarray(margin, float) < -(tolerance + ROUNDING)


def _scale(bound: float) -> float:
    return abs(bound) if bound != 0.0 else 1.0


@dc.dataclass(frozen=True)
class BoxCriterion:
    """One criterion of the acceptance box: |value - centre| <= tolerance.

    Attributes:
      name: the key in the box and the row ('box_<name>_error', 'inside_<name>_box').
      label: what the report calls it.
      centre, tolerance: the TerminalSpec fields that give them (centre None: 0, a miss
        distance); in the spec's units (km, deg, m/s, Mach).
      si: the factor from the spec's units to SI (1e3 for km, pi/180 for deg); errors are SI.
      unit: the spec's unit, as printed.
    """

    name: str
    label: str
    centre: str | None
    tolerance: str
    si: float
    unit: str


#: every criterion an acceptance box may hold, in report order (a scenario checks those whose
#: tolerance it gives)
BOX_CRITERIA = (
    BoxCriterion("altitude", "terminal altitude", "altitude_km", "altitude_tolerance_km", 1e3, "km"),
    BoxCriterion("mach", "terminal Mach", "mach", "mach_tolerance", 1.0, ""),
    BoxCriterion("distance", "distance to the target", None, "distance_tolerance_km", 1e3, "km"),
    BoxCriterion("velocity", "terminal speed", "velocity_m_s", "velocity_tolerance_m_s", 1.0, "m/s"),
    BoxCriterion("flight_path", "terminal flight-path angle", "flight_path_deg", "flight_path_tolerance_deg",
                 math.pi / 180.0, "deg"),
    BoxCriterion("alpha", "terminal angle of attack", "alpha_deg", "alpha_tolerance_deg", math.pi / 180.0, "deg"),
    BoxCriterion("vertical_speed", "terminal vertical speed", "vertical_speed_m_s", "vertical_speed_tolerance_m_s",
                 1.0, "m/s"),
    BoxCriterion("geodetic_altitude", "terminal geodetic altitude", "geodetic_altitude_km",
                 "geodetic_altitude_tolerance_km", 1e3, "km"),
)
_CRITERIA = {c.name: c for c in BOX_CRITERIA}


def acceptance_box(terminal, *, altitude_m: float, mach: float, distance_m: float, velocity_m_s: float = math.nan,
                   flight_path_rad: float = math.nan, alpha_rad: float = math.nan, vertical_speed_m_s: float = math.nan,
                   geodetic_altitude_m: float = math.nan) -> dict:
    """The mission's acceptance box (a scenario's TerminalSpec, paper 000 Table 1) at a final
    point: {criterion: {"error": e, "tolerance": tol, "inside": |e| <= tol}} (SI: m, m/s, rad;
    Mach) for each criterion of ``BOX_CRITERIA`` whose tolerance (and centre) is given:
    'altitude' about terminal.altitude_km (``altitude_m`` in the scenario's datum), 'mach',
    'distance' to the target, 'velocity', 'flight_path', 'alpha', 'vertical_speed' (V sin gamma)
    and 'geodetic_altitude' about their values. The box
    is closed, up to ``ROUNDING`` (the degree-radian conversion's rounding at an edge); a
    criterion whose measured value is not given (nan) is never inside."""
    measured = {"altitude": altitude_m, "mach": mach, "distance": distance_m, "velocity": velocity_m_s,
                "flight_path": flight_path_rad, "alpha": alpha_rad, "vertical_speed": vertical_speed_m_s,
                "geodetic_altitude": geodetic_altitude_m}
    box = {}
    for c in BOX_CRITERIA:
        tol = getattr(terminal, c.tolerance, None)
        centre = 0.0 if c.centre is None else getattr(terminal, c.centre, None)
        if tol is None or centre is None:
            continue
        e, t = float(measured[c.name] - centre * c.si), tol * c.si
        box[c.name] = {"error": e, "tolerance": t, "inside": bool(abs(e) <= t * (1.0 + ROUNDING))}
    return box


def box_text(name: str, b: dict) -> str:
    """One acceptance criterion missed, in words (in the spec's units)."""
    c = _CRITERIA[name]
    unit = f" {c.unit}" if c.unit else ""
    digits = 3 if c.unit in ("km", "") else 2
    return f"error {b['error'] / c.si:+.{digits}f}{unit} outside +-{b['tolerance'] / c.si:g}{unit}"


@dc.dataclass(frozen=True)
class Verdict:
    """The verdict of one flight.

    Attributes:
      success: reached and inside_box and within_limits (and, for a closed loop, the guidance
        was active with finite terminal errors: the caller folds those into ``reached``).
      reached: the flight stopped at its terminal interface.
      inside_box: the final state is inside every acceptance criterion.
      within_limits: every path limit held on every flown sample.
      checks: one LimitCheck per path limit.
      tolerance: the relative path-limit tolerance used.
    """

    success: bool
    reached: bool
    inside_box: bool
    within_limits: bool
    checks: tuple
    tolerance: float

    @property
    def violations(self) -> list[LimitCheck]:
        return [c for c in self.checks if not c.held]

    def violations_text(self) -> str:
        """Each breached limit with its peak, time and margin ('' when every limit held)."""
        return breaches_text(self.checks)

    def margins(self) -> dict:
        """{'margin_<limit>': relative margin} of every checked limit."""
        return {f"margin_{c.limit.name}": c.margin for c in self.checks}


def judge(tr, limits, *, reached: bool, inside_box: bool, tolerance: float = 0.0) -> Verdict:
    """The verdict of flight ``tr`` (a Trajectory): ``limits`` checked on every flown sample
    (log and integrator steps); ``reached`` and ``inside_box`` as the caller measured them."""
    checks = tuple(check_limits(tr.flown_time(), tr.flown, limits, tolerance))
    within = all(c.held for c in checks)
    return Verdict(bool(reached and inside_box and within), bool(reached), bool(inside_box), bool(within), checks,
                   float(tolerance))
