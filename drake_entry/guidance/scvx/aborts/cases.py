"""Abort reachability of paper 001 Sec. VI: the cases of an orbital-abort map and of descent
aborts, and the statistics of its Tables 4-7.

Orbital aborts (Sec. VI.A): a grid of entry interface points around the mission's, spaced
5 deg in longitude and latitude (the paper's spacing; its grid extent and the way it computed
each EIP's state (its Ref. 51, an MSc thesis) are not public). SUBSTITUTE, labelled: every EIP
keeps the mission's altitude, speed and flight-path angle, and its heading is the great-circle
bearing to the site plus the nominal EIP's heading offset from that bearing (-14.0 deg on
Table 1's mission), so each entry sees the site as the nominal one does.

Descent aborts (Sec. VI.B): the nominal plan is flown and, every 50 s, its flown state and
attitude start a new plan to an alternative site (minimum miss, as the paper switched to);
``ALTERNATIVE_SITES`` gives the sites the paper names (their coordinates are not in the
paper: public approximate locations, labelled).

A case is feasible at radius r (the paper counts 10 km and 40 km) when its plan succeeded
(converged, checked between the nodes and propagated within 5 km), its planned DRS point is
within the 10-km site radius, and its controls flown by the Drake Simulator end within r of
the site.
"""
from __future__ import annotations

import dataclasses as dc
import math

import numpy as np

from drake_entry.errors import ScenarioError
from drake_entry.guidance.scvx.mission import ENTRY_SPEED_RANGE_M_S, SITE_RADIUS_MAX_M, ScvxMission
from drake_entry.models import geodesy
from drake_entry.models.planet import Earth

__all__ = ["GRID_SPACING_DEG", "GRID_SHAPE", "FEASIBLE_RADII_M", "DESCENT_ABORT_SPACING_S", "OPEN_SITE_RADIUS_M",
           "ALTERNATIVE_SITES", "PAPER_TABLES", "COLUMN_NOTES", "heading_offset", "orbital_abort_cases",
           "CASE_FIELDS", "case_mission", "descent_abort_cases", "feasible", "abort_statistics",
           "statistics_markdown"]

#: the paper's grid spacing [deg] and the smallest map the issue asks for
GRID_SPACING_DEG = 5.0
GRID_SHAPE = (9, 9)
#: miss radii [m] at which feasibility is counted (paper 001 Sec. VI: 10 km planned, 40 km flown)
FEASIBLE_RADII_M = (10e3, 40e3)
#: descent-abort trigger spacing [s] (paper 001 Sec. VI.B)
DESCENT_ABORT_SPACING_S = 50.0
#: the site cone of a minimum-miss descent abort [m]: opened to the largest a mission accepts
OPEN_SITE_RADIUS_M = SITE_RADIUS_MAX_M
#: alternative sites (longitude, geodetic latitude) [deg]. Not given in the paper: public
#: approximate locations (town centres), labelled substitutes.
ALTERNATIVE_SITES = {"ben_guerir": (-7.95, 32.23), "gran_canaria": (-15.39, 27.93)}

#: paper 001 Tables 4-7 (orbital aborts, direct formulation, minimum heat load):
#: quantity -> (unit, mean, standard deviation, maximum, minimum)
PAPER_TABLES = {
    "Table 4": {"heat_load_MJ_m2": ("MJ/m^2", 564.859, 34.314, 630.185, 490.266),
                "final_time_s": ("s", 1850.11, 175.47, 2196.36, 1515.12),
                "planned_miss_km": ("km", 9.283, 0.660, 9.996, 8.010),
                "max_heat_flux_kW_m2": ("kW/m^2", 670.002, 0.066, 670.174, 669.778),
                "max_load_g": ("g", 2.271, 0.480, 3.000, 1.330)},
    "Table 5": {"drs_altitude_km": ("km", 10.37, 0.81, 12.73, 10.01),
                "drs_mach": ("-", 0.533, 0.057, 0.712, 0.507),
                "drs_vertical_speed_m_s": ("m/s", -60.43, 5.84, -55.32, -81.77),
                "max_dynamic_pressure_kPa": ("kPa", 6.64, 1.01, 8.75, 5.10)},
    "Table 6": {"bank_effort_deg": ("deg", 566.1, 235.8, 1030.1, 218.2),
                "max_bank_rate_deg_s": ("deg/s", 3.86, 1.48, 5.00, 0.91),
                "alpha_effort_deg": ("deg", 41.2, 6.1, 59.2, 30.6),
                "max_alpha_rate_deg_s": ("deg/s", 0.223, 0.028, 0.290, 0.170)},
    "Table 7": {"plan_wall_s": ("s", 75.5, 26.57, 212.1, 28.9),
                "iterations": ("-", 21.8, 3.5, 40.0, 14.0),
                "mean_socp_iterations": ("-", 72.88, 22.11, 142.0, 41.24),
                "rejected_steps": ("-", 1.5, 3.3, 23.0, 0.0)},
}
#: what our column measures where the paper's differs (Table 7's 'Warnings' are numerical warnings of its solver)
COLUMN_NOTES = {"rejected_steps": "rejected SCvx steps and failed SOCPs (the paper counts solver warnings)",
                "planned_miss_km": "planned DRS point to the site"}


def heading_offset(mission: ScvxMission, planet: Earth) -> float:
    """The mission's entry heading minus the great-circle bearing from its EIP to its site [deg]."""
    x0 = mission.entry_state(planet)
    bearing = math.degrees(geodesy.bearing(x0[1], x0[2], *mission.site(planet)))
    return (mission.entry_heading_deg - bearing + 180.0) % 360.0 - 180.0


def orbital_abort_cases(mission: ScvxMission, planet: Earth, *, shape: tuple = GRID_SHAPE,
                        spacing_deg: float = GRID_SPACING_DEG) -> list[dict]:
    """The EIP grid of an orbital-abort map, centred on the mission's EIP (module doc): one
    dict per entry point with 'index', grid 'row'/'column', the mission fields it changes
    (entry_longitude_deg, entry_latitude_deg (geodetic), entry_heading_deg) and its
    great-circle 'range_km' to the site."""
    rows, cols = shape
    for name, n in (("rows", rows), ("columns", cols)):
        if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or not 1 <= n <= 101:
            raise ScenarioError(f"orbital abort grid {name} = {n} is out of range; allowed: an integer in [1, 101]")
    if not 0.1 <= spacing_deg <= 30.0:
        raise ScenarioError(f"orbital abort spacing_deg = {spacing_deg} is out of range [0.1, 30] deg")
    offset = heading_offset(mission, planet)
    site = mission.site(planet)
    cases = []
    for i in range(rows):
        lat = mission.entry_latitude_deg + (i - (rows - 1) / 2) * spacing_deg
        if not -80.0 <= lat <= 80.0:
            raise ScenarioError(f"orbital abort grid reaches latitude {lat:.1f} deg; allowed: within 80 deg of the "
                                f"equator (fewer rows or a smaller spacing)")
        for j in range(cols):
            lon = mission.entry_longitude_deg + (j - (cols - 1) / 2) * spacing_deg
            h, lat_c = planet.from_geodetic(mission.entry_altitude_m, math.radians(lat))
            bearing = math.degrees(geodesy.bearing(math.radians(lon), lat_c, *site))
            heading = (bearing + offset + 10.0) % 360.0 - 10.0  # inside eq. 70's [-10, 270) where it can be
            cases.append({"index": len(cases), "row": i, "column": j, "entry_longitude_deg": lon,
                          "entry_latitude_deg": lat, "entry_heading_deg": heading,
                          "range_km": planet.great_circle_distance(math.radians(lon), lat_c, *site) / 1e3})
    return cases


#: the ScvxMission fields a case may change
CASE_FIELDS = ("entry_altitude_m", "entry_longitude_deg", "entry_latitude_deg", "entry_speed_m_s",
               "entry_flight_path_deg", "entry_heading_deg", "entry_bank_deg", "entry_alpha_deg",
               "site_longitude_deg", "site_latitude_deg", "site_radius_m")


def case_mission(mission: ScvxMission, case: dict) -> ScvxMission:
    """The mission of one abort case: ``mission`` with the case's CASE_FIELDS."""
    return dc.replace(mission, **{k: case[k] for k in CASE_FIELDS if k in case},
                      name=f"{mission.name}_abort_{case['index']}")


def descent_abort_cases(time, states, bank, alpha, planet: Earth, *, site: tuple, spacing_s: float =
                        DESCENT_ABORT_SPACING_S, site_radius_m: float = 10e3,
                        flight_path_bounds_deg=ScvxMission.flight_path_bounds_deg) -> list[dict]:
    """Descent aborts along a flown nominal: every ``spacing_s`` seconds (from spacing_s to the
    end) its state (time [s], states (n, 6) SI, bank and alpha [rad] at those times) becomes an
    abort's entry state and held attitude, with the alternative ``site`` (longitude, geodetic
    latitude) [deg]. Triggers where the flown gamma lies outside ``flight_path_bounds_deg`` are
    moved to the bound (the planner's start must satisfy eq. 70); triggers where the flown speed
    is below the planner's range (``ENTRY_SPEED_RANGE_M_S``: 500 m/s, the last minute before the
    DRS point) are not cases."""
    if not 1.0 <= spacing_s <= 1e4:
        raise ScenarioError(f"descent abort spacing_s = {spacing_s} is out of range [1, 10000] s")
    time = np.asarray(time, float)
    cases = []
    for t_a in np.arange(spacing_s, time[-1], spacing_s):
        x = np.array([np.interp(t_a, time, states[:, k]) for k in range(6)])
        if x[3] < ENTRY_SPEED_RANGE_M_S[0]:
            break
        h_geo, lat_geo = planet.geodetic(planet.radius(x[0]), x[2])
        gamma = float(np.clip(math.degrees(x[4]), *flight_path_bounds_deg))
        cases.append({"index": len(cases), "abort_time_s": float(t_a), "entry_altitude_m": float(h_geo),
                      "entry_longitude_deg": math.degrees(x[1]), "entry_latitude_deg": math.degrees(float(lat_geo)),
                      "entry_speed_m_s": float(x[3]), "entry_flight_path_deg": gamma,
                      "entry_heading_deg": math.degrees(x[5]),
                      "entry_bank_deg": math.degrees(float(np.interp(t_a, time, bank))),
                      "entry_alpha_deg": math.degrees(float(np.interp(t_a, time, alpha))),
                      "site_longitude_deg": float(site[0]), "site_latitude_deg": float(site[1]),
                      "site_radius_m": float(site_radius_m)})
    return cases


def feasible(row: dict, radius_m: float) -> bool:
    """Paper 001's feasibility of an abort row at ``radius_m`` (module doc)."""
    return bool(row.get("plan_success") and row.get("planned_miss_km", math.inf) <= FEASIBLE_RADII_M[0] / 1e3 + 1e-9
                and row.get("flown_miss_km", math.inf) <= radius_m / 1e3)


def abort_statistics(rows: list, radius_m: float = FEASIBLE_RADII_M[1]) -> dict:
    """Tables 4-7 form over the rows feasible at ``radius_m``: {table: {quantity: (mean,
    standard deviation, maximum, minimum)}} (NaN when no row is feasible)."""
    good = [r for r in rows if feasible(r, radius_m)]
    out = {}
    for table, quantities in PAPER_TABLES.items():
        out[table] = {}
        for q in quantities:
            v = np.array([float(r[q]) for r in good if r.get(q) is not None], float)
            v = v[np.isfinite(v)]
            out[table][q] = ((float(v.mean()), float(v.std()), float(v.max()), float(v.min())) if v.size
                             else (math.nan,) * 4)
    return out


def statistics_markdown(stats: dict, *, paper: bool = True) -> str:
    """Markdown tables of ``abort_statistics`` (ours, then the paper's value beside each)."""
    lines = []
    for table, quantities in stats.items():
        lines += ["", f"**{table} form** (ours / paper 001)", "",
                  "| quantity | unit | mean | std | max | min |", "|---|---|---|---|---|---|"]
        for q, values in quantities.items():
            unit, *published = PAPER_TABLES[table][q]
            cells = [f"{v:.4g} / {p:.4g}" if paper else f"{v:.4g}" for v, p in zip(values, published)]
            note = f" ({COLUMN_NOTES[q]})" if q in COLUMN_NOTES else ""
            lines.append(f"| {q}{note} | {unit} | " + " | ".join(cells) + " |")
    return "\n".join(lines)
