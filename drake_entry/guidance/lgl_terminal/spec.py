"""Scenario spec of paper 002's terminal guidance; YAML tag ``guidance: !LglTerminal``."""

import dataclasses as dc
from typing import Optional

from drake_entry.errors import ScenarioError, check_range
from drake_entry.guidance.spec import ReplanningSpec

__all__ = ["SOLVERS", "FEEDBACKS", "LglTerminal"]

SOLVERS = ("snopt", "ipopt")
FEEDBACKS = ("tvlqr", "costate", "none")


@dc.dataclass
class LglTerminal(ReplanningSpec):
    """Paper 002's optimal-control problem (a packaged problem or a problem YAML path: final
    conditions, bounds, path constraints, objective; eqs. 11, 16-19) solved before flight by the
    Legendre pseudospectral method from the scenario's entry state to its target with the
    scenario's vehicle, planet and atmosphere; its bank and angle of attack (states of the
    'rates' layout) flown in time through the shared actuators, and the problem re-solved from
    the navigation estimate every ``replan_period_s`` with the horizon that remains, warm-started
    from the solution in use (drake_entry.planning.nlp.shrinking_horizon)."""

    #: fields naming a file: a relative path is read beside the scenario file (typed_yaml.resolve_file_fields)
    FILE_FIELDS = ('problem',)
    FEEDBACKS = FEEDBACKS

    # the closed loop stops at impact
    stops_at_altitude = True
    terminal_altitude_km: float = 0.0
    # a packaged problem or a problem YAML, or 'mission': the problem the scenario's mission
    # poses (mission.mission_problem: its interface, target and vehicle limits; the three
    # fields below then set what a problem file would)
    problem: str = "marv"
    # 'mission' only: the final speed [m/s], alpha's bounds [deg] and alpha's rate bound [deg/s]
    terminal_velocity_m_s: Optional[float] = None
    alpha_bounds_deg: list[float] = dc.field(default_factory=list)
    alpha_rate_deg_s: float = 2.0
    # the final flight-path angle [deg] planned (None: the problem's)
    final_flight_path_deg: Optional[float] = None
    # 'mission' without final_flight_path_deg: the plan ends descending at least this steeply
    # [deg] (None: free). The flight stops where it first crosses the terminal altitude; a plan
    # that levels off there is crossed early or late (paper 004's CAV-H: up to 75 km short)
    final_descent_deg: Optional[float] = None
    # design margin of the plans (not the paper's): each path constraint planned this fraction
    # inside its bound (q >= 12 kPa planned as >= 12 (1 + m) kPa), so that the closed loop,
    # dispersed, holds the bounds its verdict checks
    path_margin: float = 0.08
    # the pre-flight solve: LGL nodes, NLP solver, its tolerance and iteration cap
    nodes: int = 80
    # the LGL nodes in this many equal segments sharing their end nodes (1: paper 002's one
    # polynomial; docs/methods/nlp.md, "LGL in segments"): a segment's block of the constraint
    # Jacobian is dense, so SNOPT's factorisations shrink with the segments. nodes - 1 a multiple
    # of it with >= 3 nodes per segment; a re-solve rounds its node count up to one they share
    segments: int = 1
    solver: str = "snopt"
    # SNOPT's "Scale option" for every solve, pre-flight and re-solve (0: none, SNOPT's own
    # behaviour; 1: the linear constraints and the variables; 2: all constraints and variables,
    # from the Jacobian at the guess). 2 on MaRV's problem: its two longest re-solves took 112 and
    # 94 evaluations instead of 404 and 394 to the same optimum, 39 core s per flight instead of
    # 62. Not the default: with 2, HORUS-2B's derived pre-flight plan (81 nodes) ended SNOPT
    # info 3 on 4 segments and on one polynomial, solved without it (docs/methods/lgl-terminal.md)
    snopt_scale_option: int = 0
    tolerance: float = 1.0e-7
    max_iterations: int = 3000
    # refine the pre-flight mesh (more nodes in the same segments, from ``nodes`` up to 150) while
    # the dynamics between the nodes miss their tolerance; False: refuse such a plan as it is
    refine_mesh: bool = True
    # re-solves from replan_start_s [s] every replan_period_s [s] (0: fly the pre-flight solution)
    # while more than replan_min_time_to_go_s [s] remain, on one node per replan_node_spacing_s
    # [s] of the remaining horizon, within replan_nodes [min, max], to replan_tolerance
    replan_period_s: float = 100.0
    replan_min_time_to_go_s: float = 30.0
    replan_start_s: float = 200.0
    replan_node_spacing_s: float = 10.0
    replan_nodes: list[int] = dc.field(default_factory=lambda: [40, 60])
    replan_tolerance: float = 1.0e-6
    # re-solves come closer together as impact nears (ReplanningSpec)
    replan_time_to_go_fraction: float = 0.4
    # re-solves aim at the final speed and flight-path angle within these windows [m/s, deg]
    # (the pre-flight plan at the values themselves): from a dispersed state the exact values
    # may be out of reach while a point inside the acceptance box is not
    replan_speed_window_m_s: float = 25.0
    replan_flight_path_window_deg: float = 2.5
    # re-solves predict with the nominal lift and drag times the low-passed ratios of the sensed
    # to the modelled accelerations (a density, aerodynamic or mass error the flight has shown)
    replan_model_scales: bool = True
    # between re-solves the commands track the solution in use (ReplanningSpec's feedback
    # fields): "tvlqr", "costate" (the neighbouring-optimal law of its costates,
    # planning.neighbouring_optimal) or "none"
    feedback: str = "tvlqr"
    # the angle-of-attack actuator's acceleration limit [deg/s^2] (its rate limit is the
    # problem's alpha-rate bound, eq. 17)
    alpha_accel_limit_deg_s2: float = 40.0

    def terminal_speed(self, speed_of_sound: float) -> float:
        """V_f [m/s]: the problem's final speed (the impact speed of eq. 16; a mission's: the spec's)."""
        from drake_entry.guidance.lgl_terminal.mission import MISSION, load_guidance_problem

        if self.problem == MISSION:
            return float(self.terminal_velocity_m_s)
        return float(load_guidance_problem(self).final["V"])

    def path_limits(self, scenario) -> list:
        """The problem's path constraints (eq. 18: q >= 12 kPa, a <= 45 g0) as flown limits (a
        mission's problem adds none: its constraints are the vehicle's limits, checked anyway)."""
        from drake_entry.guidance.lgl_terminal.mission import MISSION, mission_path_limits, problem_for_scenario

        if self.problem == MISSION:
            return []
        return mission_path_limits(problem_for_scenario(self, scenario, margin=False))

    def problem_for(self, scenario):
        """The OptimalControlProblem planned (planner.problem_for_scenario, with the design margin)."""
        from drake_entry.guidance.lgl_terminal.mission import problem_for_scenario

        return problem_for_scenario(self, scenario)

    def solver_options(self) -> dict | None:
        """The NLP solver's options by its own names (nlp.solve's ``solver_options``)."""
        return {"Scale option": int(self.snopt_scale_option)} if self.solver == "snopt" else None

    def validate(self, scenario) -> None:
        from drake_entry.guidance.lgl_terminal.mission import MISSION

        super().validate(scenario)
        if self.solver not in SOLVERS:
            raise ScenarioError(f"guidance.solver = '{self.solver}' is unknown; allowed: {', '.join(SOLVERS)}")
        if self.snopt_scale_option not in (0, 1, 2):
            raise ScenarioError(f"guidance.snopt_scale_option = {self.snopt_scale_option!r}; allowed 0 (none), "
                                f"1 (linear constraints and variables), 2 (all)")
        check_range("guidance.nodes", self.nodes, 10, 400)
        check_range("guidance.segments", self.segments, 1, 40)
        from drake_entry.planning.pseudospectral import nodes_per_segment

        nodes_per_segment(self.nodes, self.segments, fields=("guidance.nodes", "guidance.segments"))
        check_range("guidance.path_margin", self.path_margin, 0.0, 0.5)
        check_range("guidance.tolerance", self.tolerance, 1e-12, 1e-2)
        check_range("guidance.max_iterations", self.max_iterations, 1, 100000)
        check_range("guidance.replan_start_s", self.replan_start_s, 0.0, 1e4)
        check_range("guidance.replan_node_spacing_s", self.replan_node_spacing_s, 0.1, 1e3)
        if len(self.replan_nodes) != 2 or not 5 <= self.replan_nodes[0] <= self.replan_nodes[1] <= 400:
            raise ScenarioError(f"guidance.replan_nodes = {self.replan_nodes}; allowed [min, max] with "
                                f"5 <= min <= max <= 400")
        check_range("guidance.replan_tolerance", self.replan_tolerance, 1e-12, 1e-2)
        check_range("guidance.replan_speed_window_m_s", self.replan_speed_window_m_s, 0.0, 1e3)
        check_range("guidance.replan_flight_path_window_deg", self.replan_flight_path_window_deg, 0.0, 45.0)
        check_range("guidance.alpha_accel_limit_deg_s2", self.alpha_accel_limit_deg_s2, 0.1, 1e3)
        if self.final_flight_path_deg is not None:
            check_range("guidance.final_flight_path_deg", self.final_flight_path_deg, -89.9, 0.0)
        if self.final_descent_deg is not None:
            check_range("guidance.final_descent_deg", self.final_descent_deg, 0.0, 45.0)
            if self.final_flight_path_deg is not None:
                raise ScenarioError(f"guidance.final_descent_deg = {self.final_descent_deg:g} with final_flight_path_deg = "
                                    f"{self.final_flight_path_deg:g}: give one of them (the angle itself, or the "
                                    f"least descent when the angle is free)")
            if self.problem != MISSION:
                raise ScenarioError("guidance.final_descent_deg is a field of problem: mission (a problem file "
                                    "states its own final conditions)")
        if self.problem == MISSION:
            if self.terminal_velocity_m_s is None:
                raise ScenarioError("guidance.terminal_velocity_m_s is needed with problem: mission (the final speed)")
            check_range("guidance.terminal_velocity_m_s", self.terminal_velocity_m_s, 1.0, 2.0e4)
            if len(self.alpha_bounds_deg) != 2 or not -90.0 <= self.alpha_bounds_deg[0] < self.alpha_bounds_deg[1] <= 90:
                raise ScenarioError(f"guidance.alpha_bounds_deg = {self.alpha_bounds_deg}: with problem: mission give "
                                    f"[min, max] with -90 <= min < max <= 90 deg")
            check_range("guidance.alpha_rate_deg_s", self.alpha_rate_deg_s, 0.01, 100.0)
        self.problem_for(scenario)
