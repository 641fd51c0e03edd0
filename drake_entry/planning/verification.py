"""What a planner hands to the plan verifier, and what it gets back.

A plan succeeds only when its controls, flown by the Drake Simulator (through the closed
loop's own actuator systems where the closed loop has them), end where the plan says and hold
every path limit. That flight is a service of the diagrams layer
(``drake_entry.diagrams.verification.fly_controls``); planners receive it as an argument,
``verifier``, so that planning imports no system and no diagram. A verifier is any callable

    verifier(controls: EntryControls | OcpControls) -> FlownControls

- ``EntryControls``: bank and angle of attack in time, flown on the entry vehicle, through the
  closed loop's bank and alpha actuators when ``actuation`` is given (SCvx plans), with the
  closed loop's feedback between re-plans when ``tracking`` is given;
- ``OcpControls``: an optimal-control problem's controls in time, flown on the problem's own
  dynamics (NLP solutions, which no closed loop flies yet).

The planner judges the flight (its terminal point, its box, its limits); the verifier only flies.
"""
from __future__ import annotations

import dataclasses as dc
from typing import Callable, Union

import numpy as np

from drake_entry.errors import ScenarioError

__all__ = ["Actuation", "Tracking", "EntryControls", "OcpControls", "FlownControls", "Verifier", "require_verifier"]


@dc.dataclass(frozen=True)
class Actuation:
    """How the closed loop flies commands: sampled every ``period_s`` [s], each read
    ``lead_s`` [s] ahead on the plan, tracked by the shared actuator law
    (drake_entry.models.actuator) with these limits (rad, rad/s, rad/s^2) from these
    initial positions [rad]."""

    period_s: float
    lead_s: float
    bank_limit: float
    bank_rate_limit: float
    bank_accel_limit: float
    alpha_bounds: tuple[float, float]
    alpha_rate_limit: float
    alpha_accel_limit: float
    initial_bank: float
    initial_alpha: float

    def __post_init__(self):
        if not self.period_s > 0:
            raise ScenarioError(f"Actuation.period_s must be > 0 s, got {self.period_s}")
        if not self.lead_s >= 0:
            raise ScenarioError(f"Actuation.lead_s must be >= 0 s, got {self.lead_s}")


@dc.dataclass(frozen=True)
class Tracking:
    """The tracking law the closed loop flies on top of a plan's commands between re-plans
    (systems/replanning_guidance.py): ``plan`` as that system flies it (its control_samples(),
    and problem.alpha where alpha follows a law), ``feedback`` its law maker (plan ->
    CommandFeedback or None) and ``offset_limits`` (bank, alpha) [rad]."""

    plan: object
    feedback: Callable
    offset_limits: tuple


@dc.dataclass(frozen=True)
class EntryControls:
    """Bank and angle of attack of a plan in time, to fly from its entry state.

    Attributes:
      vehicle, planet, atmosphere: the models the plan was made with.
      initial_state: [h, lon, lat, V, gamma, psi] at t = 0 (SI, rad).
      final_time: t_f [s]: the flight stops there.
      time: (n,) sample times [s], increasing, from 0 to at least t_f.
      bank: (n,) bank [rad], unwrapped. alpha: (n,) [rad], or None where alpha follows
        ``alpha_law`` (an alpha(V) schedule, evaluated at the flown speed).
      actuation: the closed loop's actuators, or None to feed bank and alpha to the vehicle
        directly (a C2 spline through the samples).
      tracking: the closed loop's feedback on the commands (needs ``actuation``), or None.
    """

    vehicle: object
    planet: object
    atmosphere: object
    initial_state: np.ndarray
    final_time: float
    time: np.ndarray
    bank: np.ndarray
    alpha: np.ndarray | None = None
    alpha_law: object = None
    actuation: Actuation | None = None
    tracking: Tracking | None = None

    def __post_init__(self):
        if self.tracking is not None and self.actuation is None:
            raise ScenarioError("EntryControls.tracking needs an actuation: the feedback acts through the actuators")
        _check_samples("EntryControls", self.time, {"bank": self.bank, "alpha": self.alpha}, self.final_time)
        if self.alpha is None and self.alpha_law is None:
            raise ScenarioError("EntryControls needs alpha samples or an alpha_law")
        if np.shape(self.initial_state) != (6,):
            raise ScenarioError(f"EntryControls.initial_state must have 6 entries, got shape {np.shape(self.initial_state)}")


@dc.dataclass(frozen=True)
class OcpControls:
    """An optimal-control solution's controls, to fly on the problem's own dynamics.

    Attributes:
      problem: the problem (n_states, n_controls, dynamics(x, u) in SI).
      initial_state: (n_states,) at t = 0. final_time: t_f [s].
      time: (n,) sample times [s]; controls: (n, n_controls) SI.
      interpolation: 'cubic' (a C2 spline through dense samples of the transcription's own
        interpolant) or 'linear' (first-order hold, DirectCollocation's control).
    """

    problem: object
    initial_state: np.ndarray
    final_time: float
    time: np.ndarray
    controls: np.ndarray
    interpolation: str = "cubic"

    def __post_init__(self):
        _check_samples("OcpControls", self.time, {"controls": self.controls}, self.final_time)
        if self.interpolation not in ("cubic", "linear"):
            raise ScenarioError(f"OcpControls.interpolation must be 'cubic' or 'linear', got {self.interpolation!r}")


@dc.dataclass
class FlownControls:
    """A flight of a plan's controls.

    Attributes:
      time: (m,) [s]; states: (m, n_states) SI, the last row the state where the flight ended.
      trajectory: the flown drake_entry.models.trajectory.Trajectory with flight conditions and
        the integrator's own steps (entry flights; None for OcpControls).
      failure: '' when the flight reached t_f, else why and when it stopped.
    """

    time: np.ndarray
    states: np.ndarray
    trajectory: object = None
    failure: str = ""

    @property
    def reached_final_time(self) -> bool:
        return not self.failure


#: the verifier's signature (drake_entry.diagrams.verification.fly_controls is the Drake one)
Verifier = Callable[[Union[EntryControls, OcpControls]], FlownControls]


def require_verifier(verifier, who: str) -> Verifier:
    """``verifier`` itself, or a clear error when a planner was not given one."""
    if not callable(verifier):
        raise ScenarioError(f"{who} needs a verifier (the Drake flight of its controls: "
                            f"drake_entry.diagrams.verification.fly_controls), got {verifier!r}")
    return verifier


def _check_samples(owner: str, time, columns: dict, final_time: float) -> None:
    t = np.asarray(time, float)
    if t.ndim != 1 or t.size < 2 or not np.all(np.diff(t) > 0):
        raise ScenarioError(f"{owner}.time must be at least two increasing sample times [s]")
    if not (np.isfinite(final_time) and 0 < final_time <= t[-1] + 1e-9):
        raise ScenarioError(f"{owner}.final_time must be in (0, {t[-1]:.6g}] s (the last sample), got {final_time}")
    for name, values in columns.items():
        if values is not None and len(values) != t.size:
            raise ScenarioError(f"{owner}.{name} needs one sample per time ({t.size}), got {len(values)}")
