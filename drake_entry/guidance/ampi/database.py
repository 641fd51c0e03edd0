"""The trajectory database (paper 003 Sec. IV.B, E): one optimal trajectory per grid case,
stored compactly at N_LD Legendre-Gauss-Lobatto nodes, and expanded on line to any number
of points by the Lagrange matrix of eqs. 11-12 (T_HD = T_LD P).

Each case's solution (however it was transcribed) is resampled at the LD nodes tau_k of
[-1, 1], t_k = (tau_k + 1) t_f / 2, with its own interpolant; the database stores those
samples of every state and control, t_f, the objective and whether the solve was verified.
The LD-HD expansion is exact for the LD polynomial; its error against the flown
trajectory is measured by ``reconstruction_error`` (a pre-implementation prototype: 60 nodes resolve this
skipping flight to metres, 40 nodes to about 90 m).
"""
from __future__ import annotations

import dataclasses as dc
import json
import os
import zipfile
from functools import lru_cache

import numpy as np

from drake_entry.errors import ScenarioError
from drake_entry.guidance.ampi.grid import ParameterGrid
from drake_entry.guidance.ampi.spec import MODES
from drake_entry.guidance.ampi.synthesis import interpolate_corners, nearest_case, select_subspace
from drake_entry.planning.pseudospectral import interpolation_matrix, lgl_nodes

__all__ = ["OBJECTIVE_FACTOR", "FINAL_TIME_JUMP_S", "BANK_JUMP_DEG", "Synthesis", "hd_matrix", "FILE_FORMAT",
           "FILE_VERSION", "ARRAYS", "TrajectoryDatabase"]

#: consistency with the neighbours (``TrajectoryDatabase.inconsistent``): a case whose
#: objective exceeds this factor times the median of its neighbours' (a worse local branch:
#: a pre-implementation prototype found J = 70-143 among neighbours at 19-26), whose t_f differs from
#: theirs by more than FINAL_TIME_JUMP_S, or whose bank differs from every neighbour's by more
#: than BANK_JUMP_DEG (RMS over the LD nodes) is an outlier to re-solve
OBJECTIVE_FACTOR = 1.5
FINAL_TIME_JUMP_S = 30.0
BANK_JUMP_DEG = 15.0


@dc.dataclass
class Synthesis:
    """An interpolated trajectory (paper 003 Algorithms 1-2 and eq. 11).

    Attributes:
      time [s] (n,), states (n, n_states), controls (n, n_controls): at the LD nodes, or at
        the requested HD points; final_time [s]; extrapolated: per grid dimension, True where
        the query lies outside the grid (linear extrapolation); cases: the 2^d database
        entries used (indices)."""

    time: np.ndarray
    states: np.ndarray
    controls: np.ndarray
    final_time: float
    extrapolated: np.ndarray
    cases: list


@lru_cache(maxsize=16)
def hd_matrix(n_ld: int, n_hd: int) -> np.ndarray:
    """Eq. 12: the Lagrange matrix from the n_ld LGL nodes to n_hd equally spaced points of
    [-1, 1] (rows: HD points), so that T_HD = P @ T_LD (eq. 11 transposed). Read-only."""
    P = interpolation_matrix(lgl_nodes(n_ld), np.linspace(-1.0, 1.0, n_hd))
    P.flags.writeable = False
    return P


#: what ``TrajectoryDatabase.save`` stamps in a file's layout, and the arrays it holds
FILE_FORMAT, FILE_VERSION = "drake_entry.ampi.trajectory_database", 1
ARRAYS = ("values", "final_time", "objective", "verified", "meta")


@dc.dataclass
class TrajectoryDatabase:
    """Optimal trajectories on a ParameterGrid, stored at N_LD LGL nodes.

    Attributes:
      grid: the parameter grid (case i is grid.offsets(i) from the nominal entry state).
      state_names, control_names: the problem's layout.
      values: (grid.size, n_ld, n_states + n_controls) states then controls at the LD nodes, SI.
      final_time: (grid.size,) t_f [s]; objective: (grid.size,); verified: (grid.size,) bool
        (False: not solved, or solved but not verified: such a case is not interpolated from).
      provenance: how it was made (JSON-able; the database builder stores its study: the
        problem, the grid, the NLP settings), saved with it.
    """

    grid: ParameterGrid
    state_names: tuple
    control_names: tuple
    values: np.ndarray
    final_time: np.ndarray
    objective: np.ndarray
    verified: np.ndarray
    provenance: dict = dc.field(default_factory=dict)

    @staticmethod
    def empty(grid: ParameterGrid, n_ld: int, state_names, control_names, provenance: dict | None = None
              ) -> "TrajectoryDatabase":
        if not 3 <= n_ld <= 400:
            raise ScenarioError(f"n_ld = {n_ld}: allowed 3..400 LD nodes")
        n = len(state_names) + len(control_names)
        return TrajectoryDatabase(grid, tuple(state_names), tuple(control_names), np.full((grid.size, n_ld, n), np.nan),
                                  np.full(grid.size, np.nan), np.full(grid.size, np.nan), np.zeros(grid.size, bool),
                                  dict(provenance or {}))

    @property
    def n_ld(self) -> int:
        return self.values.shape[1]

    @property
    def tau(self) -> np.ndarray:
        return lgl_nodes(self.n_ld)

    @property
    def storage_bytes(self) -> int:
        """What the on-board database holds: the LD samples and t_f of every case."""
        return int(self.values.nbytes + self.final_time.nbytes)

    def ld_times(self, final_time: float) -> np.ndarray:
        return 0.5 * (self.tau + 1.0) * final_time

    def set_case(self, index: int, states: np.ndarray, controls: np.ndarray, final_time: float, objective: float,
                 verified: bool):
        """Store case ``index`` from its samples at the LD times (``ld_times(final_time)``)."""
        self.values[index] = np.hstack([np.asarray(states, float), np.asarray(controls, float)])
        self.final_time[index], self.objective[index], self.verified[index] = final_time, objective, bool(verified)

    def case(self, index: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(t [s], states, controls) of a stored case at its LD nodes."""
        nx = len(self.state_names)
        v = self.values[index]
        return self.ld_times(self.final_time[index]), v[:, :nx], v[:, nx:]

    # -- on-line synthesis ------------------------------------------------------------
    def synthesise(self, offsets, hd_points: int | None = None) -> Synthesis:
        """Algorithms 1-2 at entry offsets ``offsets`` (grid.names order, SI / rad): the LD
        trajectory and t_f interpolated from the 2^d enclosing entries, then expanded to
        ``hd_points`` equally spaced times by eq. 11 (None: the LD nodes). Refuses when an
        enclosing entry is not verified."""
        x = self._offsets(offsets)
        shape = self.grid.shape
        values = self.values.reshape(shape + self.values.shape[1:])
        (traj, tf), outside, cases = self._interpolate([values, self.final_time.reshape(shape)], x)
        return self._expanded(traj, float(tf), hd_points, outside, cases)

    def entry(self, index: int, hd_points: int | None = None) -> Synthesis:
        """Stored case ``index`` as a Synthesis (NTT's reference), expanded like ``synthesise``."""
        if not self.verified[index]:
            raise ScenarioError(f"database case {index} is not verified: re-solve it before flying it")
        return self._expanded(self.values[index], float(self.final_time[index]), hd_points,
                              np.zeros(len(self.grid.names), bool), [int(index)])

    def reference(self, mode: str, offsets, hd_points: int | None = None) -> Synthesis:
        """The reference for entry ``offsets`` in ``mode`` (spec.MODES): 'ampi' is
        ``synthesise``, 'ntt' the ``entry`` nearest to the offsets; expanded like both."""
        if mode == "ampi":
            return self.synthesise(offsets, hd_points)
        if mode == "ntt":
            return self.entry(self.nearest(offsets), hd_points)
        raise ScenarioError(f"mode = '{mode}'; allowed: {', '.join(MODES)}")

    def _offsets(self, offsets) -> np.ndarray:
        x = np.asarray(offsets, float)
        if x.shape != (len(self.grid.names),):
            raise ScenarioError(f"offsets need {len(self.grid.names)} values ({', '.join(self.grid.names)}), "
                                f"got shape {x.shape}")
        return x

    def _expanded(self, traj, tf, hd_points, outside, cases) -> Synthesis:
        """eq. 11: LD samples ``traj`` (n_ld, n) of a trajectory of duration tf to hd_points
        equally spaced times (None: kept at the LD nodes)."""
        if hd_points is not None:
            if not 2 <= int(hd_points) <= 100000:
                raise ScenarioError(f"hd_points = {hd_points}: allowed 2..100000")
            traj = hd_matrix(self.n_ld, int(hd_points)) @ traj
            t = 0.5 * (np.linspace(-1.0, 1.0, int(hd_points)) + 1.0) * tf
        else:
            t = self.ld_times(tf)
        nx = len(self.state_names)
        return Synthesis(t, traj[:, :nx], traj[:, nx:], tf, outside, cases)

    def _interpolate(self, arrays, x):
        """Algorithm 1 once, then Algorithm 2 on each array (grid shape + value shape):
        (interpolated values, extrapolated flags, the enclosing case indices)."""
        lower, frac, outside = select_subspace(self.grid.levels, x)
        cases = [self.grid.index(tuple(j + b for j, b in zip(lower, bits)))
                 for bits in np.ndindex(*(2,) * len(lower))]
        missing = [c for c in cases if not self.verified[c]]
        if missing:
            raise ScenarioError(f"database cases {missing} enclosing offsets {list(x)} are not verified: re-solve them "
                                f"before interpolating")
        corners = tuple(slice(j, j + 2) for j in lower)
        return [interpolate_corners(a[corners], frac) for a in arrays], outside, cases

    def nearest(self, offsets) -> int:
        """NTT: the index of the stored case nearest to ``offsets`` (in grid steps)."""
        return self.grid.index(nearest_case(self.grid.levels, self._offsets(offsets)))

    # -- consistency --------------------------------------------------------------------
    def inconsistent(self) -> dict:
        """{case index: reason} for verified cases out of line with their verified neighbours
        (module constants; the bank check when the states include 'sigma'), and for every case
        not verified."""
        bank_column = self.state_names.index("sigma") if "sigma" in self.state_names else None
        out = {int(i): "not verified" for i in np.flatnonzero(~self.verified)}
        for i in np.flatnonzero(self.verified):
            nb = [j for j in self.grid.neighbours(int(i)) if self.verified[j]]
            if not nb:
                continue
            J, Jn = self.objective[i], np.median(self.objective[nb])
            if J > OBJECTIVE_FACTOR * Jn and J - Jn > 1e-9 * max(1.0, abs(Jn)):
                out[int(i)] = f"objective {J:.4g} > {OBJECTIVE_FACTOR} x its neighbours' median {Jn:.4g}"
                continue
            dt = abs(self.final_time[i] - np.median(self.final_time[nb]))
            if dt > FINAL_TIME_JUMP_S:
                out[int(i)] = f"t_f {self.final_time[i]:.1f} s is {dt:.1f} s from its neighbours' median"
                continue
            if bank_column is not None:
                rms = [np.degrees(np.sqrt(np.mean((self.values[i, :, bank_column] - self.values[j, :, bank_column]) ** 2)))
                       for j in nb]
                if min(rms) > BANK_JUMP_DEG:
                    out[int(i)] = f"bank differs from every neighbour's by > {BANK_JUMP_DEG:g} deg RMS (least {min(rms):.1f})"
        return out

    # -- files ------------------------------------------------------------------------
    def save(self, path: str):
        """One .npz file: the arrays and the layout (JSON, with FILE_FORMAT and FILE_VERSION)."""
        meta = {"format": FILE_FORMAT, "version": FILE_VERSION, "grid": self.grid.as_dict(),
                "state_names": list(self.state_names), "control_names": list(self.control_names),
                "provenance": self.provenance}
        np.savez_compressed(path, values=self.values, final_time=self.final_time, objective=self.objective,
                            verified=self.verified, meta=np.array(json.dumps(meta)))

    @staticmethod
    def load(path: str) -> "TrajectoryDatabase":
        """Read a database file written by ``save``: its format, version, arrays and shapes are
        checked and every problem is one ScenarioError naming the file. Pickled objects are never
        loaded (files from before the format stamp are read as version 1)."""
        if not isinstance(path, (str, os.PathLike)):
            raise ScenarioError(f"an AMPI database is a file path; got {type(path).__name__}")
        where = f"AMPI database {os.fspath(path)}"
        if not os.path.exists(path):
            raise ScenarioError(f"{where}: file not found")
        if os.path.isdir(path):
            raise ScenarioError(f"{where} is a directory, not a database file (.npz)")
        try:
            archive = np.load(path, allow_pickle=False)
        except ValueError:
            with open(path, "rb") as raw:
                pickled = raw.read(1) == b"\x80"  # a pickle's protocol marker
            if pickled:
                raise ScenarioError(f"{where} holds pickled Python objects, which are never loaded") from None
            raise ScenarioError(f"{where} is not a database file (an .npz written by TrajectoryDatabase.save: "
                                f"its first bytes are neither a zip archive nor an array)") from None
        except (OSError, EOFError, zipfile.BadZipFile) as e:
            raise ScenarioError(f"{where} cannot be read as a database file (.npz): {str(e).splitlines()[0]}") from None
        if not isinstance(archive, np.lib.npyio.NpzFile):
            raise ScenarioError(f"{where} is a single array (.npy), not a database file (.npz with {', '.join(ARRAYS)})")
        with archive as f:
            missing = [k for k in ARRAYS if k not in f.files]
            if missing:
                raise ScenarioError(f"{where} lacks the array(s) {', '.join(missing)}; a database file holds "
                                    f"{', '.join(ARRAYS)}")
            try:
                meta = json.loads(str(f["meta"]))
                fmt, version = meta.get("format", FILE_FORMAT), meta.get("version", 1)
                if fmt != FILE_FORMAT:
                    raise ScenarioError(f"{where} is a {fmt!r} file, not an AMPI trajectory database")
                if not isinstance(version, int) or not 1 <= version <= FILE_VERSION:
                    raise ScenarioError(f"{where} has format version {version!r}; this drake_entry reads "
                                        f"versions 1 to {FILE_VERSION} (a newer drake_entry wrote it?)")
                grid = ParameterGrid.from_dict(meta["grid"])
                db = TrajectoryDatabase(grid, tuple(meta["state_names"]), tuple(meta["control_names"]),
                                        np.asarray(f["values"], float), np.asarray(f["final_time"], float),
                                        np.asarray(f["objective"], float), f["verified"].astype(bool),
                                        meta.get("provenance", {}))
            except ScenarioError:
                raise
            except Exception as e:  # a layout that is not a database's (JSON, keys, types)
                raise ScenarioError(f"{where}: its layout is not a database's ({type(e).__name__}: "
                                    f"{str(e).splitlines()[0] if str(e) else ''})") from None
        n, width = grid.size, len(db.state_names) + len(db.control_names)
        if db.values.ndim != 3 or db.values.shape[0] != n or db.values.shape[2] != width:
            raise ScenarioError(f"{where}: values has shape {db.values.shape}; its grid and layout need "
                                f"({n}, nodes, {width})")
        for name in ("final_time", "objective", "verified"):
            if getattr(db, name).shape != (n,):
                raise ScenarioError(f"{where}: {name} has shape {getattr(db, name).shape}; its grid needs ({n},)")
        return db
