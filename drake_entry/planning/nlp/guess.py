"""Initial guesses for the NLP: a propagated constant-control flight (entry problems) or
the straight line between the boundary values."""
from __future__ import annotations

import math

import numpy as np

from drake_entry.models.geodesy import bearing, central_angle_smooth, crossrange_from_great_circle
from drake_entry.planning.ocp import OptimalControlProblem

__all__ = ["initial_guess", "REVERSAL_TRIGGER_M", "REVERSAL_MIN_TURN", "REVERSAL_STEPS", "GUESS_MAX_STEP_S",
           "GUESS_SAMPLE_STEP_S", "GUESS_MISS_TOL_RAD", "GUESS_LATERAL_TOL_M", "MEET_FINAL_SHARE"]


def initial_guess(problem, samples: int = 200):
    """(t, states, controls) SI: a propagated guess.

    Entry problems: fly a constant angle of attack (alpha-bar, within the bounds, or the
    problem's alpha schedule) and a
    constant bank (within its bounds, turning towards a fixed final position) whose magnitude
    is found by regula falsi (_Bracket) so the flight (with one bank reversal, its time found
    the same way, when the final position is off the initial heading and the constant bank turns past it)
    ends at the final altitude near the final position (or at the fixed/maximum final time),
    with controls at rest; then each state is shifted linearly over the last 5 % of the
    flight to end inside its final bounds, and clipped to the state bounds. The flight ends at
    the final altitude (its lower bound), else in the middle of a terminal geodetic-altitude
    window, else on the ground. Other problems:
    the straight line between the boundary values over the mean final time (free: the
    problem's time scale or 1 s), controls at the middle of their bounds (or zero).
    """
    if isinstance(problem, OptimalControlProblem):
        return _entry_guess(problem, samples)
    return _straight_line_guess(problem, samples)


def _mid(lo, hi, default):
    if np.isfinite(lo) and np.isfinite(hi):
        return 0.5 * (lo + hi)
    if np.isfinite(lo):
        return max(lo, default)
    if np.isfinite(hi):
        return min(hi, default)
    return default


def _straight_line_guess(problem, samples):
    t_lo, t_hi = problem.final_time_bounds
    if np.isfinite(t_hi):
        tf = 0.5 * (t_lo + t_hi)
    elif t_lo > 0:
        tf = 2.0 * t_lo
    else:  # free: the problem's time scale, else 1 s
        tf = problem.scales()[2] or 1.0
    x0l, x0h = problem.boundary_bounds("initial")
    xfl, xfh = problem.boundary_bounds("final")
    xl, xh, ul, uh = problem.bounds_arrays()
    x0 = np.array([_mid(a, b, _mid(c, d, 0.0)) for a, b, c, d in zip(x0l, x0h, xl, xh)])
    xf = np.array([_mid(a, b, x0[i]) for i, (a, b) in enumerate(zip(xfl, xfh))])
    t = np.linspace(0.0, tf, samples)
    X = x0[None, :] + (t / tf)[:, None] * (xf - x0)[None, :]
    U = np.tile([_mid(a, b, 0.0) for a, b in zip(ul, uh)], (samples, 1))
    return t, np.clip(X, xl, xh), U


def _entry_guess(problem: OptimalControlProblem, samples):
    from scipy.integrate import solve_ivp

    x0l, x0h = problem.boundary_bounds("initial")
    if not np.all(np.isfinite(x0l[:6])) or not np.allclose(x0l[:6], x0h[:6]):
        return _straight_line_guess(problem, samples)
    x0 = x0l.copy()
    xl, xh, ul, uh = problem.bounds_arrays()
    xfl, xfh = problem.boundary_bounds("final")
    height = _end_height(problem, xfl)
    layout = problem.controls
    # alpha: scheduled ('bank_rate'), else alpha-bar within its bounds (a state or a control)
    alpha = None if layout == "bank_rate" else float(np.clip(
        problem.alpha_bar, xl[6] if layout == "rates" else ul[0], xh[6] if layout == "rates" else uh[0]))
    bank_where, bank_i = problem.bank_index
    t_lo, t_hi = problem.final_time_bounds
    t_max = t_hi if np.isfinite(t_hi) else 5000.0
    target = None
    if np.isfinite(xfl[1]) and np.isfinite(xfl[2]):
        target = (xfl[1], xfl[2])

    def attitude(y, bank):
        """y with the attitude states at rest (alpha-bar, ``bank``)."""
        y = y.copy()
        if layout == "rates":
            y[6] = alpha
        if bank_where == "state":
            y[bank_i] = bank
        return y

    def bank_at(t, mag, t_rev):
        return side * mag if t < t_rev else -side * mag

    def fly(mag, t_rev=math.inf, max_step=GUESS_MAX_STEP_S):
        """The flight with |bank| = mag towards ``side``, reversed at t_rev [s]."""
        def f(t, y):
            bank = bank_at(t, mag, t_rev)
            u = np.zeros(problem.n_controls) if layout != "direct" else np.array([alpha, bank])
            return problem.dynamics(attitude(y, bank), u)

        def ground(t, y):
            return height(y)
        ground.terminal, ground.direction = True, -1
        return solve_ivp(f, (0.0, t_max), attitude(x0, side * mag), events=ground, rtol=1e-7, atol=1e-9,
                         max_step=max_step)

    def miss(sol):  # flown central angle beyond the target's [rad]
        xf = sol.y[:, -1]
        start = (float(x0[1]), float(x0[2]))
        return central_angle_smooth(*start, float(xf[1]), float(xf[2])) - central_angle_smooth(*start, *target)

    def landed_miss(sol):  # miss(sol) where the flight landed and there is a final position, else None
        return miss(sol) if target is not None and sol.status == 1 else None

    def too_long(sol):  # did not land, or landed beyond the final position
        return sol.status != 1 or (target is not None and miss(sol) > 0)

    def lateral(sol):  # end's distance [m] right of the great circle from the start to the target
        xf = sol.y[:, -1]
        heading = bearing(float(x0[1]), float(x0[2]), *target)
        return float(crossrange_from_great_circle(float(xf[1]), float(xf[2]), float(x0[1]), float(x0[2]), heading,
                                                  problem.planet.reference_radius))

    def range_fit(t_rev, steps):
        """The bank magnitude whose flight lands on the final position's range (more bank =
        shorter flight): (magnitude, flight), the flight never too long; to 1e-4 rad of bank
        or GUESS_MISS_TOL_RAD of central angle. Without a final position: the least bank that
        lands, by bisection."""
        top = max(m_hi, m_lo)
        best = fly(top, t_rev)
        bracket = _Bracket(m_lo, top, None, landed_miss(best))
        for _ in range(steps):
            mid = bracket.trial()
            s = fly(mid, t_rev)
            long, short_by = too_long(s), landed_miss(s)
            bracket.keep(mid, short_by, to_hi=not long)
            if not long:
                best = s  # best is always the flight with bank bracket.hi
                if short_by is not None and -short_by < GUESS_MISS_TOL_RAD:
                    break
            if bracket.hi - bracket.lo < 1e-4:
                break
        return bracket.hi, best

    # a constant bank magnitude fitted to the range (more bank = shorter flight), on the side the
    # bank bounds allow most of
    b_lo, b_hi = (xl[bank_i], xh[bank_i]) if bank_where == "state" else (ul[bank_i], uh[bank_i])
    side, turn = (1.0 if b_hi >= -b_lo else -1.0), 0.0
    if target is not None:  # turn towards the target (bank > 0 turns right) when the bounds allow it
        turn = math.remainder(bearing(float(x0[1]), float(x0[2]), *target) - float(x0[5]), 2.0 * math.pi)
        if abs(turn) > 1e-6 and (b_hi if turn > 0 else -b_lo) > 0:
            side = math.copysign(1.0, turn)
    m_lo = max(0.0, side * (b_lo if side > 0 else b_hi))
    m_hi = min(math.radians(89.0), side * (b_hi if side > 0 else b_lo))
    hi, best = range_fit(math.inf, 25)
    t_rev = math.inf
    # the constant bank turned past the target: one reversal, its time by regula falsi on the
    # end's lateral distance (earlier = less turn), the magnitude fitted to the range at each (both signs within the bounds)
    reversible = b_lo <= -m_hi and m_hi <= b_hi
    if (target is not None and reversible and abs(turn) > REVERSAL_MIN_TURN and best.status == 1
            and side * lateral(best) > REVERSAL_TRIGGER_M):
        times = _Bracket(0.0, float(best.t[-1]), None, side * lateral(best))  # reversal at t=0 not flown
        for _ in range(REVERSAL_STEPS):
            mid = times.trial()
            m, s = range_fit(mid, 12)
            if s.status == 1 and abs(lateral(s)) < abs(lateral(best)):
                hi, best, t_rev = m, s, mid
            beyond = None if s.status != 1 else side * lateral(s)  # > 0: reverse earlier
            times.keep(mid, beyond, to_hi=beyond is not None and beyond > 0)
            if abs(lateral(best)) < GUESS_LATERAL_TOL_M:
                break
    # the samples: the chosen flight again in steps of at most GUESS_SAMPLE_STEP_S, interpolated
    # linearly (the search's longer steps sampled from the dense output change the guess within
    # the integration tolerance, and SNOPT at 1e-8 on Betts' heating-limited shuttle then stops
    # at info 3 where it converged from this guess)
    best = fly(hi, t_rev, GUESS_SAMPLE_STEP_S)
    t = np.linspace(0.0, best.t[-1], samples)
    from scipy.interpolate import interp1d

    X = interp1d(best.t, best.y, axis=1)(t).T
    bank = np.array([bank_at(tk, hi, t_rev) for tk in t])
    if bank_where == "state":
        X[:, bank_i] = bank
    if layout != "direct":
        U = np.zeros((samples, problem.n_controls))
    else:
        U = np.column_stack([np.full(samples, alpha), bank])
    if t[-1] < t_lo or t[-1] > t_hi:  # stretch to the allowed final time
        t = t * np.clip(t[-1], t_lo, t_hi) / t[-1]
    return t, _meet_final(problem, t, X), U


def _end_height(problem: OptimalControlProblem, xfl):
    """y -> height [m] above where the guess ends: the final altitude's lower bound, else the
    middle of a terminal geodetic-altitude window, else the surface (state altitude 0)."""
    h = problem.final.get("h")
    if h is not None and np.isfinite(xfl[0]):  # a final altitude given (not only the state bound)
        return lambda y: y[0] - xfl[0]
    for c in problem.terminal:
        if c.quantity == "geodetic_altitude":
            lo, hi = c.min, c.max
            end = 0.5 * (lo + hi) if np.isfinite(lo) and np.isfinite(hi) else (lo if np.isfinite(lo) else hi)
            return lambda y: problem.planet.atmospheric_altitude(y[0], y[2]) - end
    return lambda y: y[0]


#: a constant-bank guess towards a final position off the initial heading (by more than
#: REVERSAL_MIN_TURN) that ends farther than REVERSAL_TRIGGER_M [m] past it gets one bank
#: reversal (SHEFEX-3 towards 68.10 N: the constant bank ends 221 km off and the cold NLP solve
#: takes 85 s at J = 37.1; with the reversal it ends on the target, 3.4 s, J = 20.8). A final
#: position straight ahead (MARV) keeps its constant bank.
REVERSAL_TRIGGER_M = 10e3
REVERSAL_MIN_TURN = math.radians(1.0)
REVERSAL_STEPS = 12
#: the search flights' step cap [s] (catches a dip through the end height between steps; at
#: 20 s RK45 takes two thirds of the derivatives of 5-s steps), the sampled flight's [s], and
#: the range fit's stop: the flight lands within this central angle short of the final
#: position [rad] (1e-6 rad is 6.4 m on Earth)
GUESS_MAX_STEP_S = 20.0
GUESS_SAMPLE_STEP_S = 5.0
GUESS_MISS_TOL_RAD = 1e-6
#: the reversal time's stop: the flight ends within this distance of the great circle to the
#: final position [m]
GUESS_LATERAL_TOL_M = 50.0


class _Bracket:
    """[lo, hi] around the root of a monotone function, its values f_lo, f_hi where known
    (None: not flown, or no value there). The next trial: regula falsi with the Illinois
    modification (Dowell & Jarratt 1971: the end kept twice in a row has its value halved)
    once both are known, bisection before."""

    def __init__(self, lo: float, hi: float, f_lo: float | None = None, f_hi: float | None = None):
        self.lo, self.hi, self.f_lo, self.f_hi = lo, hi, f_lo, f_hi
        self._last = 0  # +1: the last trial replaced hi, -1: lo

    def trial(self) -> float:
        if self.f_lo is not None and self.f_hi is not None and self.f_lo != self.f_hi:
            x = self.hi - self.f_hi * (self.hi - self.lo) / (self.f_hi - self.f_lo)
            if self.lo < x < self.hi:
                return x
        return 0.5 * (self.lo + self.hi)

    def keep(self, x: float, fx: float | None, to_hi: bool):
        """x (its value fx) replaces hi when ``to_hi``, else lo."""
        if to_hi:
            if self._last == 1 and self.f_lo is not None:
                self.f_lo *= 0.5
            self.hi, self.f_hi, self._last = x, fx, 1
        else:
            if self._last == -1 and self.f_hi is not None:
                self.f_hi *= 0.5
            self.lo, self.f_lo, self._last = x, fx, -1

#: the share of the guess's flight over which its states are shifted to the final conditions
MEET_FINAL_SHARE = 0.05


def _meet_final(problem, t, X):
    """Shift each state linearly over the last ``MEET_FINAL_SHARE`` of the flight so it ends
    inside its final bounds (the flight keeps its shape before), then clip to the state bounds.
    A ramp over the whole flight bent MARV's alpha and gamma from the start and led SNOPT to
    other local optima (60 nodes: J = 96.5 instead of 17.66); over the last 5 % MARV's solutions
    at 24/40/60 nodes are those of the unshifted guess (J = 39.73/18.78/17.66), over the last
    10 % or 20 % SNOPT stops at 24 or 40 nodes with info 3."""
    xfl, xfh = problem.boundary_bounds("final")
    xl, xh, _, _ = problem.bounds_arrays()
    X = X.copy()
    share = (t - t[0]) / (t[-1] - t[0])
    ramp = np.clip((share - (1.0 - MEET_FINAL_SHARE)) / MEET_FINAL_SHARE, 0.0, 1.0)
    for i in range(X.shape[1]):
        end = float(np.clip(X[-1, i], xfl[i], xfh[i]))
        X[:, i] += ramp * (end - X[-1, i])
    return np.clip(X, xl, xh)
