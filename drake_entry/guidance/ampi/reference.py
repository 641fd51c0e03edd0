"""On-board reference generation from the trajectory database (paper 003 Secs. IV-VI): at the
entry interface the measured state gives the offsets from the nominal entry (eq. 6), and the
reference is either

- ``ampi``: synthesised from the 2^d enclosing entries (Algorithms 1-2, eq. 11), or
- ``ntt``: the nearest stored entry (neighbour-trajectory tracking, the paper's comparison),

expanded to ``hd_points`` equally spaced times; both are then tracked by the same
time-varying LQR (planning.tracking), computed about the chosen reference.

    planner = DatabaseReference.load("shefex3")      # the packaged database and its problem
    ref = planner.reference(estimated_entry_state)   # TrackedReference: law, cases, offsets
"""
from __future__ import annotations

import dataclasses as dc
import time

import numpy as np

from drake_entry.errors import ScenarioError
from drake_entry.guidance.ampi.database import Synthesis, TrajectoryDatabase
from drake_entry.guidance.ampi.spec import MODES, database_path
from drake_entry.planning.ocp_yaml import load_problem
from drake_entry.planning.result import PlanResult
from drake_entry.planning.tracking import TrackingLaw, TrackingWeights, tvlqr

__all__ = ["TrackedReference", "DatabaseReference"]


@dc.dataclass(frozen=True)
class TrackedReference:
    """What the guidance flies: the reference and its tracking law.

    Attributes:
      law: TrackingLaw (reference samples, TVLQR gains).
      synthesis: the database Synthesis (final_time, extrapolated flags, cases used).
      offsets: the measured entry offsets (grid names order, SI / rad).
      mode: 'ampi' or 'ntt'; synthesis_s, gains_s: wall times [s].
    """

    law: TrackingLaw
    synthesis: Synthesis
    offsets: np.ndarray
    mode: str
    synthesis_s: float
    gains_s: float


@dc.dataclass(kw_only=True)
class DatabaseReference(PlanResult):
    """The database guidance's planner (made once per mission): the database, its problem
    and the tracking weights. ``success``: every case verified and none out of line with
    its neighbours (TrajectoryDatabase.inconsistent).

    Attributes:
      database: the TrajectoryDatabase.
      problem: the OptimalControlProblem the database solved (its initial state is the grid's
        centre).
      mode: 'ampi' or 'ntt'.
      hd_points: eq. 11's N_HD + 1, the reference's equally spaced samples.
      weights: the TVLQR's TrackingWeights (default TrackingWeights.entry()).
      gain_samples: times the dynamics are linearised at for the gains.
    """

    database: TrajectoryDatabase
    problem: object
    mode: str = "ampi"
    hd_points: int = 601
    weights: TrackingWeights | None = None
    gain_samples: int = 120

    def __post_init__(self):
        if self.mode not in MODES:
            raise ScenarioError(f"mode = '{self.mode}'; allowed: {', '.join(MODES)}")
        if tuple(self.problem.state_names) != self.database.state_names:
            raise ScenarioError(f"the database's states {self.database.state_names} are not its problem's "
                                f"{tuple(self.problem.state_names)}")
        if self.weights is None:
            self.weights = TrackingWeights.entry()

    @staticmethod
    def load(database: str, mode: str = "ampi", **kwargs) -> "DatabaseReference":
        """From a packaged database name or an .npz path; the problem is the one the database
        was built from (its provenance)."""
        t0 = time.perf_counter()
        db = TrajectoryDatabase.load(database_path(database))
        study = db.provenance.get("study", {})
        if "problem" not in study:
            raise ScenarioError(f"database '{database}' does not record its problem (provenance.study.problem); "
                                "rebuild it with guidance.ampi.database_study.build_database")
        problem, _ = load_problem(study["problem"])
        bad = db.inconsistent()
        ok = not bad
        msg = (f"{int(db.verified.sum())}/{db.grid.size} cases verified and consistent" if ok else
               f"{len(bad)} of {db.grid.size} cases not verified or out of line, e.g. case {min(bad)}: {bad[min(bad)]}")
        return DatabaseReference(database=db, problem=problem, mode=mode, success=ok, message=msg,
                                 build_time=time.perf_counter() - t0, objective=float(np.nanmedian(db.objective)),
                                 **kwargs)

    def offsets(self, entry_state) -> np.ndarray:
        """Eq. 6: the measured entry state [h, lon, lat, V, gamma, psi] (h the state altitude)
        minus the nominal, in the grid's order; the altitude offset is geodetic."""
        x = np.asarray(entry_state, float)
        nominal = self.problem.initial
        planet = self.problem.planet
        d = {"h": planet.atmospheric_altitude(x[0], x[2]) - planet.atmospheric_altitude(nominal["h"], nominal["lat"]),
             "lon": x[1] - nominal["lon"], "lat": x[2] - nominal["lat"], "V": x[3] - nominal["V"],
             "gamma": x[4] - nominal["gamma"], "psi": x[5] - nominal["psi"]}
        return np.array([float(d[n]) for n in self.database.grid.names])

    def synthesis(self, entry_state) -> tuple[Synthesis, np.ndarray]:
        """(the mode's reference at the measured entry state, the offsets)."""
        x = self.offsets(entry_state)
        return self.database.reference(self.mode, x, self.hd_points), x

    def reference(self, entry_state) -> TrackedReference:
        """The reference for a flight from ``entry_state`` and its TVLQR law."""
        t0 = time.perf_counter()
        syn, x = self.synthesis(entry_state)
        t1 = time.perf_counter()
        law = tvlqr(self.problem, syn.time, syn.states, syn.controls, self.weights, self.gain_samples)
        return TrackedReference(law, syn, x, self.mode, t1 - t0, time.perf_counter() - t1)

    def evaluate(self, at) -> dict:
        """The nominal entry's reference (the grid centre) at times ``at`` [s]."""
        syn = self.database.entry(self.database.grid.index(self.database.grid.centre), self.hd_points)
        at = np.asarray(at, float)
        out = {n: np.interp(at, syn.time, syn.states[:, i]) for i, n in enumerate(self.database.state_names)}
        out.update({n: np.interp(at, syn.time, syn.controls[:, j]) for j, n in enumerate(self.database.control_names)})
        return out

