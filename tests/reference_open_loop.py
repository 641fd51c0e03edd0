"""Independent integration of a scenario's open-loop flight with scipy.integrate.solve_ivp.

Same equations (drake_entry.models.dynamics), same schedules and actuator law, no Drake: the
reference the Drake open-loop diagram is checked and benchmarked against.
"""
from __future__ import annotations

import time

import numpy as np
from scipy.integrate import solve_ivp

from drake_entry.errors import ScenarioError
from drake_entry.models.actuator import actuator_rates
from drake_entry.models.dynamics import specific_energy, state_derivatives
from drake_entry.scenario import Scenario


def solve_ivp_open_loop(scenario: Scenario, t_final: float, *, method: str = "DOP853", rtol: float = 1e-10,
                        atol: float | None = None, bandwidth: float = 2.0):
    """Integrate [x(6), sigma, sigma_dot] from the entry interface to t_final [s].

    Time- and energy-scheduled commands. Returns (solution, wall time [s]).
    """
    vehicle, planet, atm = scenario.make_vehicle(), scenario.make_planet(), scenario.make_atmosphere()
    alpha_s, bank_s = scenario.schedule("alpha"), scenario.schedule("bank")
    for which, sch in (("alpha", alpha_s), ("bank", bank_s)):
        if sch.variable not in ("time", "energy"):
            raise ScenarioError(f"solve_ivp_open_loop supports time and energy schedules only ({which} is "
                             f"'{sch.variable}')")

    def command(sch, t, y):
        return sch(t) if sch.variable == "time" else sch(specific_energy(y, planet))
    lim = dict(lower=-vehicle.bank_limit, upper=vehicle.bank_limit, rate_limit=vehicle.bank_rate_limit,
               accel_limit=vehicle.bank_accel_limit, bandwidth=bandwidth)

    def rhs(t, y):
        xdot = state_derivatives(y[:6], y[6], command(alpha_s, t, y), vehicle, planet, atm)
        s_dot, s_ddot = actuator_rates(y[6], y[7], command(bank_s, t, y), **lim)
        return np.append(xdot, (s_dot, s_ddot))

    x0 = scenario.initial_state()
    y0 = np.append(x0, (command(bank_s, 0.0, x0), 0.0))
    # absolute tolerances scaled to each state's size (m, rad, m/s, rad)
    scale = np.array([1e5, 1.0, 1.0, 1e4, 1.0, 1.0, 1.0, 1.0])
    atol = rtol * scale if atol is None else atol
    t0 = time.perf_counter()
    sol = solve_ivp(rhs, (0.0, t_final), y0, method=method, rtol=rtol, atol=atol, dense_output=False)
    return sol, time.perf_counter() - t0
