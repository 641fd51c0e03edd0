"""Paper 004's guidance law, the pieces a trajectory evaluation applies at every guidance step:
the bank magnitude linear in energy (eq. 17), the quasi-equilibrium-glide compensation
(eqs. 46-48, eq. 47 corrected), and the angle of attack derived from the path constraints
(load factor, eq. 31; heat rate, eq. 21).

Units: the paper works in Lu's nondimensional units (r in R0, V in sqrt(g0 R0), time in
sqrt(R0/g0), accelerations in g0, mu = 1); its gains (k2 = 10, beta = 920) are defined there,
so the QEG functions take nondimensional arguments. The alpha functions are SI. Everything
is vectorised over numpy arrays (a population of trajectories).
"""
from __future__ import annotations

import dataclasses as dc
import math

import numpy as np

from drake_entry.errors import ScenarioError
from drake_entry.guidance.path_feedback import PathLimits, corrected_cos_bank, path_limit_correction
from drake_entry.models.scalar import clamp
from drake_entry.models.schedules import linear_bank

__all__ = ["equilibrium_glide_radius", "qeg_sin_flight_path", "qeg_bank", "SOLVE_RTOL", "SOLVE_MAX_ITERATIONS",
           "load_coefficient_target", "heat_drag_target", "alpha_for_load_factor", "alpha_for_heat_rate",
           "LawMemory", "LawSettings", "law_commands", "bank_magnitude", "scheduled_alpha"]


def equilibrium_glide_radius(V, lift_coefficient_term, beta: float):
    """r_eq(V) of paper 004 eq. 46, nondimensional: the radius where lift balances gravity
    less centrifugal acceleration in an exponential atmosphere rho0 exp(-beta (r - 1)):
    r_eq = 1 + ln(c V^2 / (1 - V^2)) / beta, with c = V_scale^2 rho0 S C_L / (2 m g0)
    (``lift_coefficient_term``)."""
    V = np.asarray(V, float)
    return 1.0 + np.log(lift_coefficient_term * V * V / (1.0 - V * V)) / beta


def qeg_sin_flight_path(r, V, D, beta: float):
    """sin(gamma_QEGC), nondimensional (paper 004 eq. 47, corrected).

    Equating dr/dV of the dynamics (dr/dt = V sin gamma, dV/dt = -D - sin gamma / r^2) with
    d r_eq/dV = 2 / (beta V (1 - V^2)) from eq. 46 gives
    sin gamma = -2 D / (beta V^2 (1 - V^2) + 2 / r^2).
    The paper prints -D / (beta V^3 (1 - V^2) + 1/r^2), which is off by x0.56 to x1.25
    (docs/methods/swarm-bank.md); tests check this form against eq. 46's derivative."""
    return -2.0 * D / (beta * V * V * (1.0 - V * V) + 2.0 / (r * r))


def qeg_bank(sigma_base, L, D, sin_gamma, sin_gamma_qeg, k2: float):
    """|sigma_cmd| [rad] of paper 004 eq. 48, nondimensional L and D:
    L cos(sigma_cmd) = L cos(sigma_base) - k2 (dr/de - dr_QEGC/de), with dr/de = sin gamma / D
    (eq. 11: de/dt = D V). Climbing faster than the glide (dr/de above) lowers the vertical
    lift. cos(sigma_cmd) is clipped to [-1, 1] (the compensation saturates)."""
    drde = (sin_gamma - sin_gamma_qeg) / D
    c = np.cos(sigma_base) - k2 * drde / L
    return np.arccos(clamp(c, -1.0, 1.0))


#: the alpha laws' root finder: relative tolerance on the target, most iterations
SOLVE_RTOL, SOLVE_MAX_ITERATIONS = 1e-13, 60


def load_coefficient_target(dynamic_pressure, area_over_mass: float, g0: float, load_max: float):
    """sqrt(C_L^2 + C_D^2) at which the total aerodynamic load is ``load_max`` [g] (eq. 31:
    q S sqrt(C_L^2 + C_D^2) / (m g0) = a_max). Any scalar type or numpy arrays."""
    return load_max * g0 / (dynamic_pressure * area_over_mass)


def heat_drag_target(drag_coefficient_previous, heat_ratio):
    """C_DQ of eq. 21: C_D(alpha_previous) (Qdot / Qdot_max)^2 (alpha_for_heat_rate)."""
    return drag_coefficient_previous * heat_ratio * heat_ratio


def _solve_increasing(f, target, lo: float, hi: float, rtol: float = SOLVE_RTOL,
                      max_iterations: int = SOLVE_MAX_ITERATIONS):
    """x in [lo, hi] with f(x) = target for f increasing in x, vectorised: the Illinois
    variant of false position (superlinear; about 8 evaluations instead of bisection's 40).
    Targets outside [f(lo), f(hi)] give the bound (the constraint cannot be met exactly:
    saturate)."""
    target = np.asarray(target, float)
    a, b = np.full(target.shape, lo), np.full(target.shape, hi)
    fa, fb = f(a) - target, f(b) - target
    x = np.where(fa >= 0.0, a, b)  # saturated answers; the bracketed ones are refined below
    inside = (fa < 0.0) & (fb > 0.0)
    side = np.zeros(target.shape)
    tol = rtol * np.maximum(np.abs(target), 1.0)
    for _ in range(max_iterations):
        if not inside.any():
            break
        xi = np.where(inside, b - fb * (b - a) / np.where(inside, fb - fa, 1.0), x)
        fx = np.where(inside, f(xi) - target, 0.0)
        upper = inside & (fx > 0.0)  # the root is left of xi: xi becomes b
        lower = inside & (fx <= 0.0)
        fa = np.where(upper & (side == -1), 0.5 * fa, fa)  # Illinois: halve the stale end
        fb = np.where(lower & (side == 1), 0.5 * fb, fb)
        b, fb = np.where(upper, xi, b), np.where(upper, fx, fb)
        a, fa = np.where(lower, xi, a), np.where(lower, fx, fa)
        side = np.where(upper, -1.0, np.where(lower, 1.0, side))
        x = np.where(inside, xi, x)
        inside = inside & (np.abs(fx) > tol) & (b - a > 1e-15)
    return x


def _check_bounds(lo: float, hi: float):
    if not lo < hi:
        raise ScenarioError(f"alpha bounds [{lo}, {hi}] rad need lower < upper")


def alpha_for_load_factor(dynamic_pressure, mach, aero, area_over_mass: float, g0: float, load_max: float,
                          lo: float, hi: float):
    """alpha [rad] in [lo, hi] at which the total aerodynamic load equals ``load_max`` [g]
    (paper 004 eq. 31: q S sqrt(C_L^2 + C_D^2) / (m g0) = a_max), for each (q [Pa], Mach).
    Assumes sqrt(C_L^2 + C_D^2) increases with alpha on [lo, hi] (true of the CAV-H fit for
    alpha > 0); where a_max cannot be reached the nearest bound is returned."""
    _check_bounds(lo, hi)
    q, mach = np.broadcast_arrays(np.asarray(dynamic_pressure, float), np.asarray(mach, float))

    def coefficient(alpha):
        cl, cd = aero.coefficients(alpha, mach)
        return np.hypot(cl, cd)

    return _solve_increasing(coefficient, load_coefficient_target(q, area_over_mass, g0, load_max), lo, hi)


def alpha_for_heat_rate(alpha_previous, heat_ratio, mach, aero, lo: float, hi: float):
    """alpha_Q [rad] of paper 004 eq. 21, one guidance step: the drag coefficient that keeps
    the heat rate at its limit is C_DQ = C_D(alpha_previous) rho / rho_Q, and rho / rho_Q =
    (Qdot / Qdot_max)^2 (eq. 13), so C_DQ = C_D(alpha_previous) * heat_ratio^2 with
    heat_ratio = Qdot / Qdot_max; then C_D(alpha_Q, M) = C_DQ is solved on [lo, hi]. The
    equation is a recursion on the previous alpha with gain heat_ratio^2 per step, so its
    result depends on the guidance step (document it with the scenario)."""
    _check_bounds(lo, hi)
    a_prev, ratio, mach = np.broadcast_arrays(*(np.asarray(v, float) for v in (alpha_previous, heat_ratio, mach)))
    target = heat_drag_target(aero.coefficients(a_prev, mach)[1], ratio)
    return _solve_increasing(lambda alpha: aero.coefficients(alpha, mach)[1], target, lo, hi)


@dc.dataclass
class LawMemory:
    """What the alpha law remembers between guidance steps (arrays over a population).

    Attributes:
      alpha_command: the previous alpha command [rad] (the eq. 21 recursion runs on it).
      mach_was_above: Mach has exceeded Mach_shift (Case 2).
      switched: Case 2 has switched to the load-factor law for good (Mach fell below Mach_shift
        after exceeding it; latched, so a climb back above Mach_shift does not switch back).
    """

    alpha_command: np.ndarray
    mach_was_above: np.ndarray
    switched: np.ndarray

    @staticmethod
    def start(alpha_command, n: int, *, was_above: bool = False, switched: bool = False) -> "LawMemory":
        return LawMemory(np.full(n, float(alpha_command)), np.full(n, bool(was_above)), np.full(n, bool(switched)))


@dc.dataclass(frozen=True)
class LawSettings:
    """The constants of paper 004's law (SI, rad). sigma_f: eq. 17's terminal bank;
    e0, ef: eq. 17's energies [J/kg] (e = mu/r - V^2/2); bank_limit; alpha_min, alpha_max;
    load_max [g], heat_max [W/m^2]; case 'load' (Case 1), 'heat' (Case 2) or 'schedule'; mach_shift;
    k2, beta: eqs. 46-48 (nondimensional); R0 [m], g0 [m/s^2]: Lu's units; mu [m^3/s^2];
    alpha_speeds [m/s] (increasing), alpha_values [rad]: the 'schedule' case's alpha, linear
    in speed and held beyond its ends; path: Lu 2014's path-limit feedback on the bank
    (guidance.path_feedback; None or a zero gain: paper 004's law, which holds its limits with alpha)."""

    sigma_f: float
    e0: float
    ef: float
    bank_limit: float
    alpha_min: float
    alpha_max: float
    load_max: float
    heat_max: float
    case: str
    mach_shift: float
    k2: float
    beta: float
    R0: float
    g0: float
    mu: float
    alpha_speeds: tuple = ()
    alpha_values: tuple = ()
    path: PathLimits | None = None


def scheduled_alpha(speed, speeds, values):
    """alpha [rad] of the 'schedule' case at speed [m/s]: linear between the breakpoints
    ``speeds`` (increasing) and held beyond their ends."""
    return np.interp(speed, speeds, values)


def law_commands(s: LawSettings, sigma0, x, r, rho, mach, L, D, heat, q, aero, area_over_mass: float,
                 memory: LawMemory, sigma_f=None):
    """One guidance step of paper 004's law for a population: (|sigma| [rad], alpha command
    [rad], the next LawMemory).

    x: states (6, n) [h, lon, lat, V, gamma, psi]; r: radii [m]; rho, mach, L, D [m/s^2],
    heat [W/m^2], q [Pa]: the air data and aerodynamic accelerations at the step (n,).
    |sigma|: eq. 17 (linear in e from sigma0) with the QEG compensation (eqs. 46-48), limited
    to bank_limit. alpha: eq. 31 (Case 1); Case 2: eq. 21 until Mach has fallen below
    Mach_shift after exceeding it, then eq. 31; 'schedule': the mission's alpha in speed (the
    law flown with another method's alpha profile). ``sigma_f``: per-member eq. 17 end banks
    (default: the settings')."""
    magnitude = bank_magnitude(s, sigma0, x[3], x[4], r, L, D, s.sigma_f if sigma_f is None else sigma_f,
                               heat=heat, q=q)
    if s.case == "schedule":
        alpha = scheduled_alpha(np.asarray(x[3], float), s.alpha_speeds, s.alpha_values)
        return magnitude, alpha, LawMemory(alpha, memory.mach_was_above, memory.switched)
    alpha = alpha_for_load_factor(q, mach, aero, area_over_mass, s.g0, s.load_max, s.alpha_min, s.alpha_max)
    above, switched = memory.mach_was_above, memory.switched
    if s.case == "heat":
        above = above | (mach > s.mach_shift)
        switched = switched | (above & (mach <= s.mach_shift))
        heat_alpha = alpha_for_heat_rate(memory.alpha_command, heat / s.heat_max, mach, aero, s.alpha_min, s.alpha_max)
        alpha = np.where(switched, alpha, heat_alpha)
    return magnitude, alpha, LawMemory(alpha, above, switched)


def bank_magnitude(s: LawSettings, sigma0, V, gamma, r, L, D, sigma_f, e0=None, ef=None, heat=None, q=None):
    """|sigma| [rad] of eq. 17 (linear in e from sigma0 at e0 to sigma_f at ef; default the
    settings' energies) with the QEG compensation (eqs. 46-48) and, with ``s.path``, Lu 2014's
    path-limit feedback (cos(sigma) lowered by its term sqrt(g0/R0) / L: more vertical lift where
    the load, heat rate or q would pass their limits ``horizon`` seconds ahead), limited to
    bank_limit, at speed V [m/s], flight-path angle gamma [rad], radius r [m], lift and drag L, D
    [m/s^2], heat rate [W/m^2] and q [Pa]. Any scalar type or numpy arrays (the compiled
    population flight traces it)."""
    e = s.mu / r - 0.5 * V * V
    base = linear_bank(e, s.e0 if e0 is None else e0, s.ef if ef is None else ef, sigma0, sigma_f)
    v_scale = math.sqrt(s.g0 * s.R0)
    s_qeg = qeg_sin_flight_path(r / s.R0, V / v_scale, D / s.g0, s.beta)
    sin_gamma = np.sin(gamma)
    magnitude = qeg_bank(base, L / s.g0, D / s.g0, sin_gamma, s_qeg, s.k2)
    if s.path is not None and s.path.active:
        term = path_limit_correction(V, sin_gamma, D, np.sqrt(L * L + D * D), heat, q, s.path)
        magnitude = np.arccos(clamp(corrected_cos_bank(np.cos(magnitude), term, L, s.R0, s.g0), -1.0, 1.0))
    return clamp(magnitude, -math.inf, s.bank_limit)
