"""Scenario spec of paper 003's database guidance; YAML tag ``guidance: !Ampi``."""

import dataclasses as dc
import math
import os
from importlib import resources
from typing import Dict

from drake_entry.errors import ScenarioError, check_range
from drake_entry.guidance.spec import GuidanceSpecBase

__all__ = ["MISSION_DATABASE", "MAX_MISSION_CASES", "MODES", "TRACKING_INDICES", "packaged_databases", "database_path", "Ampi"]

#: the ``database`` value that builds the database for the scenario's own mission
MISSION_DATABASE = "mission"
#: the most grid cases a mission database may have (3^5: an hour of solves on 2 cores at 30 s each)
MAX_MISSION_CASES = 243

#: how the on-board reference is made: AMPI synthesis or the nearest entry (NTT)
MODES = ("ampi", "ntt")
#: what the tracker reads its reference at: the flight's clock, or the reference time of the
#: flight's energy (systems/reference_tracking.py)
TRACKING_INDICES = ("time", "energy")


def packaged_databases() -> tuple:
    """Names of the trajectory databases shipped in drake_entry/data/ampi (``<name>.npz``, built by
    guidance/ampi/database_study.py)."""
    folder = resources.files("drake_entry").joinpath("data/ampi")
    return tuple(sorted(p.name[:-4] for p in folder.iterdir() if p.name.endswith(".npz")))


def database_path(name_or_path: str) -> str:
    """The file of a packaged database name or a path."""
    if name_or_path in packaged_databases():
        return str(resources.files("drake_entry").joinpath(f"data/ampi/{name_or_path}.npz"))
    if os.path.exists(name_or_path):
        return name_or_path
    raise ScenarioError(f"database '{name_or_path}' is neither a packaged database "
                        f"({', '.join(packaged_databases())}) nor a file")


@dc.dataclass
class Ampi(GuidanceSpecBase):
    """A reference made at the entry interface from the trajectory database (paper 003) and
    tracked in time by a TVLQR (planning.tracking) through the shared bank actuator; alpha is
    the scenario's schedule (Table 2). ``reference``: 'ampi' (Algorithms 1-2 from the 2^6
    enclosing entries) or 'ntt' (the nearest entry, the paper's comparison); the same
    controller flies both.

    The flight stops at the energy of (terminal_altitude_km, terminal_velocity_m_s): with the
    scenario's altitude_datum 'ellipsoid' the altitude is geodetic at the target's latitude.
    The defaults are where the packaged database's references end (bank-effort optimum: the
    corner h 21.0-21.4 km, V 620 m/s of Table 1's window)."""

    #: fields naming a file: a relative path is read beside the scenario file (typed_yaml.resolve_file_fields)
    FILE_FIELDS = ('database',)

    terminal_altitude_km: float = 21.1
    terminal_velocity_m_s: float = 620.0
    period_s: float = 0.5
    # packaged database name, .npz path (guidance/ampi/database_study.py builds one), or
    # 'mission': built for the scenario's own mission on demand and cached (guidance/ampi/mission.py)
    database: str = "shefex3"
    # database 'mission' only: the grid of entry offsets, {state: step} in m, deg or m/s (h,
    # lon, lat, V, gamma, psi; paper 003 eq. 5's form), with grid_levels levels each (odd:
    # the nominal at the centre); the LD nodes each solution is stored at (eq. 11's N_LD); the
    # NLP's nodes (Hermite-Simpson); the planned fraction of each vehicle limit kept free; the
    # fresh solves its references are checked against
    grid: Dict[str, float] = dc.field(default_factory=dict)
    grid_levels: int = 3
    ld_nodes: int = 60
    nodes: int = 100
    path_margin: float = 0.07
    accuracy_cases: int = 3
    reference: str = "ampi"
    # eq. 11's N_HD: equally spaced reference samples the tracker interpolates linearly
    hd_points: int = 601
    # TVLQR: the deviations that cost 1 (Q = state_weight I on the scaled states; Q_f on the
    # final position, altitude and speed) [m, deg, m/s, deg]; the rate deviation that costs 1
    # [deg/s]; linearisation samples
    tracking_scales: list[float] = dc.field(default_factory=lambda: [1000.0, 0.1, 0.1, 10.0, 0.1, 0.1, 1.0])
    tracking_state_weight: float = 1.0e-5
    terminal_scales: list[float] = dc.field(default_factory=lambda: [1000.0, 0.01, 0.01, 10.0])
    tracking_rate_deg_s: float = 1.0
    gain_samples: int = 120
    # the command leads the reference bank by the lag of the bank loop it drives: the shared
    # actuator's position loop (1/bandwidth = 0.5 s), its rate loop (0.125 s) and the command's
    # zero-order hold (period/2 = 0.25 s). Measured on the SHEFEX-3 nominal: lead 0 misses by
    # 16.9 km, 0.75 s and 1.0 s by < 1.3 km (docs/methods/ampi.md)
    bank_lead_s: float = 0.75
    # what the tracker reads the reference at: 'time' (the flight's clock, paper 003's) or
    # 'energy' (the reference time of the estimate's energy; systems/reference_tracking.py)
    tracking_index: str = "time"
    # read the reference at the lift and drag ratios the flight has sensed (the altitude where
    # the sensed drag is the reference's, the bank that gives its vertical lift there;
    # systems/reference_tracking.py); off: the reference as planned with the nominal models
    model_scales: bool = False
    # Lu 2014's path-limit feedback on the tracker's command (not paper 003's, whose tracker sees no
    # limit: a flight away from its reference may pass one): gain (0 = off; Lu: 40), prediction
    # horizon [s], the fraction of the vehicle's limits held (guidance/path_feedback.py)
    path_gain: float = 0.0
    path_horizon_s: float = 16.0
    path_limit_fraction: float = 0.95

    def _validate_mission_fields(self) -> None:
        from drake_entry.guidance.ampi.grid import PARAMETERS

        if not self.grid:
            raise ScenarioError(f"guidance.grid: database '{MISSION_DATABASE}' needs the grid of entry offsets, "
                                f"e.g. {{velocity: 15.0}} ({', '.join(PARAMETERS)}: m, deg, m/s)")
        for name, step in self.grid.items():
            if name not in PARAMETERS:
                raise ScenarioError(f"guidance.grid.{name}: not an entry state; allowed: {', '.join(PARAMETERS)}")
            check_range(f"guidance.grid.{name}", step, 1e-9, 1e6)
        check_range("guidance.grid_levels", self.grid_levels, 3, 9)
        if self.grid_levels % 2 == 0:
            raise ScenarioError(f"guidance.grid_levels = {self.grid_levels}: give an odd number (the nominal entry "
                                f"at the centre)")
        if self.grid_levels ** len(self.grid) > MAX_MISSION_CASES:
            raise ScenarioError(f"guidance.grid: {self.grid_levels}^{len(self.grid)} = "
                                f"{self.grid_levels ** len(self.grid)} cases; allowed up to {MAX_MISSION_CASES}")
        check_range("guidance.ld_nodes", self.ld_nodes, 3, 400)
        check_range("guidance.nodes", self.nodes, 10, 1000)
        check_range("guidance.path_margin", self.path_margin, 0.0, 0.5)
        check_range("guidance.accuracy_cases", self.accuracy_cases, 1, 1000)

    def terminal_speed(self, speed_of_sound: float) -> float:
        return self.terminal_velocity_m_s

    def weights(self):
        """The TVLQR weights (planning.tracking.TrackingWeights) of these fields."""
        from drake_entry.planning.tracking import TrackingWeights
        d = math.radians
        h, lon, lat, V, gamma, psi, sigma = self.tracking_scales
        hf, lonf, latf, Vf = self.terminal_scales
        return TrackingWeights(
            state_scale={"h": h, "lon": d(lon), "lat": d(lat), "V": V, "gamma": d(gamma), "psi": d(psi),
                         "sigma": d(sigma)},
            control_scale={"u_sigma": d(self.tracking_rate_deg_s)}, state_weight=self.tracking_state_weight,
            terminal_scale={"h": hf, "lon": d(lonf), "lat": d(latf), "V": Vf})

    def validate(self, scenario) -> None:
        super().validate(scenario)
        check_range("guidance.terminal_velocity_m_s", self.terminal_velocity_m_s, 1.0, scenario.entry.velocity_m_s)
        if self.reference not in MODES:
            raise ScenarioError(f"guidance.reference = '{self.reference}'; allowed: {', '.join(MODES)}")
        if self.database == MISSION_DATABASE:
            self._validate_mission_fields()
        else:
            try:
                database_path(self.database)
            except ScenarioError as e:
                raise ScenarioError(f"guidance.{e}") from None
            if self.grid:
                raise ScenarioError(f"guidance.grid: only with database '{MISSION_DATABASE}' (database "
                                    f"'{self.database}' has its own grid)")
        check_range("guidance.hd_points", self.hd_points, 2, 100000)
        check_range("guidance.gain_samples", self.gain_samples, 2, 10000)
        for name, values, n in (("tracking_scales", self.tracking_scales, 7), ("terminal_scales", self.terminal_scales, 4)):
            if len(values) != n:
                raise ScenarioError(f"guidance.{name} needs {n} values, got {len(values)}")
            for v in values:
                check_range(f"guidance.{name}", v, 1e-9, 1e9)
        check_range("guidance.tracking_state_weight", self.tracking_state_weight, 1e-12, 1e6)
        check_range("guidance.tracking_rate_deg_s", self.tracking_rate_deg_s, 1e-6, 1e3)
        check_range("guidance.bank_lead_s", self.bank_lead_s, 0.0, 10.0)
        check_range("guidance.path_gain", self.path_gain, 0.0, 1000.0)
        check_range("guidance.path_horizon_s", self.path_horizon_s, 0.1, 600.0)
        check_range("guidance.path_limit_fraction", self.path_limit_fraction, 0.5, 1.0)
        if self.tracking_index not in TRACKING_INDICES:
            raise ScenarioError(f"guidance.tracking_index = '{self.tracking_index}'; allowed: "
                                f"{', '.join(TRACKING_INDICES)}")
