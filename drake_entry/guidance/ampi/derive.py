"""AMPI's settings from a mission (drake_entry.guidance.derivation): the database built for the
mission itself (``database: mission``, guidance.ampi.mission), ending at the centre of the
mission's acceptance box (below the speed where the planned dynamic-pressure bound is met, as the
LGL guidance's), over a grid of the entry offsets the mission disperses most, each spanning its
3-sigma reach (paper 003 eq. 5's form: the grid step is the dispersion's 3 sigma).

The database's settings are not searched: each candidate would be a database of its own (minutes
of solves); only the tracker's reading of the reference (time or energy) is, on the one database,
and, where the mission disperses the air or the aerodynamics, whether it reads the reference at the
lift and drag ratios the flight senses (``model_scales``). The
terminal altitude is the box centre, or the first of the shared steps inside the box where the
dynamic-pressure bound leaves a speed in the box."""

import math

from drake_entry.guidance.ampi.mission import BANK_FRACTION, BANK_RATE_FRACTION
from drake_entry.guidance.ampi.spec import MISSION_DATABASE, TRACKING_INDICES, Ampi
from drake_entry.guidance.derivation import (
    PATH_LIMIT_FRACTION,
    Q_SPEED_FRACTION,
    CannotFly,
    Choice,
    Derivation,
    SearchStep,
    interface_speeds,
    mission_alpha,
    path_gain,
    require_alpha_window,
    terminal_interface,
)
from drake_entry.models.dispersions import entry_spread, force_dispersions

__all__ = ["GRID_DIMENSIONS", "GRID_NAMES", "LD_NODES_RANGE", "ld_nodes", "TRACKING_STATE_WEIGHT", "TERMINAL_POSITION_FRACTIONS", "range_effects",
           "derive"]

#: the most entry offsets a derived grid spans (3 levels each: 27 solves, a few minutes on 2 cores)
GRID_DIMENSIONS = 3
#: the TVLQR's path weight on a mission (paper 003's SHEFEX-3 flight, 600 s, flies 1e-5: the
#: terminal weight steers and the path weight only damps). On Lu 2014's CAV-H 2400-s glide the
#: nominal flight with 1e-5 ended 3440 km off (the vehicle skipped away from the reference); 1e-3,
#: 125 km; 1e-2, 147 km with the planned bank rate at the vehicle's limit and 0.18 km with it at a
#: quarter and the planned bank at 0.9 of the limit (guidance.ampi.mission)
TRACKING_STATE_WEIGHT = 1.0e-2
#: the TVLQR's final-position scales searched, as fractions of the box's distance tolerance (paper
#: 003's 0.01 deg, 1.1 km, for its 25-km window). HORUS-2B's nominal with 0.01 deg ended 5.6 km
#: from the target, with 0.002 deg (220 m) 1.0 km, against its 2-km box. A fiftieth pulls the
#: short flights home (20 runs with the path-limit feedback: the capsule 36 of 40 against 33 of 40,
#: paper 004's CAV-H 18 of 20 against 5, HORUS-2B's misses 0.04 km against 0.2) and throws a long
#: glide off (Lu 2014's CAV-H: 558 km median against 19 km), so the search flies both
TERMINAL_POSITION_FRACTIONS = (0.1, 0.02)
#: the fewest and most LD nodes of a derived database (paper 003 stores its 600-s flights at 60)
LD_NODES_RANGE = (60, 400)
#: the grid's names of the entry deviations, in the dispersions' order [m, deg, deg, m/s, deg, deg]
GRID_NAMES = ("h", "lon", "lat", "V", "gamma", "psi")


def ld_nodes(scenario, interface) -> tuple[int, float, float]:
    """(the LD nodes of a mission database, the flight's duration estimate [s], a planned bank
    reversal's duration [s]): enough Legendre-Gauss-Lobatto nodes that their widest interval,
    pi T / (2 N) in the middle of a flight of T seconds, is at most half a reversal (the planned
    bank from one side to the other at the planned rate, guidance.ampi.mission), within
    LD_NODES_RANGE. T: the great-circle range to the target over the mean of the entry and
    terminal speeds."""
    vehicle = scenario.make_vehicle()
    reversal = float(2.0 * BANK_FRACTION * vehicle.bank_limit / (BANK_RATE_FRACTION * vehicle.bank_rate_limit))
    planet = scenario.make_planet()
    x0 = scenario.initial_state()
    to_go = planet.great_circle_distance(x0[1], x0[2], math.radians(scenario.target.longitude_deg),
                                         math.radians(scenario.target.latitude_deg))
    duration = float(to_go / (0.5 * (x0[3] + interface.speed_m_s)))
    low, high = LD_NODES_RANGE
    return min(max(math.ceil(math.pi * duration / reversal), low), high), duration, reversal


def range_effects(scenario, interface, spread) -> dict:
    """How far [m] each entry deviation's 3-sigma reach ``spread`` (dispersions.entry_spread) moves
    the flight's end at the terminal ``interface`` (derivation.terminal_interface), to first order: a position offset by itself (the arc length), a speed or
    altitude offset by its share of the energy to dissipate times the range to go (range grows
    with the energy spent), a flight-path or heading offset as that angle times the range to go."""
    planet = scenario.make_planet().with_(j2=0.0)
    x0 = scenario.initial_state()
    hf = interface.altitude_km * 1e3
    span = float(planet.specific_energy(x0[0], x0[3]) - planet.specific_energy(hf, interface.speed_m_s))
    R = planet.reference_radius
    lon_t, lat_t = math.radians(scenario.target.longitude_deg), math.radians(scenario.target.latitude_deg)
    to_go = planet.great_circle_distance(x0[1], x0[2], lon_t, lat_t)
    d = math.radians
    h, lon, lat, V, gamma, psi = (float(v) for v in spread)
    return {"h": to_go * planet.g0 * h / span, "lon": R * d(lon) * math.cos(x0[2]), "lat": R * d(lat),
            "V": to_go * float(x0[3]) * V / span, "gamma": to_go * d(gamma), "psi": to_go * d(psi)}


def derive(scenario) -> Derivation:
    """Ampi settings for ``scenario``'s mission stating no block of this method."""
    require_alpha_window(scenario)
    interface = terminal_interface(scenario)
    altitude, speed = interface_speeds(scenario, interface, Ampi.path_margin)[0]
    spread = entry_spread(scenario.dispersions)
    effects = range_effects(scenario, interface, spread)
    ranked = sorted((n for n, s in zip(GRID_NAMES, spread) if s > 0.0), key=lambda n: -effects[n])
    if not ranked:
        raise CannotFly("the mission disperses no entry state: a database of one entry is its nominal plan (fly "
                        "the LGL or SCvx guidance, which plan it)")
    names = ranked[:GRID_DIMENSIONS]
    steps = {n: float(spread[GRID_NAMES.index(n)]) for n in names}
    alpha, source = mission_alpha(scenario)
    own_alpha = alpha is scenario.alpha
    nodes, duration, reversal = ld_nodes(scenario, interface)
    spec = Ampi(database=MISSION_DATABASE, terminal_altitude_km=altitude, terminal_velocity_m_s=speed, ld_nodes=nodes,
                grid={n: round(v, 6) for n, v in steps.items()}, tracking_state_weight=TRACKING_STATE_WEIGHT)
    tolerance_km = scenario.terminal.distance_tolerance_km
    radius = scenario.make_planet().reference_radius

    def terminal_scales(fraction: float) -> list[float]:
        position = round(math.degrees(fraction * tolerance_km * 1e3 / radius), 6)
        return [spec.terminal_scales[0], position, position, spec.terminal_scales[3]]

    if tolerance_km:
        spec.terminal_scales = terminal_scales(TERMINAL_POSITION_FRACTIONS[0])
    spec.path_gain, spec.path_limit_fraction = path_gain(scenario.make_vehicle()), PATH_LIMIT_FRACTION
    units = {"h": "m", "V": "m/s"}
    left = [n for n in ranked if n not in names]
    choices = [
        Choice("guidance.database", MISSION_DATABASE, "built for this mission on demand and cached: paper 003's "
               "problem form (bank rate, alpha scheduled, bank effort with a flight-path term) from the mission's entry, target, interface "
               "and vehicle limits"),
        Choice("guidance.terminal_altitude_km, terminal_velocity_m_s", f"{altitude:g} km, {speed:.1f} m/s",
               f"{interface.speed_words} ({interface.speed_m_s:.1f} m/s), or {Q_SPEED_FRACTION:g} of the speed where "
               f"the planned dynamic-pressure bound is met at the altitude when lower"),
        Choice("guidance.grid", ", ".join(f"{n} {steps[n]:g} {units.get(n, 'deg')}" for n in names),
               "the entry deviations that move the end most, each at its 3-sigma reach (end moved by "
               + ", ".join(f"{n} {effects[n] / 1e3:.3g} km" for n in ranked)
               + (f"; {', '.join(left)} left to the tracker" if left else "") + ")"),
        Choice("guidance.ld_nodes", nodes,
               f"a planned bank reversal ({reversal:.0f} s) spans two LGL intervals or more in a flight of about "
               f"{duration:.0f} s (the range over the mean speed), within {LD_NODES_RANGE[0]}-{LD_NODES_RANGE[1]}: "
               f"one global polynomial through fewer nodes overshoots a reversal (paper 004's CAV-H at 60 nodes: the "
               f"reference bank at 130 deg against the planned 76.5, the nominal 124 km off; at 200, 6 km)"),
        Choice("guidance.tracking_state_weight", TRACKING_STATE_WEIGHT,
               "the TVLQR holds the reference along a long glide, not only at its end (paper 003's 1e-5 left "
               "Lu 2014's CAV-H nominal 3440 km off)"),
        Choice("guidance.path_gain, path_limit_fraction", f"{spec.path_gain:g}, {spec.path_limit_fraction:g}",
               "Lu 2014's path-limit feedback on the tracker's command (FNPEG's), holding that fraction of the "
               "vehicle's limits, which the TVLQR does not see (the capsule's final dive: q over in 21 of 100 runs "
               "without it)" if spec.path_gain > 0 else "the vehicle states no limit to hold"),
        Choice("alpha", "as the mission's" if own_alpha else ", ".join(
            f"{v:g} deg" + ("" if len(alpha.breakpoints) == 1 else f" at {b:g}")
            for b, v in zip(alpha.breakpoints, alpha.values_deg)) + f" ({alpha.variable})",
            f"{source} alpha schedule, flown by the database's problem and the closed loop alike"),
    ]
    # one database serves both candidates (the index is not in its fingerprint): the search's
    # flights cost seconds once it is built
    search = [SearchStep.over("guidance.tracking_index", TRACKING_INDICES,
                              "read in time, the reference asks the state a flight that spends its energy sooner or "
                              "later has not reached; read in energy, the altitude and speed it trades at that energy "
                              "(10 runs of Lu 2014's CAV-H: 64 km median miss in time, 28 km in energy; paper 004's "
                              "CAV-H: 70 km in time, 144 km in energy): every candidate flown, the best kept",
                              exhaustive=True)]
    forces = force_dispersions(scenario.dispersions)
    if forces:
        search.append(SearchStep.over(
            "guidance.model_scales", (False, True),
            f"the mission disperses {', '.join(forces)}: a reference planned with the nominal models asks a denser "
            f"or draggier flight for the nominal altitude; read at the sensed ratios it asks the altitude of the "
            f"reference's drag (the capsule's 6 campaign draws: 9-13 km misses as planned, 1.7-3.2 km read at the "
            f"sensed ratios): both flown, the better kept", exhaustive=True))
    if tolerance_km:
        search.append(SearchStep.over(
            "guidance.terminal_scales", [terminal_scales(f) for f in TERMINAL_POSITION_FRACTIONS],
            "the TVLQR's final position weighted at " + " or ".join(f"{f:g}" for f in TERMINAL_POSITION_FRACTIONS)
            + " of the box's distance tolerance: the heavier pulls a short flight home and throws a long glide off "
            "(20 runs: paper 004's CAV-H 18 of 20 against 5; Lu 2014's CAV-H 558 km median against 19): both flown, "
            "the better kept", exhaustive=True))
    else:
        choices.append(Choice("guidance.terminal_scales", spec.terminal_scales, "paper 003's (the box checks no distance)"))
    return Derivation(spec, choices, search, alpha=None if own_alpha else alpha)

