"""A simulated trajectory (the record every diagram runner returns) and its metrics: the
one place where peak heat flux, dynamic pressure, loads and heat load (``metrics``) and the
bank's activity (``control_activity``) are computed (for the CLI summaries, campaign rows and
plots)."""
from __future__ import annotations

import dataclasses as dc

import numpy as np

from drake_entry.models.constraints import PathLimits
from drake_entry.models.dynamics import FLIGHT_CONDITION_NAMES, STATE_NAMES

__all__ = ["Trajectory", "metrics", "navigation_errors", "REVERSAL_THRESHOLD", "control_activity"]


@dc.dataclass
class Trajectory:
    """A simulated trajectory sampled at the log period (plus the final instant).

    Attributes:
      time: [s], shape (n,). state: (n, 6) [h, lon, lat, V, gamma, psi] SI.
      conditions: (n, 9) FlightConditions columns. bank, alpha: (n,) [rad].
      reason: why the run stopped. wall_time: [s].
      extra: other logged signals by name, (n, k) arrays.
      extra_columns: table column names (units in them) of those signals, by name.
      steps: the state, conditions, bank and alpha at every integrator step (a Trajectory
        without extras), where the runner logged them: path limits and peaks are evaluated on
        both (``flown``), so nothing between two log samples is missed.
    """

    time: np.ndarray
    state: np.ndarray
    conditions: np.ndarray
    bank: np.ndarray
    alpha: np.ndarray
    reason: str
    wall_time: float
    extra: dict = dc.field(default_factory=dict)
    extra_columns: dict = dc.field(default_factory=dict)
    steps: "Trajectory | None" = None

    def flown_time(self) -> np.ndarray:
        """The times [s] of every flown sample: the log samples, then the integrator steps."""
        return self.time if self.steps is None else np.concatenate([self.time, self.steps.time])

    def flown(self, name: str) -> np.ndarray:
        """``column(name)`` at every flown sample (``flown_time``'s order)."""
        return self.column(name) if self.steps is None else np.concatenate([self.column(name),
                                                                             self.steps.column(name)])

    def column(self, name: str) -> np.ndarray:
        if name in STATE_NAMES:
            return self.state[:, STATE_NAMES.index(name)]
        if name in FLIGHT_CONDITION_NAMES:
            return self.conditions[:, FLIGHT_CONDITION_NAMES.index(name)]
        return {"time": self.time, "bank": self.bank, "alpha": self.alpha}[name]

    def table(self) -> dict:
        """Columns with units in the names (for Parquet / CSV)."""
        out = {"time_s": self.time,
               "altitude_m": self.state[:, 0], "longitude_deg": np.degrees(self.state[:, 1]),
               "latitude_deg": np.degrees(self.state[:, 2]), "velocity_m_s": self.state[:, 3],
               "flight_path_deg": np.degrees(self.state[:, 4]), "heading_deg": np.degrees(self.state[:, 5]),
               "bank_deg": np.degrees(self.bank), "alpha_deg": np.degrees(self.alpha)}
        units = {"rho": "density_kg_m3", "mach": "mach", "dynamic_pressure": "dynamic_pressure_Pa",
                 "heat_flux": "heat_flux_W_m2", "normal_load": "normal_load_g", "total_load": "total_load_g",
                 "lift": "lift_m_s2", "drag": "drag_m_s2", "energy": "energy_J_kg"}
        for i, name in enumerate(FLIGHT_CONDITION_NAMES):
            out[units[name]] = self.conditions[:, i]
        for name, columns in self.extra_columns.items():
            for i, column in enumerate(columns):
                out[column] = self.extra[name][:, i]
        return out


def metrics(tr: Trajectory, limits: PathLimits | None = None) -> dict:
    """Peak path quantities (over every flown sample, ``Trajectory.flown``) and the heat load of
    a trajectory, with the relative margins 1 - peak/limit (negative = violated) when ``limits``
    are given.

    Keys: peak_heat_flux_W_m2, peak_dynamic_pressure_Pa, peak_normal_load_g,
    peak_total_load_g, heat_load_J_m2 (trapezoidal integral of the heat flux over time),
    and margin_heat_flux, margin_dynamic_pressure, margin_normal_load, margin_total_load
    (for the finite limits only).
    """
    heat = tr.column("heat_flux")
    out = {"peak_heat_flux_W_m2": float(tr.flown("heat_flux").max()),
           "peak_dynamic_pressure_Pa": float(tr.flown("dynamic_pressure").max()),
           "peak_normal_load_g": float(tr.flown("normal_load").max()),
           "peak_total_load_g": float(tr.flown("total_load").max()),
           "heat_load_J_m2": float(np.sum(0.5 * (heat[1:] + heat[:-1]) * np.diff(tr.time)))}
    if limits is not None:
        m = limits.margins(heat_flux=out["peak_heat_flux_W_m2"], dynamic_pressure=out["peak_dynamic_pressure_Pa"],
                           normal_load=out["peak_normal_load_g"], total_load=out["peak_total_load_g"])
        out.update({f"margin_{k}": float(v) for k, v in m.items() if np.isfinite(getattr(limits, f"{k}_max"))})
    return out


def navigation_errors(tr: Trajectory) -> dict:
    """The INS flight's navigation error (the logged "navigation_error" signal: |position error|
    [m], |velocity error| [m/s]) at the end and its largest over the flight; {} when the flight
    had no inertial navigation."""
    e = tr.extra.get("navigation_error")
    if e is None or len(e) == 0:
        return {}
    return {"nav_position_error_end_m": float(e[-1, 0]), "nav_velocity_error_end_m_s": float(e[-1, 1]),
            "nav_position_error_max_m": float(e[:, 0].max()), "nav_velocity_error_max_m_s": float(e[:, 1].max())}


#: a bank reversal is a sign change of the flown bank between excursions beyond this [rad]
REVERSAL_THRESHOLD = np.radians(1.0)


def control_activity(tr: Trajectory, bank_limit: float, bank_rate_limit: float) -> dict:
    """The bank's activity over every flown sample in time order (log samples and integrator
    steps): ``bank_reversals`` (sign changes between excursions beyond REVERSAL_THRESHOLD),
    ``bank_travel_deg`` (the total angle turned), ``peak_bank_rate_deg_s`` (largest |rate| by
    finite differences of the C1 actuator path), ``time_at_bank_limit_s`` (|bank| within 1e-6
    rad of ``bank_limit`` [rad] at both ends of an interval) and ``time_at_bank_rate_limit_s``
    (|rate| >= 99 % of ``bank_rate_limit`` [rad/s])."""
    t, idx = np.unique(tr.flown_time(), return_index=True)
    bank = tr.flown("bank")[idx]
    if t.size < 2:
        return {"bank_reversals": 0, "bank_travel_deg": 0.0, "peak_bank_rate_deg_s": 0.0,
                "time_at_bank_limit_s": 0.0, "time_at_bank_rate_limit_s": 0.0}
    dt, step = np.diff(t), np.diff(bank)
    rate = step / dt
    signs = np.sign(bank[np.abs(bank) > REVERSAL_THRESHOLD])
    held = np.abs(bank) >= bank_limit - 1e-6
    at_limit = held[:-1] & held[1:]
    at_rate = np.abs(rate) >= 0.99 * bank_rate_limit
    return {"bank_reversals": int(np.count_nonzero(np.diff(signs))),
            "bank_travel_deg": float(np.degrees(np.abs(step).sum())),
            "peak_bank_rate_deg_s": float(np.degrees(np.abs(rate).max())),
            "time_at_bank_limit_s": float(dt[at_limit].sum()), "time_at_bank_rate_limit_s": float(dt[at_rate].sum())}
