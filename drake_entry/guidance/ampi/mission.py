"""AMPI's trajectory database for any mission: the problem it solves, where it is cached.

Paper 003 builds its database for SHEFEX-3's own problem (Sec. III). With ``database:
mission`` the guidance poses that problem's form from the scenario instead
(``mission_problem_spec``): from the entry state to the target, ending at the energy where the
closed loop stops (the guidance's terminal altitude and speed) within an altitude window (in the
mission's altitude datum), alpha the mission's schedule, the bank a state driven by its rate within the vehicle's
limits, the vehicle's heat-flux, dynamic-pressure and load limits planned ``path_margin`` inside,
the bank-effort objective. The problem is written as a problem file; the database study
(guidance.ampi.database_study) solves it on the spec's grid of entry offsets; a few entries
drawn like the campaign's are then solved afresh and compared with their AMPI references
(guidance.ampi.accuracy_study: the interpolation error, paper 003 Sec. V).

The database is built before the first plan (the method's preparation,
guidance.ampi.mission_study) into the user's cache (drake_entry.user_cache), in a folder named by
the fingerprint of the problem file, the grid, the solve settings, a user vehicle file's content,
the drake_entry and Drake versions and the source of the code that builds it (``BUILD_SOURCES``:
a change to the build's rules builds afresh rather than reusing an older build); the planner
loads it from there (``built_database``).
"""
from __future__ import annotations

import dataclasses as dc
import functools
import hashlib
import importlib.util
import json
import math
import os

from pydrake.common.yaml import yaml_dump_typed

from drake_entry.errors import ScenarioError
from drake_entry.guidance.ampi.spec import MISSION_DATABASE
from drake_entry.guidance.derivation import box_altitude_tolerance_km
from drake_entry.models.vehicles import PACKAGED_VEHICLES
from drake_entry.planning.ocp_yaml import (
    AlphaScheduleSpec,
    BoundSpec,
    ObjectiveSpec,
    PathSpec,
    ProblemSpec,
    SolveSpec,
)

__all__ = ["PROBLEM_FILE", "DATABASE_FILE", "REPORT_FILE", "BANK_FRACTION", "BANK_RATE_FRACTION",
           "GAMMA_BOUNDS_DEG", "FLIGHT_PATH_SCALE_DEG", "FLIGHT_PATH_WEIGHT", "ALTITUDE_WINDOW_FRACTION",
           "ALTITUDE_WINDOW_M", "RATE_WEIGHT", "TOLERANCE", "mission_problem_spec", "database_folder",
           "read_built", "built_database", "fingerprint", "MissionDatabase", "BUILD_SOURCES",
           "source_digest", "build_source_digest"]

#: the references end at the energy where the flight stops (the guidance's terminal altitude and
#: speed: a reference ending at another energy leaves flight unplanned, or is cut short), at an
#: altitude within this fraction of the box's altitude tolerance about the terminal altitude
#: (ALTITUDE_WINDOW_M where the box gives none), the speed free: fixing it too leaves the
#: optimiser one point of the box
ALTITUDE_WINDOW_FRACTION = 0.5
ALTITUDE_WINDOW_M = 500.0
#: the flight-path bounds of a mission's database problem [deg] (the LGL guidance's on a mission:
#: they keep the heading equation off its singularity at -90 deg)
GAMMA_BOUNDS_DEG = (-60.0, 15.0)
#: the flight-path term added to the bank effort: (gamma / FLIGHT_PATH_SCALE_DEG)^2 at this weight.
#: Without it the least bank over a long glide is a skipping flight (Lu 2014's CAV-H: the
#: reference climbed from 38 to 87 km and back three times, and the tracker held none of 10
#: flights); bounding gamma <= 0 instead left a level flight at 41 km that needed the bank at its
#: limit (0/1)
FLIGHT_PATH_SCALE_DEG, FLIGHT_PATH_WEIGHT = 1.0, 1.0
#: the planned bank's and bank rate's bounds as fractions of the vehicle's: the tracker's room.
#: Lu 2014's CAV-H nominal (tracking weight 1e-2): planned at the vehicle's 85 deg and 20 deg/s it
#: ended 147 km off, dipping 7 km under the reference in its reversal (q 186 kPa against 100); at a
#: quarter of the rate, 14 km off (the reference at 89.7 deg, beyond the limit, where the cases
#: interpolate); with the bank at 0.9 of the limit too, 0.18 km
BANK_FRACTION, BANK_RATE_FRACTION = 0.9, 0.25
#: the bank-rate term's weight in the bank-effort objective (problems/shefex3.yaml's)
RATE_WEIGHT = 0.1
#: the bank magnitude the bank effort is measured from, as a fraction of the planned bank bound
BANK_CENTRE_FRACTION = 0.5
#: the NLP's optimality tolerance (problems/shefex3.yaml's). The transcription is Hermite-Simpson
#: with mesh refinement from the spec's nodes: HORUS-2B's 1400-s glide on 100 nodes was converged
#: but inaccurate (0.0043 between the nodes on 160 dircol nodes; 0.015 on 4 LGL segments of 121
#: nodes); refined to 220 nodes it is verified (0.00052 between the nodes) in 14 s
TOLERANCE = 1.0e-6
#: files of a built database's folder
PROBLEM_FILE, DATABASE_FILE, REPORT_FILE = "problem.yaml", "database.npz", "build.json"


def mission_problem_spec(spec, scenario) -> ProblemSpec:
    """The optimal-control problem (a ProblemSpec, as a problem file states it) the database
    solves for ``scenario``'s mission with the Ampi ``spec``: paper 003 Sec. III's form (bank
    rate control, alpha scheduled, bank effort, here with a flight-path term) on the mission (module docstring), ending over
    the target at the energy where the closed loop stops, inside the altitude window."""
    vehicle = scenario.make_vehicle()
    limits = vehicle.limits
    alpha = scenario.schedule("alpha")
    breakpoints = [float(b) for b in alpha.breakpoints]
    schedule = AlphaScheduleSpec(variable=alpha.variable, values_deg=[math.degrees(v) for v in alpha.values],
                                 smooth=bool(alpha.smooth),
                                 **({"breakpoints_s": breakpoints} if alpha.variable == "time" else
                                    {"breakpoints": breakpoints}))
    e, target = scenario.entry, scenario.target
    initial = {"altitude_km": e.altitude_km, "longitude_deg": e.longitude_deg, "latitude_deg": e.latitude_deg,
               "velocity_m_s": e.velocity_m_s, "flight_path_deg": e.flight_path_deg, "heading_deg": e.heading_deg,
               "time_s": 0.0}
    kind, load_max = limits.planned_load()
    keep = 1.0 - spec.path_margin
    path = [PathSpec(quantity=q, max=keep * bound) for q, bound in (("heat_flux", limits.heat_flux_max),
                                                                   ("dynamic_pressure", limits.dynamic_pressure_max),
                                                                   (f"{kind}_load", load_max))
            if math.isfinite(bound)]
    h_f = spec.terminal_altitude_km * 1e3
    E_f = dc.replace(scenario, guidance=spec).guidance_terminal_state()[2]  # where the closed loop stops
    tol = box_altitude_tolerance_km(scenario.terminal)
    window = ALTITUDE_WINDOW_FRACTION * tol * 1e3 if tol else ALTITUDE_WINDOW_M
    # the terminal altitude in the mission's datum: geodetic (a terminal constraint) with
    # altitude_datum 'ellipsoid' or on a spherical planet (where the two altitudes are one), else
    # the state altitude (a final bound; SPHYNX's 3.83-km state altitude at the site is 11.5 km
    # geodetic, and a geodetic window about 3.83 km was infeasible). The two forms pose the same
    # problem on a sphere, but the solver's path differs and with it the local optima the bank
    # effort's flat valley offers: the capsule's database as a final bound flew 4 of 10 draws
    # that the terminal constraint's database lands 10 of 10
    altitude_window = {"min": h_f - window, "max": h_f + window}
    geodetic = scenario.altitude_datum == "ellipsoid" or scenario.make_planet().is_spherical
    final_altitude = {} if geodetic else {"altitude_km": BoundSpec(**{k: v / 1e3 for k, v in altitude_window.items()})}
    terminal_altitude = [PathSpec(quantity="geodetic_altitude", **altitude_window, scale=1.0e4)] if geodetic else []
    bank = BANK_FRACTION * math.degrees(vehicle.bank_limit)
    rate = BANK_RATE_FRACTION * math.degrees(vehicle.bank_rate_limit)
    return ProblemSpec(
        name=f"ampi_{MISSION_DATABASE}",  # no scenario name: the same mission under another name is the same problem
        description="paper 003's database problem posed from a mission",
        source="drake_entry.guidance.ampi.mission.mission_problem_spec", vehicle=_vehicle_name(scenario),
        aero=scenario.aero, planet=dc.replace(scenario.planet), altitude_datum=scenario.altitude_datum,
        atmosphere=dc.replace(scenario.atmosphere), controls="bank_rate", alpha_schedule=schedule,
        initial={k: BoundSpec(value=float(v)) for k, v in initial.items()},
        final={"longitude_deg": BoundSpec(value=float(target.longitude_deg)),
               "latitude_deg": BoundSpec(value=float(target.latitude_deg)), **final_altitude},
        final_time_s=BoundSpec(min=1.0, max=float(scenario.simulation.max_time_s)),
        state_bounds={"bank_deg": BoundSpec(min=-bank, max=bank),
                      "flight_path_deg": BoundSpec(min=GAMMA_BOUNDS_DEG[0], max=GAMMA_BOUNDS_DEG[1])},
        control_bounds={"bank_rate_deg_s": BoundSpec(min=-rate, max=rate)},
        path=path,
        terminal=[PathSpec(quantity="central_energy", min=E_f, max=E_f), *terminal_altitude],
        objective=[ObjectiveSpec(kind="bank_effort", bank_max_deg=bank, bank_rate_max_deg_s=rate,
                                 rate_weight=RATE_WEIGHT, bank_centre_deg=BANK_CENTRE_FRACTION * bank),
                   ObjectiveSpec(kind="flight_path_effort", weight=FLIGHT_PATH_WEIGHT,
                                 scale=math.radians(FLIGHT_PATH_SCALE_DEG))],
        solve=SolveSpec(transcription="hermite_simpson", solver="auto", nodes=int(spec.nodes), tolerance=TOLERANCE,
                        refine=True))


def _vehicle_name(scenario) -> str:
    """The scenario's vehicle as a problem file names it: a packaged name, or an absolute path."""
    if scenario.vehicle in PACKAGED_VEHICLES:
        return scenario.vehicle
    return os.path.abspath(scenario.vehicle)


#: the packages whose code builds a database: the database, accuracy and mission studies, the
#: optimal-control transcription and solver settings, the models and the Drake systems and
#: diagrams the cases are verified with. Their source is in the fingerprint: drake_entry's
#: version number changes only at a release, so without it a change to the build's rules
#: (re-solve criteria, a constraint's form) would silently load a database built by older rules
BUILD_SOURCES = ("drake_entry.guidance.ampi", "drake_entry.planning", "drake_entry.models",
                 "drake_entry.systems", "drake_entry.diagrams")


def source_digest(folders) -> str:
    """The sha256 hex digest of every ``.py`` file under ``folders``: each file's path relative
    to its folder and its bytes, in sorted order (byte-compiled caches and other files ignored)."""
    h = hashlib.sha256()
    for folder in folders:
        files = sorted(os.path.relpath(os.path.join(root, name), folder)
                       for root, _, names in os.walk(folder) for name in names if name.endswith(".py"))
        for rel in files:
            h.update(rel.replace(os.sep, "/").encode())
            h.update(b"\0")
            with open(os.path.join(folder, rel), "rb") as f:
                h.update(f.read())
            h.update(b"\0")
    return h.hexdigest()


@functools.lru_cache(maxsize=1)
def build_source_digest() -> str:
    """source_digest of the installed BUILD_SOURCES packages (computed once per process)."""
    folders = []
    for name in BUILD_SOURCES:
        found = importlib.util.find_spec(name)
        folders.extend(found.submodule_search_locations)
    return source_digest(folders)


def fingerprint(spec, scenario) -> tuple[str, str]:
    """(the problem file's text, the hex fingerprint of everything the database depends on)."""
    import importlib.metadata

    import drake_entry

    text = yaml_dump_typed(mission_problem_spec(spec, scenario))
    h = hashlib.sha256()
    for part in (text, json.dumps(dict(spec.grid), sort_keys=True), str(spec.grid_levels), str(spec.ld_nodes),
                 str(spec.accuracy_cases),
                 drake_entry.__version__, importlib.metadata.version("drake"), build_source_digest()):
        h.update(part.encode())
        h.update(b"\0")
    if scenario.vehicle not in PACKAGED_VEHICLES:  # a user's vehicle file: its content, not its name
        with open(scenario.vehicle, "rb") as f:
            h.update(f.read())
    return text, h.hexdigest()[:20]


@dc.dataclass
class MissionDatabase:
    """A built mission database: ``path`` of its database.npz, ``folder``, the build ``report``
    (cases, verified, re-solved, wall time) and the ``accuracy`` of its references against fresh
    solves (accuracy_study.summarise), ``cached``: loaded, not built, by this call."""

    path: str
    folder: str
    report: dict
    accuracy: dict
    cached: bool


def database_folder(spec, scenario) -> tuple[str, str, str]:
    """(the cache folder of this mission's database, its fingerprint, the problem file's text)."""
    from drake_entry.user_cache import cache_dir

    text, key = fingerprint(spec, scenario)
    return os.path.join(cache_dir("ampi"), key), key, text


def read_built(folder: str) -> MissionDatabase | None:
    """The database built in ``folder`` (database_folder), or None when none is finished there."""
    report = os.path.join(folder, REPORT_FILE)
    if not os.path.exists(report):
        return None
    with open(report) as f:
        done = json.load(f)
    return MissionDatabase(os.path.join(folder, DATABASE_FILE), folder, done["build"], done["accuracy"], True)


def built_database(spec, scenario) -> MissionDatabase:
    """The built database of ``scenario``'s mission; a ScenarioError saying how to build it when
    it is not in the cache."""
    folder, key, _ = database_folder(spec, scenario)
    built = read_built(folder)
    if built is None:
        raise ScenarioError(f"the AMPI database of mission '{scenario.name}' (fingerprint {key}) is not built: "
                            f"`drake-entry plan`, `campaign` and `compare` build it first; from Python call "
                            f"drake_entry.campaign.preparation.prepare(scenario)")
    return built
