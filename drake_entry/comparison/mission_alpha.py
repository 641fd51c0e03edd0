"""A mission's alpha schedule in time, rewritten in speed for another method by the mission's own
open-loop flight.

FNPEG flies its alpha in speed, drag-energy in normalised energy and SCvx as a law of speed; a
schedule in time (paper 003's Table 2: 42 deg until 58 s, 17.5 deg at 88 s) has no equivalent
before a flight (drake_entry.guidance.derivation.alpha_rewritten refuses it). The comparison
flies the mission's open-loop diagram (its own alpha and bank schedules, the Drake Simulator)
and reads the speed at each breakpoint and at each logged instant between them (a ramp in time
is not a ramp in speed); the rewritten schedule, flown on that same flight,
must give the time schedule's alpha within ALPHA_TOLERANCE_DEG at every logged sample (the
speed must fall through the breakpoints), else the method cannot fly the mission.
"""
from __future__ import annotations

import dataclasses as dc

import numpy as np

from drake_entry.guidance.derivation import CannotFly, Choice

__all__ = ["ALPHA_TOLERANCE_DEG", "alpha_in_speed"]

#: the largest alpha difference [deg] between the time schedule and its rewriting in speed, both
#: flown along the mission's open-loop flight
ALPHA_TOLERANCE_DEG = 0.5


def alpha_in_speed(mission):
    """(``mission`` with its alpha schedule in time rewritten in speed, the Choice that says how),
    or (``mission``, None) when its schedule is not in time or is constant; CannotFly when the
    open-loop flight does not reach the last breakpoint or the rewriting departs from the time
    schedule by more than ALPHA_TOLERANCE_DEG."""
    from drake_entry.diagrams.open_loop import simulate

    s = mission.alpha
    values = [float(v) for v in s.values_deg]
    if s.variable != "time" or len(set(values)) == 1:
        return mission, None
    tr = simulate(mission)
    t, V = np.asarray(tr.time, float), np.asarray(tr.state[:, 3], float)
    if t[-1] < s.breakpoints[-1]:
        raise CannotFly(f"the mission's alpha schedule is in time and its open-loop flight ends at {t[-1]:.0f} s, "
                        f"before the schedule's last breakpoint ({s.breakpoints[-1]:g} s): no speed to rewrite it at")
    # the breakpoints and every logged instant between them: a ramp in time is not a ramp in speed
    inner = t[(t > s.breakpoints[0]) & (t < s.breakpoints[-1])]
    times = np.union1d(np.asarray(s.breakpoints, float), inner)
    speeds, alphas = np.interp(times, t, V), np.interp(times, s.breakpoints, values)
    order = np.argsort(speeds)
    rewritten = dc.replace(s, variable="velocity", breakpoints=[round(float(v), 3) for v in speeds[order]],
                           values_deg=[round(float(a), 4) for a in alphas[order]])
    in_time = np.interp(t, s.breakpoints, values)
    in_speed = np.interp(V, rewritten.breakpoints, rewritten.values_deg)
    worst = int(np.argmax(np.abs(in_speed - in_time)))
    gap = abs(in_speed[worst] - in_time[worst])
    if gap > ALPHA_TOLERANCE_DEG:
        raise CannotFly(f"the mission's alpha schedule is in time, and in speed it departs from itself along the "
                        f"mission's open-loop flight by {gap:.2g} deg at "
                        f"{t[worst]:.0f} s ({V[worst]:.0f} m/s; allowed {ALPHA_TOLERANCE_DEG:g}): its speed does "
                        f"not fall through the breakpoints")
    ends = [(rewritten.breakpoints[i], rewritten.values_deg[i]) for i in (0, -1)]
    text = (f"{len(times)} breakpoints, {ends[1][1]:g} deg at {ends[1][0]:.0f} m/s to {ends[0][1]:g} deg at "
            f"{ends[0][0]:.0f} m/s")
    how = (f"the mission's alpha schedule in time ({', '.join(f'{a:g} deg at {b:g} s' for b, a in zip(s.breakpoints, values))}) "
           f"rewritten in speed at the speeds of the mission's open-loop flight (its own alpha and bank schedules, "
           f"the Drake Simulator) at those times and at each logged instant between them; flown along that flight "
           f"the two agree within {gap:.2g} deg")
    return dc.replace(mission, alpha=rewritten), Choice("alpha", text, how)
