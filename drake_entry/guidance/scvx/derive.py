"""SCvx's settings from a mission (drake_entry.guidance.derivation): paper 001's DRS box posed on
the mission's acceptance box. The altitude window is the box's, the Mach window the box's (from
its speed window where it gives one), the site cone half the box's distance tolerance (a design
margin), the alpha law the mission's alpha rewritten in speed, the heading bounds half a turn
either side of the entry heading; the plan bounds the vehicle's heat flux and whichever load it
limits, and is re-planned on board as paper 001's own scenario is. A mission whose box gives no
altitude window or no distance cannot be posed: CannotFly."""

from drake_entry.guidance.derivation import CannotFly, Choice, Derivation, alpha_rewritten, terminal_interface
from drake_entry.guidance.scvx.mission import planned_load
from drake_entry.guidance.scvx.spec import Scvx

__all__ = ["derive", "SITE_RADIUS_FRACTION", "STOP_ABOVE_WINDOW_KM", "REPLAN_PERIOD_S", "OBJECTIVE", "FORMULATION"]

#: the plan's objective and formulation on another method's mission: the miss distance, with the
#: bank a state and alpha the mission's law. Measured on HORUS-2B's nominal (plans of 23-40
#: iterations, 2-3 s): the flown controls of a heat-load plan end 107-164 km from its terminal
#: point (bang-bang bank swings the actuators lag), of a miss plan with alpha planned 41 km, of a
#: miss plan with the mission's alpha 23 km
OBJECTIVE, FORMULATION = "miss", "direct_bank"

#: the plan's site cone as a fraction of the box's distance tolerance (room for the flown error)
SITE_RADIUS_FRACTION = 0.5
#: the flight stops this far above the window's lower edge [km] (the plans end at the edge plus
#: their 200 m design margin: paper 001's scenario stops 170 m above its window)
STOP_ABOVE_WINDOW_KM = 0.15
#: re-plan from the navigation estimate every this [s] while more than 300 s are left (paper
#: 001's scenario: the pre-flight plan alone ends 21.5 km from its site)
REPLAN_PERIOD_S = 200.0


def derive(scenario) -> Derivation:
    """Scvx settings for ``scenario``'s mission stating no !Scvx block (module doc)."""
    t = scenario.terminal
    interface = terminal_interface(scenario)
    if not t.altitude_tolerance_km:
        raise CannotFly("the mission's box gives no altitude tolerance: SCvx plans to an altitude window "
                        "(paper 001 eq. 64)")
    if not t.distance_tolerance_km:
        raise CannotFly("the mission's box gives no distance tolerance: SCvx plans into a cone about the site "
                        "(paper 001 eqs. 67-68)")
    a = interface.speed_of_sound
    if t.mach is not None and t.mach_tolerance:
        mach_lo, mach_hi, mach_how = t.mach - t.mach_tolerance, t.mach + t.mach_tolerance, "the box's Mach window"
    elif t.velocity_m_s is not None and t.velocity_tolerance_m_s:
        mach_lo = (t.velocity_m_s - t.velocity_tolerance_m_s) / a
        mach_hi = (t.velocity_m_s + t.velocity_tolerance_m_s) / a
        mach_how = f"the box's speed window as Mach at {interface.altitude_km:g} km"
    else:
        mach_lo, mach_hi, mach_how = 0.0, 10.0, "the box checks no speed: the Mach window is open"
    mach_lo = max(mach_lo, 0.0)
    mach = interface.mach
    h = interface.altitude_km
    window = [round((h - t.altitude_tolerance_km) * 1e3, 3), round((h + t.altitude_tolerance_km) * 1e3, 3)]
    if window[0] < 0.0:
        raise CannotFly(f"the mission's altitude window reaches below the ground ({window[0] / 1e3:g} km)")
    speeds, alphas, alpha_how = alpha_rewritten(scenario, interface, "velocity")
    if len(alphas) == 1:
        alpha_deg, alpha_speeds = [alphas[0], alphas[0]], [2000.0, 5000.0]
    else:
        alpha_deg, alpha_speeds = [alphas[-1], alphas[0]], [max(speeds[0], 1.0), speeds[-1]]
    bounds = [min(alphas), max(alphas)] if max(alphas) > min(alphas) else [max(0.0, alphas[0] - 2.0), alphas[0] + 2.0]
    psi = scenario.entry.heading_deg
    spec = Scvx(terminal_altitude_km=round(window[0] / 1e3 + STOP_ABOVE_WINDOW_KM, 4),
                terminal_mach=round(min(max(mach, mach_lo), mach_hi), 4), final_altitude_m=window,
                final_mach_min=round(mach_lo, 4), final_mach_max=round(mach_hi, 4),
                site_radius_m=round(SITE_RADIUS_FRACTION * t.distance_tolerance_km * 1e3, 3),
                final_vertical_speed_min_m_s=-300.0, heading_bounds_deg=[psi - 180.0, psi + 180.0],
                flight_path_bounds_deg=[-30.0, 5.0], objective=OBJECTIVE, formulation=FORMULATION,
                alpha_deg=alpha_deg, alpha_speeds_m_s=alpha_speeds, alpha_bounds_deg=bounds,
                replan_period_s=REPLAN_PERIOD_S)
    load, _ = planned_load(scenario.make_vehicle().limits)
    choices = [
        Choice("guidance.final_altitude_m", f"{window[0] / 1e3:g}-{window[1] / 1e3:g} km", "the box's altitude window"),
        Choice("guidance.terminal_altitude_km", spec.terminal_altitude_km,
               f"the flight stops {STOP_ABOVE_WINDOW_KM:g} km above the window's lower edge, where the plans end"),
        Choice("guidance.final_mach_min, final_mach_max", f"{mach_lo:.3g}-{mach_hi:.3g}", mach_how),
        Choice("guidance.site_radius_m", spec.site_radius_m,
               f"{SITE_RADIUS_FRACTION:g} x the box's distance tolerance (room for the flown error)"),
        Choice("guidance.alpha_deg, alpha_speeds_m_s, alpha_bounds_deg",
               f"{alpha_deg} deg at {[round(v) for v in alpha_speeds]} m/s, bounds {bounds} deg", alpha_how),
        Choice("guidance.heading_bounds_deg", spec.heading_bounds_deg, "half a turn either side of the entry heading"),
        Choice("guidance.flight_path_bounds_deg", spec.flight_path_bounds_deg,
               "paper 001's lower bound; the upper opened to 5 deg (the mission does not bound gamma)"),
        Choice("guidance.objective, formulation", f"{OBJECTIVE}, {FORMULATION}",
               "the miss, with the mission's alpha: the plans whose controls fly closest to themselves"),
        Choice("the plan's load bound", load, f"the vehicle limits the {load} load"),
        Choice("guidance.replan_period_s", REPLAN_PERIOD_S, "re-planned on board as paper 001's scenario is"),
    ]
    return Derivation(spec, choices, [])
