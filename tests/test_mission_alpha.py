"""A mission's alpha schedule in time rewritten in speed by its open-loop flight
(drake_entry.comparison.mission_alpha), as the comparison hands it to another method."""
import dataclasses as dc

import numpy as np
import pytest

from drake_entry.comparison.mission_alpha import ALPHA_TOLERANCE_DEG, alpha_in_speed
from drake_entry.guidance.derivation import CannotFly
from drake_entry.scenario import load_scenario


def test_shefex3s_table_2_law_in_speed_gives_the_same_alpha_along_the_open_loop_flight():
    """Paper 003's Table 2 (42 deg until 58 s, 17.5 deg at 88 s) in speed: the speeds of the
    open-loop flight at 58 and 88 s bound the ramp, the ends keep their values, and flown along
    that same flight the speed schedule gives the time schedule's alpha at every logged instant."""
    from drake_entry.diagrams.open_loop import simulate

    shefex = load_scenario("shefex3_ampi")
    rewritten, choice = alpha_in_speed(shefex)
    a = rewritten.alpha
    assert a.variable == "velocity" and np.all(np.diff(a.breakpoints) > 0)
    tr = simulate(shefex)
    t, V = tr.time, tr.state[:, 3]
    assert a.breakpoints[0] == pytest.approx(np.interp(88.0, t, V), abs=1e-3)
    assert a.breakpoints[-1] == pytest.approx(np.interp(58.0, t, V), abs=1e-3)
    assert (a.values_deg[0], a.values_deg[-1]) == (17.5, 42.0)
    in_time = np.interp(t, [58.0, 88.0], [42.0, 17.5])
    assert np.max(np.abs(np.interp(V, a.breakpoints, a.values_deg) - in_time)) < ALPHA_TOLERANCE_DEG
    # the two ends alone (a ramp in time is not one in speed) depart by degrees mid-ramp
    ends = np.interp(V, [a.breakpoints[0], a.breakpoints[-1]], [17.5, 42.0])
    assert np.max(np.abs(ends - in_time)) > 2.0
    assert choice.field == "alpha" and "open-loop flight" in choice.how and "42 deg at 58 s" in choice.how
    assert shefex.alpha.variable == "time"  # the mission itself is left as it is


def test_a_schedule_not_in_time_or_constant_is_left_and_one_past_the_flight_is_refused():
    horus = load_scenario("horus2b")  # in normalised energy
    assert alpha_in_speed(horus) == (horus, None)
    p4 = load_scenario("cav_h_paper004")  # constant, in time
    assert alpha_in_speed(p4)[1] is None
    shefex = load_scenario("shefex3_ampi")
    late = dc.replace(shefex, alpha=dc.replace(shefex.alpha, breakpoints=[58.0, 5000.0]))
    with pytest.raises(CannotFly, match="open-loop flight ends at .* before the schedule's last breakpoint"):
        alpha_in_speed(late)


def test_another_method_derives_from_the_rewritten_mission_and_the_own_method_from_the_mission():
    """FNPEG needs its alpha in speed: on SHEFEX-3 it now derives (the rewriting is its first
    choice), where the mission itself is refused; AMPI, the mission's own method, sees the
    mission as it is."""
    from drake_entry.comparison.runner import _derivation
    from drake_entry.comparison.spec import ComparedMethod
    from drake_entry.guidance.fnpeg.spec import Fnpeg

    shefex = load_scenario("shefex3_ampi")
    seen, derivation = _derivation(shefex, ComparedMethod(label="fnpeg", method="Fnpeg"))
    assert isinstance(derivation.spec, Fnpeg) and derivation.choices[0].field == "alpha"
    assert seen.alpha.variable == "velocity" and derivation.spec.alpha_deg[0] == pytest.approx(17.5)
    own, ampi = _derivation(shefex, ComparedMethod(label="ampi", method="Ampi"))
    assert own is shefex and all(c.field != "alpha" for c in ampi.choices)
