"""The drag-energy guidance's settings from a mission (drake_entry.guidance.derivation): the
terminal interface in the mission's box, the mission's alpha schedule in normalised energy, its
reversal corridor, re-plans from the reference; the interface's altitude, the corridor margin,
the corridor centring and the reversal corridor's width searched (paper 000's corridor closes
where the vehicle's limits meet: the altitude that keeps it open is the mission's)."""

import dataclasses as dc
import math

import numpy as np

from drake_entry.guidance.derivation import (
    ALTITUDE_WHY,
    CannotFly,
    Choice,
    Derivation,
    SearchStep,
    alpha_rewritten,
    interface_altitudes,
    require_alpha_window,
    reversal_corridor,
    terminal_interface,
)
from drake_entry.guidance.drag_energy.spec import DragEnergy
from drake_entry.models.dispersions import force_dispersions
from drake_entry.scenario import ScheduleSpec

__all__ = ["derive", "require_glide_floor", "range_offset_from", "MARGIN_CANDIDATES", "REPLAN_PERIOD_S",
           "CENTRING_CANDIDATES", "REVERSAL_WIDENING", "RANGE_OFFSET_WHY"]
#: corridor margins tried (paper 000 keeps the profile inside the limits by a margin)
MARGIN_CANDIDATES = (0.05, 0.03, 0.08, 0.02)
#: re-plan from the navigation state every this [s] (paper 000 plans once; re-planning is what
#: dispersed entries need: HORUS-2B's single plan ends 24.3 +- 4.3 km from the runway)
REPLAN_PERIOD_S = 20.0
#: corridor-centring weights tried (DragEnergyProblem.centring; 0 is paper 000's smoothest profile)
CENTRING_CANDIDATES = (1000.0, 0.0)
#: the reversal corridor's half-width at its upper speed is tried widened by this factor first
REVERSAL_WIDENING = 5.0 / 3.0
#: why the derivation re-plans from the reference (measured on Lu 2014's CAV-H, seed 2026)
REFERENCE_START_WHY = (
    "each re-plan starts at the reference's drag and slope at the flight's energy (eq. 84 at the reference), so "
    "the tracking law keeps correcting its error; started at the flown drag, every re-plan adopts the error and a "
    "long glide's slow drift of the drag is planned around until the profile reaches the corridor's ceiling (Lu "
    "2014's CAV-H, 100 runs with the other settings as derived: 14 successful from the flown drag, 94 from the "
    "reference's)")


#: why the plans' range is offset by the nominal flight's final range to go (measured on Lu 2014's CAV-H)
RANGE_OFFSET_WHY = (
    "the plans fly the range to go plus the nominal flight's final range to go with the settings chosen before: "
    "the end game (the last reversals, the descent to the interface) flies range the plan does not see (Lu 2014's "
    "CAV-H: the nominal flight ends 2.37 km past the target; 100 runs, seed 2026: 90 successful without the "
    "offset, range error -1.7 +- 2.2 km; 93 with it, +0.6 +- 2.2 km)")


#: the bank [deg] held before the guidance engages: paper 000's lift up first
PRE_GUIDANCE_BANK_CANDIDATES = (0.0, 30.0, 45.0, 60.0)

#: why the pre-guidance bank is searched
PRE_GUIDANCE_WHY = ("the bank held until the guidance engages (paper 000 flies the lift up): a lifting vehicle "
                    "entering shallow near circular speed pulls out high with the lift up (SPHYNX: at 74 km, drag "
                    "0.8 m/s^2), where the first plan asks for a descent that its 90-deg bank limit cannot fly "
                    "(the drag 60 % under the plan for 300 s, the flight 780 km long); banked, it engages lower "
                    "(45 deg: at 400 s, 1 km from the target on the nominal flight)")


def require_glide_floor(scenario, interface, altitudes_km, alpha_deg: float) -> None:
    """CannotFly when at every candidate interface altitude the vehicle's drag at the box's speed
    (and the mission's alpha there) lies below the corridor's floor, the equilibrium glide with
    the lift vertical (paper 000 eq. 70), so far that the plan, which ends on the floor, ends
    outside the box's altitude window: on the interface's energy level the floor's drag lies
    that much lower (a capsule of L/D 0.3 at 19 km, 305 m/s: 13 m/s^2 against 30, the floor's
    drag 6 km under the box). SPHYNX's DRS point lies under the floor too (Mach 0.5 at 11.5 km
    geodetic), but the floor's drag is within its box."""
    from drake_entry.guidance.drag_energy.corridor import compute_corridor
    from drake_entry.guidance.drag_energy.drag_dynamics import drag_acceleration
    from drake_entry.guidance.drag_energy.planner import altitude_speed_from_drag

    vehicle, atmosphere = scenario.make_vehicle(), scenario.make_atmosphere()
    planet = scenario.make_planet().with_(j2=0.0)
    alpha, lat_f = math.radians(alpha_deg), math.radians(scenario.target.latitude_deg)
    geodetic = scenario.altitude_datum == "ellipsoid"
    centre, tol = interface.altitude_km, interface.altitude_tolerance_km
    below = []
    for h_km in altitudes_km:
        h = h_km * 1e3  # in the mission's datum
        state_h = float(planet.state_altitude(h, lat_f)) if geodetic else h
        E = float(planet.specific_energy(state_h, interface.speed_m_s))
        floor = float(compute_corridor([E], lambda _: alpha, vehicle, planet, atmosphere,
                                       lat_of_E=lambda _: lat_f).D_min[0])
        drag = float(drag_acceleration(scenario.air_altitude(h), interface.speed_m_s, alpha, vehicle, atmosphere))
        if drag >= floor:
            return
        h_floor = altitude_speed_from_drag(E, floor, alpha, vehicle, planet, atmosphere, h_guess=state_h,
                                           lat=lat_f)[0]
        h_floor_km = (float(planet.atmospheric_altitude(h_floor, lat_f)) if geodetic else h_floor) / 1e3
        if tol is None or abs(h_floor_km - centre) <= tol:
            return
        below.append((h_km, drag, floor, h_floor_km))

    def span(values, fmt: str) -> str:
        lo, hi = format(min(values), fmt), format(max(values), fmt)
        return lo if lo == hi else f"{lo}-{hi}"
    heights, drags, floors, floor_heights = zip(*below)
    raise CannotFly(f"drag below the glide floor at the interface: {span(drags, '.3g')} m/s^2 against "
                    f"{span(floors, '.3g')} ({span(heights, 'g')} km, {interface.speed_m_s:.0f} m/s, alpha "
                    f"{alpha_deg:g} deg; the floor of paper 000's drag corridor, eq. 70, is the equilibrium glide "
                    f"with the lift vertical): a plan ends on the floor, whose drag on the interface's energy "
                    f"level lies at {span(floor_heights, '.3g')} km, outside the box's {centre:g} +- {tol:g} km")


def derive(scenario) -> Derivation:
    """DragEnergy settings for ``scenario``'s mission stating no
    block of this method (derivation_for returns a stated one as it is)."""
    require_alpha_window(scenario)
    interface = terminal_interface(scenario)
    mach = interface.mach
    heading, velocity, corridor = reversal_corridor(scenario)
    widened = [heading[0], round(heading[1] * REVERSAL_WIDENING, 3)]
    corridor = dc.replace(corridor, how=f"{corridor.how}; its half-width at the upper speed is searched, "
                                        f"{widened[1]:g} deg first")
    breakpoints, values, alpha_how = alpha_rewritten(scenario, interface, "normalized_energy")
    own = scenario.alpha
    alpha = (None if own.variable in ("energy", "normalized_energy")
             else ScheduleSpec("normalized_energy", breakpoints, values, own.smooth))
    altitudes = interface_altitudes(scenario, interface)
    require_glide_floor(scenario, interface, altitudes, float(np.interp(1.0, breakpoints, values)))
    forces = force_dispersions(scenario.dispersions)
    spec = DragEnergy(terminal_altitude_km=altitudes[0], terminal_mach=round(mach, 4),
                      corridor_margin=MARGIN_CANDIDATES[0], replan_period_s=REPLAN_PERIOD_S, replan_until_e=0.99,
                      bandwidth_rad_s=0.1, reversal_heading_deg=widened, reversal_velocity_m_s=velocity,
                      replan_model_scales=bool(forces), replan_start="reference",
                      corridor_centring=CENTRING_CANDIDATES[0])
    choices = [
        Choice("guidance.terminal_mach", round(mach, 4), f"the Mach number of {interface.speed_words}"
               + ("" if interface.mach_given else f" ({interface.speed_m_s:g} m/s)")),
        Choice("alpha", "as the mission's" if alpha is None else
               ", ".join(f"{v:g} deg at e = {b:.3f}" for b, v in zip(breakpoints, values)),
               alpha_how if alpha is not None else "the planner flies alpha(E): the mission's schedule is in energy"),
        corridor,
        Choice("guidance.replan_period_s, replan_until_e", f"{REPLAN_PERIOD_S:g} s, 0.99",
               "re-planned from the navigation state (paper 000 plans once; a single HORUS-2B plan ends "
               "24.3 +- 4.3 km from the runway)"),
        Choice("guidance.replan_start", "reference", REFERENCE_START_WHY),
        Choice("guidance.bandwidth_rad_s", 0.1, "the tracking law's constant time-domain bandwidth (omega = "
               "0.1 / (D V)): the same response at every speed, for any vehicle's drag"),
        Choice("guidance.replan_model_scales", bool(forces),
               f"the mission disperses {', '.join(forces)}: re-plans take the corridor and the terminal drag of the "
               f"vehicle with the lift and drag ratios the flight has sensed (paper 004's CAV-H, 100 runs: 89 with "
               f"the nominal corridor, 11 over the 2-g load on the planned drag; 99 with the sensed one)" if forces else
               "the mission disperses nothing that changes the lift or drag: the nominal corridor is the flight's"),
    ]
    search = [SearchStep.over("guidance.pre_guidance_bank_deg", PRE_GUIDANCE_BANK_CANDIDATES, PRE_GUIDANCE_WHY),
              SearchStep.over("guidance.terminal_altitude_km", altitudes, ALTITUDE_WHY),
              SearchStep.over("guidance.corridor_margin", MARGIN_CANDIDATES,
                         "room between the profile and the limits for the dispersions"),
              SearchStep.over("guidance.corridor_centring", CENTRING_CANDIDATES,
                              "the profile kept away from both bounds (not paper 000's): the smoothest profile of "
                              "eq. 92 rides the corridor's ceiling where the range is short for the energy, and a "
                              "flight that falls behind there cannot catch up (Lu 2014's CAV-H: 94 of 100 at 1000, "
                              "13 of the first 20 without)"),
              SearchStep.over("guidance.reversal_heading_deg", (widened, list(heading)),
                              f"the reversal corridor widened at its upper speed by {REVERSAL_WIDENING:.3g} first: "
                              f"each reversal rolls through lift-up and loses drag the plan needs (Lu 2014's CAV-H, "
                              f"100 runs: 94 successful widened, 79 with its own corridor)"),
              SearchStep.calibrated("guidance.range_offset_m", range_offset_from, (0.0,), RANGE_OFFSET_WHY)]
    return Derivation(spec, choices, search, alpha=alpha)


def range_offset_from(nominal: dict) -> float:
    """The range offset [m] that cancels the nominal flight's final range to go (its campaign
    row's ``err_range_m``, negative past the target; flown with no offset), to 10 m."""
    return round(float(nominal["err_range_m"]) / 10.0) * 10.0
