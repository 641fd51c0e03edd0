"""Initial guess of the SCvx entry planner: a quasi-equilibrium glide flown with the real
bank (paper 001 Sec. IV.A).

The bank magnitude gives the vertical lift of a constant reference bank sigma_g (the
quasi-equilibrium glide condition of eq. 30, with cos(sigma) where the paper prints sin(sigma),
holds along the glide it flies), with a proportional flight-path feedback that damps the
phugoid:

    L cos(sigma) = L cos(sigma_g) - k_gamma V gamma        (clipped to the bank limits),

its sign reverses when the heading error to the site leaves a deadband, and the angle of
attack follows the mission's alpha(V) law. The trajectory is propagated (scipy DOP853 on the
project's equations of motion) to the middle of the DRS altitude window, and sigma_g is
chosen to end as close to the site as the law can.
"""
from __future__ import annotations

import dataclasses as dc
import math

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import minimize_scalar

from drake_entry.errors import ScenarioError
from drake_entry.guidance.scvx.mission import ScvxMission
from drake_entry.models import geodesy
from drake_entry.models.atmosphere import Atmosphere
from drake_entry.models.dynamics import aero_accelerations, air_data, equations_of_motion
from drake_entry.models.planet import Earth
from drake_entry.models.vehicles import Vehicle

__all__ = ["GlideGuess", "glide_bank_magnitude", "heading_error", "reversal_deadband", "propagate_glide",
           "glide_guess"]


@dc.dataclass(frozen=True)
class GlideGuess:
    """A propagated guess: times [s], states (n, 6), bank [rad] at those times, the
    reference bank sigma_g [rad], the distance of its end from the site [m], whether it
    reached the middle of the DRS altitude window (it may stop earlier by speed or time), and
    the angle of attack [rad] at those times where the guess has its own (a re-plan's, from the
    previous plan; None: the mission's alpha(V) schedule)."""

    time: np.ndarray
    states: np.ndarray
    bank: np.ndarray
    reference_bank: float
    miss: float
    reached_drs_altitude: bool
    alpha: np.ndarray | None = None

    @property
    def final_time(self) -> float:
        return float(self.time[-1])


def glide_bank_magnitude(x, L: float, reference_bank: float, mission: ScvxMission, vehicle: Vehicle,
                         gain: float = 0.005) -> float:
    """|bank| [rad] of the damped glide law (module doc) at state x with lift L [m/s^2]."""
    c_min, c_max = math.cos(vehicle.bank_limit), math.cos(math.radians(mission.bank_min_deg))
    cos_sigma = math.cos(reference_bank) - gain * x[3] * x[4] / max(L, 1e-6)
    return math.acos(min(max(cos_sigma, c_min), c_max))


def heading_error(x, site) -> float:
    """Bearing of the site minus the heading [rad], in (-pi, pi] (positive: site to the right)."""
    return (geodesy.bearing(x[1], x[2], site[0], site[1]) - x[5] + math.pi) % (2 * math.pi) - math.pi


def reversal_deadband(distance: float) -> float:
    """Heading-error deadband [rad] of the bank reversals: 10 deg far out, 2 deg near the site."""
    return math.radians(2.0 + 8.0 * min(1.0, distance / 5e6))


def propagate_glide(reference_bank: float, vehicle: Vehicle, planet: Earth, atmosphere: Atmosphere,
                    mission: ScvxMission, *, max_time: float = 6000.0, rtol: float = 1e-8) -> GlideGuess:
    """Fly the glide law from the entry interface to the middle of the DRS altitude window.
    The bank sign reverses when the heading error to the site leaves the deadband (one
    integration arc per reversal, so the integrator never steps over a switch)."""
    site = mission.site(planet)
    alpha = mission.alpha_schedule()
    h_stop = 0.5 * (mission.final_altitude_m[0] + mission.final_altitude_m[1])

    def bank_at(x, sign):
        rho, a = air_data(x, planet, atmosphere)
        _, L, D = aero_accelerations(x, alpha(float(x[3])), rho, a, vehicle)
        return sign * glide_bank_magnitude(x, L, reference_bank, mission, vehicle), L, D

    def reached(t, x, sign):
        return planet.atmospheric_altitude(x[0], x[2]) - h_stop
    reached.terminal, reached.direction = True, -1.0

    def too_slow(t, x, sign):
        return x[3] - 50.0
    too_slow.terminal = True

    def reverse(t, x, sign):
        distance = planet.great_circle_distance(x[1], x[2], *site)
        if distance < 50e3:  # over the site the bearing swings: hold the bank side
            return 1.0
        return sign * heading_error(x, site) + reversal_deadband(distance)
    reverse.terminal, reverse.direction = True, -1.0

    def rhs(t, x, sign):
        sigma, L, D = bank_at(x, sign)
        return equations_of_motion(list(x), sigma, L, D, planet)

    x = mission.entry_state(planet)
    atol = rtol * np.array([1e4, 1.0, 1.0, 1e3, 1.0, 1.0])
    sign = 1.0 if heading_error(x, site) >= 0.0 else -1.0
    times, states, banks = [np.zeros(1)], [x[None, :]], [np.array([bank_at(x, sign)[0]])]
    t, reached_stop = 0.0, False
    for _ in range(1000):
        sol = solve_ivp(rhs, (t, max_time), x, method="DOP853", rtol=rtol, atol=atol, args=(sign,),
                        events=(reached, too_slow, reverse))
        if sol.status == -1:
            raise ScenarioError(f"the glide guess failed to integrate (reference bank "
                                f"{math.degrees(reference_bank):.1f} deg): {sol.message}")
        times.append(sol.t[1:])
        states.append(sol.y.T[1:])
        banks.append(np.array([bank_at(xk, sign)[0] for xk in sol.y.T[1:]]))
        t, x = sol.t[-1], sol.y[:, -1]
        reached_stop = bool(sol.t_events[0].size)
        if sol.status == 0 or reached_stop or sol.t_events[1].size:
            break
        sign = -sign
    T, X, bank = np.concatenate(times), np.concatenate(states), np.concatenate(banks)
    xf = X[-1]
    return GlideGuess(T, X, bank, reference_bank, planet.great_circle_distance(xf[1], xf[2], *site), reached_stop)


def glide_guess(vehicle: Vehicle, planet: Earth, atmosphere: Atmosphere, mission: ScvxMission, *,
                scan: int = 10, bank_tolerance: float = 1e-3) -> GlideGuess:
    """The glide guess whose reference bank ends closest to the site: a scan of sigma_g over
    [bank_min, 85 deg], then scipy's bounded Brent search between the best point's
    neighbours to ``bank_tolerance`` [rad]. The miss need not be zero (near maximum range the
    lateral and longitudinal demands compete): the SCvx virtual controls and the buffered
    site cone absorb it, and ``GlideGuess.miss`` says how far."""
    lo, hi = math.radians(mission.bank_min_deg) + 1e-3, min(vehicle.bank_limit, math.radians(85.0))
    grid = np.linspace(lo, hi, scan)
    tried = [propagate_glide(b, vehicle, planet, atmosphere, mission) for b in grid]
    k = int(np.argmin([g.miss for g in tried]))

    def miss(bank):
        tried.append(propagate_glide(float(bank), vehicle, planet, atmosphere, mission))
        return tried[-1].miss

    minimize_scalar(miss, bounds=(grid[max(k - 1, 0)], grid[min(k + 1, scan - 1)]), method="bounded",
                    options={"xatol": bank_tolerance})
    return min(tried, key=lambda g: g.miss)
