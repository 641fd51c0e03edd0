"""The guidance-method interface: what a method gives the shared closed loop, and what the
closed loop gives it.

A method is one package under ``drake_entry/guidance/`` registered in
``drake_entry/guidance/__init__.py``. It provides (docs/architecture.md, "Adding a method"):

- a scenario spec dataclass (``spec.py``, pure data, YAML tag ``!ClassName``);
- a ``GuidanceMethod`` (``method.py``): a planner factory, ``add_systems`` that adds its
  Drake systems to the closed-loop ``DiagramBuilder`` and returns its command ports, and
  ``summarise`` that reads its systems after a flight into per-sample fields;
- optionally ``drake_entry/cli/methods/<folder>.py`` (CLI layer) with ``plan_report(scenario, out_dir) -> int`` for
  ``drake-entry plan``.

The closed loop (``drake_entry.diagrams.closed_loop``) builds only the shared parts:
vehicle, atmosphere, navigation, bank and angle-of-attack actuators, termination monitor
and loggers.
"""
from __future__ import annotations

import dataclasses as dc

from pydrake.systems.framework import OutputPort

__all__ = ["PlantPorts", "LoggedSignal", "ActuatorLimits", "GuidanceCommands", "GuidanceSummary", "GuidanceMethod"]


@dc.dataclass(frozen=True)
class PlantPorts:
    """Output ports of the shared closed loop that a method's systems may connect to.

    Attributes:
      estimated_state: [6] navigation estimate [h m, lon rad, lat rad, V m/s, gamma rad, psi rad].
      flight_conditions: [9] sensed flight conditions of the true vehicle (the accelerometer's
        drag and lift, loads, q, heat flux; drake_entry.models.dynamics.FLIGHT_CONDITION_NAMES).
    Time is the context's time; no port is needed for it.
    """

    estimated_state: OutputPort
    flight_conditions: OutputPort


@dc.dataclass(frozen=True)
class LoggedSignal:
    """A method signal logged at the scenario's log period into ``Trajectory.extra[name]``.

    Attributes:
      port: the output port (of a system the method added).
      columns: one column name per element, with units, for trajectory tables.
    """

    port: OutputPort
    columns: tuple[str, ...]


@dc.dataclass(frozen=True)
class ActuatorLimits:
    """Position [rad], rate [rad/s] and acceleration [rad/s^2] limits of a commanded angle."""

    lower: float
    upper: float
    rate: float
    acceleration: float


@dc.dataclass
class GuidanceCommands:
    """What ``add_systems`` returns.

    Attributes:
      bank: [1] bank-angle command [rad], fed to the shared bank actuator.
      alpha: [1] angle-of-attack command [rad], fed to the shared alpha actuator with
        ``alpha_limits``; None = the scenario's alpha schedule flies the vehicle.
      initial_bank, initial_alpha: [rad] what the actuators hold until the first command.
      logged: signals to log, by name.
      alpha_sinks: input ports of the method's systems that the closed loop feeds with the
        angle of attack flown [rad] (e.g. a filter of the sensed lift and drag ratios).
      bank_sinks: [2] input ports that the closed loop feeds with the bank flown [rad] and its
        rate [rad/s], the bank actuator's position (the attitude measured on board; e.g. where an
        on-board prediction's actuator starts, mid-reversal included).
    """

    bank: OutputPort
    alpha: OutputPort | None = None
    alpha_limits: ActuatorLimits | None = None
    initial_bank: float = 0.0
    initial_alpha: float = 0.0
    logged: dict[str, LoggedSignal] = dc.field(default_factory=dict)
    alpha_sinks: tuple = ()
    bank_sinks: tuple = ()


@dc.dataclass
class GuidanceSummary:
    """A method's account of one flight (read from its systems after the run).

    Attributes:
      active: the guidance flew the vehicle (e.g. engaged, or a plan existed); a flight
        whose guidance never became active is not a success.
      message: why it was not active ('' when it was).
      plans: number of successful (re-)plans on board (0 for a method that plans once before
        flight); planning_wall_s: wall-clock time spent planning on board [s].
      fields: method-specific per-sample row fields (flat scalars, units in the names).
      details: the method's own record (e.g. its references) for scripts and plots.
    """

    active: bool
    message: str = ""
    plans: int = 0
    planning_wall_s: float = 0.0
    fields: dict = dc.field(default_factory=dict)
    details: object = None


class GuidanceMethod:
    """Base of the registered methods; subclasses override the three hooks."""

    #: name used in rows, reports and messages (snake_case)
    name: str = ""
    #: what must exist before ``make_planner`` can run, built once per mission by the campaign
    #: layer (drake_entry.campaign.preparation): None, or 'module:function' of the method's own
    #: study, called as function(scenario, progress=...) -> a one-line summary (e.g. AMPI's
    #: database for the mission). A name, not an import: a method's wiring imports no campaign.
    preparation: str | None = None

    def make_planner(self, scenario, verifier):
        """What the method builds once per mission and reuses for every flight and sample
        (e.g. a planner with its corridor). Runs in each campaign worker. ``verifier`` flies a
        plan's controls with the Drake Simulator (drake_entry.planning.verification): a planner
        whose plan is a set of controls calls its plans a success only when they fly."""
        raise NotImplementedError

    def add_systems(self, builder, scenario, planner, plant: PlantPorts) -> GuidanceCommands:
        """Add the method's systems to ``builder`` (named uniquely), connect them to the
        plant ports, and return the command ports and logged signals."""
        raise NotImplementedError

    def summarise(self, diagram, context, planner) -> GuidanceSummary:
        """Read the method's systems in the finished simulation's root ``context``."""
        raise NotImplementedError

    def flight_plots(self, result, out_dir: str, *, title: str = "") -> list[str]:
        """Method-specific figures of one closed-loop flight (``drake-entry fly``); PNG paths."""
        return []
