"""SCvx's settings from a mission (drake_entry.guidance.derivation): paper 001's DRS box posed on
the mission's acceptance box. The plan ends at the altitude where the flight stops (the box's
centre, then other altitudes in the box: a search), inside the middle of the box's Mach window
(from its speed window where it gives one), within half the box's distance tolerance of the
site (a design margin); its alpha is the mission's alpha rewritten in speed, its heading bounds
half a turn either side of the entry heading; it bounds the vehicle's heat flux, whichever load
the vehicle limits and its dynamic pressure, and is re-planned on board as paper 001's own
scenario is. A mission whose box gives no altitude window or no distance cannot be posed:
CannotFly."""
import math

from drake_entry.guidance.derivation import (
    ALTITUDE_WHY,
    FINAL_DESCENT_DEG,
    FORCE_SIGMAS,
    LIMIT_MARGIN,
    CannotFly,
    Choice,
    Derivation,
    SearchStep,
    alpha_actuator,
    alpha_rewritten,
    box_mach_window,
    interface_altitudes,
    load_limit_speed,
    q_limit_speed,
    terminal_interface,
)
from drake_entry.guidance.scvx.mission import alpha_law
from drake_entry.guidance.scvx.spec import Scvx
from drake_entry.models.constraints import equilibrium_glide_lift
from drake_entry.models.dispersions import force_dispersions, force_ratio_high

__all__ = ["derive", "SITE_RADIUS_FRACTION", "MACH_WINDOW_FRACTION", "AIM_WINDOW_KM", "AIM_TOLERANCE_KM",
           "FEEDBACK", "REPLAN_PERIOD_S", "REPLAN_TIME_TO_GO_FRACTION", "REPLAN_MIN_TIME_TO_GO_S", "FLOWN_MACH_SLACK",
           "GLIDE_AIM_TOLERANCE_KM", "glides_at", "INTERFACE_SPEED_WINDOW", "FLIGHT_PATH_BOUNDS_DEG", "OBJECTIVE", "FORMULATION", "aim_window",
           "MAX_ITERATIONS"]

#: the plan's objective and formulation on another method's mission: the control effort (the
#: integral of |sigma_dot|), with the bank a state and alpha the mission's law. Measured on
#: HORUS-2B's nominal with the dynamic-pressure bound (plans of 21-42 iterations, 2.5-3.5 s), the
#: controls of each objective's plan flown open loop (no feedback) end this far from its end:
#: control effort 0.5 km; miss 27 km (its bank chatters between nodes: any path inside the cone
#: is as good); max load 76 km, max heat flux 132 km, heat load 183 km, time 176 km (bang-bang
#: bank swings the actuators lag); max control rate: the sub-problem failed
OBJECTIVE, FORMULATION = "control_effort", "direct_bank"

#: the SCvx iteration cap of the derived plans (paper 001's scenario: 100): SHEFEX-3's pre-flight
#: control-effort plan is feasible (defects 4e-9) by iteration 30, then its trust region sits at
#: 0.002 and the effort falls about 0.25 % an iteration; it converged in 161 iterations (9.8 s)
MAX_ITERATIONS = 250

#: the plan's site cone as a fraction of the box's distance tolerance (room for the flown error)
SITE_RADIUS_FRACTION = 0.5
#: the plan's Mach window as a fraction of the box's Mach window, about its centre
MACH_WINDOW_FRACTION = 0.5
#: the flown plan's DRS altitude is checked within this of the stop altitude [km] (at most a
#: quarter of the box's altitude tolerance), and the plan aims within AIM_TOLERANCE_KM of it: the
#: flight stops at that altitude, so a plan ending 1.5 km above it (the window's upper part,
#: where a control-effort plan settles) left 34 km and Mach 0.9 of flight it never planned. A
#: vehicle that can glide at the interface ends its plans at the shallow final descent bound
#: (FINAL_DESCENT_DEG), so the aim's tolerance becomes a range error of tolerance / tan(gamma_f):
#: at 50 m, plans settling at its top ended HORUS-2B's flights 2-4 km past the target (-13 m/s at
#: 650 m/s; 6 of 100 outside its 2-km box) and Lu 2014's CAV-H 5.0-5.4 km past (11 of 100 outside
#: 5 km); at GLIDE_AIM_TOLERANCE_KM (10 m) those draws ended 1.1 and 3.0 km out, 100 of 100 each.
#: A vehicle that cannot glide there dives through it (Lu 2008's capsule at -40 to -50 deg: 50 m
#: is 0.05 km of range) and the tighter aim only made its re-plans harder (refused 86 of 400
#: against 41; 82 of 100 against 94)
AIM_WINDOW_KM, AIM_TOLERANCE_KM, GLIDE_AIM_TOLERANCE_KM = 0.5, 0.05, 0.01
#: the feedback between re-plans (drake_entry.guidance.scvx.feedback): measured on HORUS-2B's
#: nominal (50 x 6 mesh, path margin 0.07), the plan flown through the actuators ends 36.8 km
#: from its terminal point without it (with 0.5 s less command lead 15 km, 1 s more 21 km), 0.38
#: km with it; with it the paper's 33 x 4 mesh flew the nominal and two dispersed draws inside
#: the box as 50 x 6 did (box ratio 0.84 both)
FEEDBACK = "tvlqr"
#: re-plan from the navigation estimate every REPLAN_PERIOD_S [s] (paper 001's scenario: the
#: pre-flight plan alone ends 21.5 km from its site), every REPLAN_TIME_TO_GO_FRACTION of the time
#: to go when that is shorter, while more than REPLAN_MIN_TIME_TO_GO_S [s] are left (paper 001's
#: scenario: 300 s, over which Lu 2008's capsule, a 550-s flight, was re-planned once and missed
#: by 8-30 km; paper 004's CAV-H by 20-67 km at the end of a 2450-s glide)
REPLAN_PERIOD_S, REPLAN_TIME_TO_GO_FRACTION, REPLAN_MIN_TIME_TO_GO_S = 200.0, 0.4, 60.0
#: a flown plan may end above its Mach window by the window's room up to the box's (or the aimed
#: speed window's) upper edge plus this fraction of its own width: its flown speed is the plan's
#: error, which the box, not the aim, judges
FLOWN_MACH_SLACK = 0.5
#: re-plans predict with the lift and drag ratios the flight has shown (models.acceleration_ratios;
#: not paper 001's, whose dispersions are the entry's) where the mission disperses what changes
#: the lift or drag (dispersions.force_dispersions): Lu 2014's CAV-H draws with 6 % more lift ended
#: 223 and 259 km from the target with the nominal models, 4.4 and 4.5 km with the ratios. Where
#: it disperses only the entry the ratios learn nothing but the alpha actuator's lag behind its
#: command (HORUS-2B, 10 runs: 10/10 without them, 8/10 with, two flights' re-plans refused)
#: the plan's speed window about the interface's speed where the box checks none (an open window
#: let the plans arrive at the stop altitude at any speed, away from the interface's energy)
INTERFACE_SPEED_WINDOW = 0.05
#: the flight-path bounds of eq. 70 on a mission that bounds no gamma [deg]: paper 001's -30 deg
#: is its own mission's (a capsule's last minute below 25 km dives to -31 to -35 deg), the upper
#: bound opened to 5 deg
FLIGHT_PATH_BOUNDS_DEG = (-45.0, 5.0)


def glides_at(scenario, altitude_km: float, speed_m_s: float, alpha_deg: float) -> bool:
    """True when the mission's vehicle, wings level at ``alpha_deg`` [deg], has lift enough to
    hold level flight at ``altitude_km`` and ``speed_m_s`` (nominal air): L/m >= g - V^2/r."""
    vehicle, atmosphere, planet = scenario.make_vehicle(), scenario.make_atmosphere(), scenario.make_planet()
    h = altitude_km * 1e3
    air = scenario.air_altitude(h)
    CL, _ = vehicle.aero.coefficients(math.radians(alpha_deg), speed_m_s / float(atmosphere.speed_of_sound(air)))
    lift = 0.5 * float(atmosphere.density(air)) * speed_m_s ** 2 * vehicle.area_over_mass * float(CL)
    r = float(planet.radius(h))
    return lift >= equilibrium_glide_lift(speed_m_s, r, planet.mu / r ** 2)


def aim_window(scenario, interface, altitude_km: float, mach_window: tuple, alpha_deg, *,
               force_high: float = 1.0, mach_floor: float = 0.0) -> dict:
    """The fields that make a plan end at ``altitude_km`` where the flight stops: the DRS
    window the flown plan is checked in [m] (AIM_WINDOW_KM about it, at most a quarter of the
    box's altitude tolerance and inside the box), the margin that narrows the plan's aim to
    GLIDE_AIM_TOLERANCE_KM where the vehicle glides there at the interface's speed (``glides_at``),
    else AIM_TOLERANCE_KM [m], the stop altitude [km], and the plan's Mach window: the middle
    MACH_WINDOW_FRACTION of the box's ``mach_window`` (low, high) below the Mach
    number where the vehicle's dynamic-pressure limit, and the load it limits at its planned
    bound flying ``alpha_deg(V)`` [deg], are met at that altitude (a window the limits close
    gives an empty window: the candidate is refused), its lower edge extended down to where a
    flight whose aerodynamic forces are ``force_high`` times the nominal meets the planned load
    bound (a re-plan predicts with the forces sensed: paper 004's CAV-H with 6-9 % more drag
    found every re-plan infeasible at its last node), not below ``mach_floor`` (the box's
    lower edge where it checks the speed); the ``interface``'s (terminal_interface) Mach number
    held inside the window as the spec's terminal_mach, its altitude and tolerance the box's."""
    mach = interface.mach
    centre_km, tolerance_km = interface.altitude_km, interface.altitude_tolerance_km
    half = min(AIM_WINDOW_KM, 0.25 * tolerance_km, tolerance_km - abs(altitude_km - centre_km))
    a = float(scenario.make_atmosphere().speed_of_sound(scenario.air_altitude(altitude_km * 1e3)))
    glides = glides_at(scenario, altitude_km, mach * a, alpha_deg(mach * a))
    margin = min(max(half - (GLIDE_AIM_TOLERANCE_KM if glides else AIM_TOLERANCE_KM), 0.0), 0.49 * 2.0 * half)
    fields = {"guidance.final_altitude_m": [round((altitude_km - half) * 1e3, 3), round((altitude_km + half) * 1e3, 3)],
              "guidance.final_altitude_margin_m": round(margin * 1e3, 3), "guidance.terminal_altitude_km": altitude_km}
    lo, hi = mach_window
    hi = min(hi, q_limit_speed(scenario, altitude_km) / a,
             load_limit_speed(scenario, altitude_km, alpha_deg, LIMIT_MARGIN) / a)
    window_hi = hi
    centre, half_width = 0.5 * (lo + hi), 0.5 * MACH_WINDOW_FRACTION * (hi - lo)
    lo, hi = round(max(centre - half_width, 0.0), 4), round(min(centre + half_width, window_hi), 4)
    dispersed = load_limit_speed(scenario, altitude_km, alpha_deg, LIMIT_MARGIN / force_high) / a
    lo = round(max(min(lo, dispersed), mach_floor, 0.0), 4)
    # a flown plan is judged against the window it aims inside, up to that window's upper edge
    # (a plan flown to Mach 6.83 against 6.82 was refused on Lu 2014's CAV-H, whose box checks no speed)
    return fields | {"guidance.final_mach_min": lo, "guidance.final_mach_max": hi,
                     "guidance.flown_mach_margin": round(max(window_hi - hi, 0.0) + FLOWN_MACH_SLACK * (hi - lo), 4),
                     "guidance.terminal_mach": min(max(round(mach, 4), lo), hi)}


def derive(scenario) -> Derivation:
    """Scvx settings for ``scenario``'s mission stating no !Scvx block (module doc)."""
    t = scenario.terminal
    interface = terminal_interface(scenario)
    if not interface.altitude_tolerance_km:
        raise CannotFly("the mission's box gives no altitude tolerance: SCvx plans to an altitude window "
                        "(paper 001 eq. 64)")
    if not t.distance_tolerance_km:
        raise CannotFly("the mission's box gives no distance tolerance: SCvx plans into a cone about the site "
                        "(paper 001 eq. 69)")
    box_window = box_mach_window(scenario, interface)
    if box_window is not None:
        mach_window, mach_how = box_window
    else:  # the interface's speed, which the box does not check: the plan aims at it
        m = interface.mach
        mach_window = (m * (1.0 - INTERFACE_SPEED_WINDOW), m * (1.0 + INTERFACE_SPEED_WINDOW))
        mach_how = (f"the box checks no speed: the interface's Mach {m:.3g} +- {INTERFACE_SPEED_WINDOW:.0%} (where the "
                    f"other methods' energy stop puts it)")
    force_high = force_ratio_high(scenario.dispersions, FORCE_SIGMAS)
    mach_how = (f"the middle {MACH_WINDOW_FRACTION:g} of {mach_how} below the vehicle's dynamic-pressure limit and "
                f"its planned load bound at the interface altitude (room for the flown error), reaching down to "
                f"where forces {force_high:.3g} x the nominal ({FORCE_SIGMAS:g} sigma of the mission's force "
                f"dispersions) meet that load bound")
    h, tol = interface.altitude_km, interface.altitude_tolerance_km
    if h - tol < 0.0:
        raise CannotFly(f"the mission's altitude window reaches below the ground ({h - tol:g} km)")
    altitudes = interface_altitudes(scenario, interface)
    speeds, alphas, alpha_how = alpha_rewritten(scenario, interface, "velocity")
    if len(alphas) == 1:
        alpha_deg, alpha_speeds = [alphas[0], alphas[0]], [2000.0, 5000.0]
    else:
        alpha_deg, alpha_speeds = [alphas[-1], alphas[0]], [max(speeds[0], 1.0), speeds[-1]]
    bounds = [min(alphas), max(alphas)] if max(alphas) > min(alphas) else [max(0.0, alphas[0] - 2.0), alphas[0] + 2.0]
    psi = scenario.entry.heading_deg
    alpha_rate, alpha_accel, actuator = alpha_actuator(
        scenario, ("guidance.alpha_rate_limit_deg_s", "alpha_accel_limit_deg_s2"),
        (Scvx.alpha_rate_limit_deg_s, Scvx.alpha_accel_limit_deg_s2), "paper 001's rate and the spec's acceleration")
    law = alpha_law(alpha_deg, alpha_speeds)  # the plans' own alpha(V) [rad]
    aims = [aim_window(scenario, interface, altitude, mach_window,
                       lambda V: math.degrees(law(V)), force_high=force_high,
                       mach_floor=mach_window[0] if box_window is not None else 0.0) for altitude in altitudes]
    aims = [aim for aim in aims if aim["guidance.final_mach_min"] < aim["guidance.final_mach_max"]]
    if not aims:
        raise CannotFly(f"the vehicle's dynamic-pressure or load limit closes the box's Mach window {mach_window} at every "
                        f"altitude of the box ({', '.join(f'{v:g}' for v in altitudes)} km)")
    first = aims[0]
    forces = force_dispersions(scenario.dispersions)
    spec = Scvx(terminal_altitude_km=first["guidance.terminal_altitude_km"], terminal_mach=first["guidance.terminal_mach"],
                final_altitude_m=first["guidance.final_altitude_m"],
                final_altitude_margin_m=first["guidance.final_altitude_margin_m"],
                final_mach_min=first["guidance.final_mach_min"], final_mach_max=first["guidance.final_mach_max"],
                flown_mach_margin=first["guidance.flown_mach_margin"],
                site_radius_m=round(SITE_RADIUS_FRACTION * t.distance_tolerance_km * 1e3, 3),
                final_vertical_speed_min_m_s=-300.0,
                final_vertical_speed_max_m_s=round(-interface.speed_m_s * math.sin(math.radians(FINAL_DESCENT_DEG)), 3),
                heading_bounds_deg=[psi - 180.0, psi + 180.0],
                flight_path_bounds_deg=list(FLIGHT_PATH_BOUNDS_DEG), objective=OBJECTIVE, formulation=FORMULATION,
                alpha_deg=alpha_deg, alpha_speeds_m_s=alpha_speeds, alpha_bounds_deg=bounds,
                replan_period_s=REPLAN_PERIOD_S, replan_min_time_to_go_s=REPLAN_MIN_TIME_TO_GO_S,
                replan_time_to_go_fraction=REPLAN_TIME_TO_GO_FRACTION,
                path_margin=round(1.0 - LIMIT_MARGIN, 4), feedback=FEEDBACK, replan_model_scales=bool(forces),
                alpha_rate_limit_deg_s=alpha_rate, alpha_accel_limit_deg_s2=alpha_accel, max_iterations=MAX_ITERATIONS)
    load, _ = scenario.make_vehicle().limits.planned_load()
    choices = [
        Choice("guidance.final_mach_min, final_mach_max",
               f"{first['guidance.final_mach_min']:.3g}-{first['guidance.final_mach_max']:.3g}", mach_how),
        Choice("guidance.flown_mach_margin", spec.flown_mach_margin,
               f"a flown plan may end above its Mach window by the room up to the window it was cut from plus "
               f"{FLOWN_MACH_SLACK:g} of its width (the box judges the flight, the window is the plan's aim: a plan "
               f"flown to Mach 6.83 against 6.82 was refused on Lu 2014's CAV-H, whose box checks no speed)"),
        Choice("guidance.site_radius_m", spec.site_radius_m,
               f"{SITE_RADIUS_FRACTION:g} x the box's distance tolerance (room for the flown error)"),
        Choice("guidance.alpha_deg, alpha_speeds_m_s, alpha_bounds_deg",
               f"{alpha_deg} deg at {[round(v) for v in alpha_speeds]} m/s, bounds {bounds} deg", alpha_how),
        actuator,
        Choice("guidance.max_iterations", MAX_ITERATIONS,
               "paper 001's 100 stopped SHEFEX-3's feasible pre-flight plan while its effort still fell 0.25 % an "
               "iteration (converged in 161)"),
        Choice("guidance.heading_bounds_deg", spec.heading_bounds_deg, "half a turn either side of the entry heading"),
        Choice("guidance.final_vertical_speed_max_m_s", spec.final_vertical_speed_max_m_s,
               f"the plans end descending at {FINAL_DESCENT_DEG:g} deg or steeper at the interface speed (the "
               f"altitude stop then falls where the plan ends)"),
        Choice("guidance.flight_path_bounds_deg", spec.flight_path_bounds_deg,
               "the mission bounds no gamma: wider than paper 001's [-30, 0.5] deg, its own mission's"),
        Choice("guidance.objective, formulation", f"{OBJECTIVE}, {FORMULATION}",
               "the control effort, with the mission's alpha: the plans whose controls fly closest to themselves"),
        Choice("the plan's path bounds", f"heat flux, {load} load, dynamic pressure",
               f"the vehicle's limits (it limits the {load} load)"),
        Choice("guidance.path_margin", spec.path_margin,
               f"the plans keep {LIMIT_MARGIN:g} of each limit, the shared margin for dispersions (between re-plans "
               f"the flight drifts: at paper 001's 0.02 a dispersed HORUS-2B flight met 100.5 % of its heat-flux "
               f"limit 100 s after the first re-plan)"),
        Choice("guidance.replan_period_s, replan_time_to_go_fraction, replan_min_time_to_go_s",
               f"{REPLAN_PERIOD_S:g} s, {REPLAN_TIME_TO_GO_FRACTION:g}, {REPLAN_MIN_TIME_TO_GO_S:g} s",
               "re-planned on board as paper 001's scenario is, closer together near the end"),
        Choice("guidance.replan_model_scales", bool(forces),
               f"the mission disperses {', '.join(forces)}: re-plans predict with the nominal lift and drag times the "
               f"ratios the flight has sensed (with the nominal models alone two Lu 2014 CAV-H draws ended 220-260 km "
               f"from the target, with the ratios 4.4-4.5 km)" if forces else
               "the mission disperses nothing that changes the lift or drag: the ratios would learn only the alpha "
               "actuator's lag (HORUS-2B: 10/10 without, 8/10 with)"),
        Choice("guidance.feedback", FEEDBACK,
               "between re-plans the commands track the plan (not paper 001's): without it the plan flown through "
               "the actuators drifts 5-37 km from itself over HORUS-2B's glide, with it 0.4 km"),
    ]
    search = [
        SearchStep("the interface altitude (the plan ends where the flight stops)",
                   tuple(aims), ALTITUDE_WHY),
    ]
    return Derivation(spec, choices, search)
