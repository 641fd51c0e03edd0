"""FNPEG's settings from a mission (drake_entry.guidance.derivation): Lu 2014's terminal interface
e_f at the mission's box centre, the mission's alpha schedule in speed, its reversal corridor,
the path-limit feedback on the vehicle's limits with a margin; sigma_f searched."""
import dataclasses as dc
import math

from drake_entry.guidance.derivation import (
    Choice,
    Derivation,
    SearchStep,
    alpha_actuator,
    alpha_rewritten,
    path_gain,
    require_alpha_window,
    reversal_corridor,
    terminal_interface,
)
from drake_entry.guidance.fnpeg.spec import Fnpeg

__all__ = ["derive", "BANK_END_CANDIDATES_DEG", "LIMIT_MARGINS", "ENGAGE_ACCELERATIONS_M_S2", "final_range_from"]

#: sigma_f flown on the nominal flight and the search's draws, every one (it sets the altitude
#: at e_f, graded: on Lu's CAV-H case 50, 40 and 30 deg end 2.0 km low, centred and 1.3 km high)
#: [deg] (Lu 2008: 60-70; the hand-tuned HORUS-2B value was 45)
BANK_END_CANDIDATES_DEG = (45.0, 50.0, 40.0, 55.0, 35.0, 60.0, 30.0, 65.0, 25.0, 70.0, 20.0)
#: fractions of the vehicle's limits the path feedback enforces, tried in order (the hand-tuned
#: HORUS-2B values were 0.90-0.94)
LIMIT_MARGINS = (0.93, 0.9, 0.85, 0.8)
#: the sensed aerodynamic acceleration at which FNPEG engages [m/s^2], tried in order: Lu 2014's
#: 1.52, then a half and a quarter of it. SPHYNX's entry (-1.29 deg at 115 km, L/D 0.9 at 40 deg)
#: skips: wings level its first pull-out senses at most 1.09 m/s^2 (74 km, 354 s), and at 1.52 the
#: guidance engaged only at 1340 s, past the site, ending 3500-4100 km from it; at 1.0 and 0.5 it
#: engaged at 319 and 247 s and ended 3.5 and 3.6 km from it
ENGAGE_ACCELERATIONS_M_S2 = (1.52, 0.76, 0.38)


def derive(scenario) -> Derivation:
    """Fnpeg settings for ``scenario``'s mission that states no !Fnpeg block (module doc)."""
    require_alpha_window(scenario)
    interface = terminal_interface(scenario)
    speeds, alphas, alpha_how = alpha_rewritten(scenario, interface, "velocity")
    heading, velocity, corridor = reversal_corridor(scenario)
    v = scenario.make_vehicle()
    lim = v.limits
    limits = {"heat_rate_limit_kW_m2": lim.heat_flux_max / 1e3,
              "load_limit_g": lim.load_bound_max,
              "dynamic_pressure_limit_kPa": lim.dynamic_pressure_max / 1e3}

    def enforced(margin: float) -> dict:
        return {f"guidance.{k}": (round(margin * x, 4) if math.isfinite(x) else 0.0) for k, x in limits.items()}

    gain = path_gain(v)  # Lu 2014's path-limit feedback where the vehicle has a limit (HORUS-2B's hand-tuned 40)
    candidates = tuple(b for b in BANK_END_CANDIDATES_DEG if b <= v.bank_limit_deg)
    first = {k.split(".", 1)[1]: x for k, x in enforced(LIMIT_MARGINS[0]).items()}
    alpha_rate, alpha_accel, actuator = alpha_actuator(
        scenario, ("guidance.alpha_rate_deg_s", "alpha_accel_deg_s2"), (Fnpeg.alpha_rate_deg_s, Fnpeg.alpha_accel_deg_s2),
        "the spec's defaults")
    spec = Fnpeg(terminal_altitude_km=interface.altitude_km, terminal_velocity_m_s=round(interface.speed_m_s, 3),
                 final_range_km=0.0, bank_end_deg=candidates[0], alpha_deg=alphas,
                 alpha_velocity_m_s=[round(x, 3) for x in speeds], reversal_heading_deg=heading,
                 reversal_velocity_m_s=velocity, path_gain=gain, alpha_rate_deg_s=alpha_rate,
                 alpha_accel_deg_s2=alpha_accel, **first)
    choices = [
        Choice("guidance.terminal_altitude_km", interface.altitude_km,
               "Lu's e_f at the altitude of the mission's acceptance box (not searched: the altitude at e_f is "
               "sigma_f's)"),
        Choice("guidance.terminal_velocity_m_s", round(interface.speed_m_s, 3),
               f"Lu's e_f at {interface.speed_words}"
               + (f" (Mach {interface.mach:g}, as a speed)" if interface.mach_given else "")),
        Choice("guidance.final_range_km", 0.0, "the target is the box's distance centre"),
        Choice("guidance.alpha_deg, alpha_velocity_m_s",
               ", ".join(f"{a:g} deg at {s:.0f} m/s" for a, s in zip(alphas, speeds)), alpha_how),
        actuator,
        corridor,
        Choice("guidance.path_gain", gain, "Lu 2014's path-limit feedback, on where the vehicle has a limit (the "
               "load enforced is the lower of its normal and total load limits: the total bounds the normal)"),
    ]
    margin = SearchStep("limit margin", tuple(enforced(m) for m in LIMIT_MARGINS),
                        f"the fraction of the vehicle's limits the feedback enforces "
                        f"({', '.join(map(str, LIMIT_MARGINS))}): the rest is the predictor's and the actuators' lag")
    # No step on the terminal altitude: FNPEG steers the range to e_f, and the altitude there is
    # what sigma_f leaves (on paper 004's mission 29-31.5 km moved it by 0.1 km; sigma_f 30-60 deg by 3 km)
    search = [
        margin,
        SearchStep.over("guidance.bank_end_deg", candidates,
                        "sigma_f sets the lift left at the end, so the altitude at e_f (Lu: chosen per vehicle); "
                        "every candidate flown, the best kept", exhaustive=True),
        dc.replace(margin, name="limit margin at that sigma_f"),
        SearchStep.over("guidance.engage_acceleration_m_s2", ENGAGE_ACCELERATIONS_M_S2,
                        "Lu 2014's engagement at 1.52 m/s^2 of sensed acceleration first; a vehicle that skips "
                        "on a shallow entry senses less in its first pull-out and would glide on wings level "
                        "until past the target: half, then a quarter (last, so a mission that engages at Lu's "
                        "keeps it)"),
        SearchStep.calibrated("guidance.final_range_km", final_range_from, (0.0,),
                              "Lu's s_f* at the distance the nominal flight with the settings chosen before ends "
                              "past the target (the flight flies range its predictions do not see), then 0"),
    ]
    return Derivation(spec, choices, search)


def final_range_from(nominal: dict) -> float:
    """Lu's s_f* [km] that cancels the nominal flight's overshoot: the distance past the target
    its campaign row's ``err_range_m`` gives (negative past it), to 0.1 km; 0 for a flight that
    ends short (s_f* >= 0)."""
    return max(round(-float(nominal["err_range_m"]) / 100.0) / 10.0, 0.0)
