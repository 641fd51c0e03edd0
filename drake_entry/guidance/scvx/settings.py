"""The SCvx planner's settings as plain data (paper 001): the iteration settings, the entry
problem's discretisation, formulation and objective, and how a plan is verified by flight.
Pure data with their range checks (numpy-free): the ``!Scvx`` scenario spec builds them
without loading the SOCP engine."""
from __future__ import annotations

import dataclasses as dc
import math

from drake_entry.errors import FieldError, ScenarioError

__all__ = ["SOLVER_TOLERANCES", "ScvxSettings", "Formulation", "FORMULATIONS", "OBJECTIVES", "RATE_OBJECTIVES",
           "EntryProblemSettings", "DEFAULT_PATH_MARGIN", "PAPER_LOSSLESS", "FlightCheck"]

#: convergence tolerances by solver where they differ from ScvxSettings' (``for_solver``)
SOLVER_TOLERANCES = {"scs": {"defect_tolerance": 1e-5, "constraint_tolerance": 1e-5, "decrease_tolerance": 1e-3}}


@dc.dataclass
class ScvxSettings:
    """SCvx iteration settings (paper 001 Sec. III; its SCOPT defaults where it has them).

    Attributes:
      max_iterations: SOCP solves, accepted or rejected.
      trust_radius, trust_radius_min, trust_radius_max: initial, smallest and largest
        inf-norm radius of the hard trust region in scaled variables.
      rho0, rho1, rho2: eq. 22 thresholds (reject below rho0; shrink below rho1; grow above rho2).
      trust_factor: radius change factor.
      virtual_control_weight, buffer_weight: l1 penalty weights of eqs. 27-28.
      line_search_steps: golden-section steps (eq. 29); 0 takes the full step.
      defect_tolerance: largest scaled defect at convergence.
      constraint_tolerance: largest scaled inequality or convex violation at convergence.
      decrease_tolerance: predicted decrease of J_a (relative to 1 + |J_a|) at convergence.
      second_order_correction: after each SOCP step, also try the step plus the least-norm
        correction that cancels the defects it created and the inequalities it violates
        (``defect_correction``) and keep the better point; near the solution they are what
        makes the linear model over-predict, so rho stays near 1 and the trust region need
        not collapse.
      feasibility_projection: project each accepted point whose largest defect is at most
        ``projection_defect_limit`` onto its defects and violated inequalities (same KKT
        solve; kept if the merit falls). The tail of small infeasibilities then costs no SOCP
        iterations: nominal direct plan 23 iterations instead of 44, lossless 27 instead of 33,
        9 x 9 abort map 52 feasible of 81 instead of 49. Farther from feasibility the
        projection's linearisation is poor (limits 1e-2 and above converged 0.2 % higher).
      solver: 'clarabel' or 'scs' (``for_solver`` gives SCS its tolerances). solver_options:
        passed to the solver (over CLARABEL_DEFAULTS or SCS_DEFAULTS).
    """

    max_iterations: int = 60
    trust_radius: float = 1.0
    trust_radius_min: float = 1e-5
    trust_radius_max: float = 10.0
    rho0: float = 0.0
    rho1: float = 0.2
    rho2: float = 0.6
    trust_factor: float = 2.0
    virtual_control_weight: float = 1e3
    buffer_weight: float = 1e2
    line_search_steps: int = 5
    defect_tolerance: float = 1e-6
    constraint_tolerance: float = 1e-6
    decrease_tolerance: float = 1e-4
    second_order_correction: bool = True
    feasibility_projection: bool = True
    projection_defect_limit: float = 1e-3
    solver: str = "clarabel"
    solver_options: dict = dc.field(default_factory=dict)

    @classmethod
    def for_solver(cls, solver: str, **fields) -> "ScvxSettings":
        """Settings for ``solver`` with its convergence tolerances (``SOLVER_TOLERANCES``: SCS's
        first-order answers cannot show a decrease of 1e-4 of J_a; on the nominal plan its trust
        region collapsed after 48 iterations with the defaults, it converged in 40 with its own), ``fields``
        over them."""
        return cls(solver=solver, **{**SOLVER_TOLERANCES.get(solver, {}), **fields})

    def __post_init__(self):
        if not 0.0 <= self.rho0 <= self.rho1 <= self.rho2 <= 1.0:
            raise ScenarioError(f"ScvxSettings rho0 <= rho1 <= rho2 must lie in [0, 1], got "
                                f"{self.rho0}, {self.rho1}, {self.rho2}")
        if not self.trust_factor > 1.0:
            raise FieldError("ScvxSettings", "trust_factor", f"= {self.trust_factor} must be > 1")
        if not 0.0 < self.trust_radius_min <= self.trust_radius <= self.trust_radius_max:
            raise ScenarioError("ScvxSettings needs 0 < trust_radius_min <= trust_radius <= trust_radius_max")
        if not (isinstance(self.max_iterations, int) and self.max_iterations >= 1):
            raise FieldError("ScvxSettings", "max_iterations", f"= {self.max_iterations} must be an integer >= 1")
        if not (isinstance(self.line_search_steps, int) and 0 <= self.line_search_steps <= 30):
            raise FieldError("ScvxSettings", "line_search_steps", f"= {self.line_search_steps} must be in [0, 30]")
        for name in ("virtual_control_weight", "buffer_weight", "defect_tolerance", "constraint_tolerance",
                     "decrease_tolerance", "projection_defect_limit"):
            if not getattr(self, name) > 0.0:
                raise FieldError("ScvxSettings", name, f"= {getattr(self, name)} must be > 0")
        if self.solver not in ("clarabel", "scs"):
            raise FieldError("ScvxSettings", "solver", f"= '{self.solver}'; allowed: clarabel, scs")


@dc.dataclass(frozen=True)
class Formulation:
    """How the bank and the angle of attack enter: bank 'lossless' (u1, u2) or 'rate' (sigma a
    state, sigma_dot a control); alpha 'schedule' (the mission's alpha(V)) or 'rate'."""

    bank: str
    alpha: str


FORMULATIONS = {"lossless": Formulation("lossless", "schedule"), "hybrid": Formulation("lossless", "rate"),
                "direct_bank": Formulation("rate", "schedule"), "direct": Formulation("rate", "rate")}

#: objective -> (unit of ``ScvxPlan.objective``, its value in SI per reported unit)
OBJECTIVES = {"heat_load": ("MJ/m^2", 1e6), "control_effort": ("deg", math.radians(1.0)),
              "max_control_rate": ("deg/s", math.radians(1.0)), "max_flight_path_rate": ("deg/s", math.radians(1.0)),
              "max_heat_flux": ("kW/m^2", 1e3), "max_load": ("g", 1.0), "time": ("s", 1.0), "miss": ("km", 1e3)}
RATE_OBJECTIVES = ("control_effort", "max_control_rate")


@dc.dataclass
class EntryProblemSettings:
    """Discretisation, formulation and objective of the entry problem.

    Attributes:
      segments, nodes_per_segment: the Lobatto mesh (2 nodes per segment: trapezoid).
      formulation: one of FORMULATIONS.
      objective: one of OBJECTIVES (the rate objectives need a rate formulation).
      heading_weight: |lambda_chi| of eq. 45 as a fraction of the scaled objective per
        radian of mean heading (0 disables the regulariser; lossless bank with
        max_lossless_gap = 1 only).
      heading_sign: +1, -1, or 0 for the geometric rule ``heading_regulariser_sign``.
      max_lossless_gap: largest 1 - |u| allowed at a node (lossless bank): 1 is the paper's
        relaxation (eq. 42 and the regulariser only); below 1 the floor |u| >= 1 - gap is
        imposed (module doc), so the real bank flies the plan. Default 0.01: the nominal
        mission's relaxed plan has a gap of 0.1-0.2 and flies 6-19 km from itself.
      lossless_rate_limit: bound the lossless bank's turn between nodes by the vehicle's
        bank_rate_limit (module doc; the paper imposes it only in the rate formulations).
        ``PAPER_LOSSLESS`` holds the two settings of the paper's relaxation.
      path_margin: the nodes keep heat flux and load this fraction inside the vehicle's limits
        (a design margin, not the paper's): the segment polynomials between the nodes peak
        above them (the nominal lossless plan's load by 3 % at its 22-s pull-up at 4.2 km/s),
        and the between-node check holds the plan to the vehicle's limits. 0: the paper's.
        None (default): ``DEFAULT_PATH_MARGIN`` of the bank's form: 0.04 for the lossless bank,
        whose relaxed u modulates the load sharply between nodes (flown through the actuators
        with 0.02 its load was 0.8 % over), 0.02 for a bank state, whose plans flown through the
        closed loop's actuators, dispersed, peak up to 1 % above their nodes' heat flux (the
        margin shrinks the reachable set: the 9 x 9 abort map loses EIPs that rode the limits).
      path_margin_ramp_s: the margin grows linearly from 0 at the plan's first node to
        ``path_margin`` at this flight time [s] (the final-time guess's): a re-plan begins where
        the vehicle is, and a vehicle flying within the margin of a limit (a dispersed closed
        loop rides the heat-flux limit within 0.4 %) cannot leave it in the seconds to its next
        nodes; with the margin at full strength there, the re-plan is infeasible at its first
        node. 0: the full margin from the first node.
      flight_path_margins_deg: the nodes keep gamma this far [deg] inside the mission's
        flight-path bounds (eq. 70), (above the lower bound, below the upper), so that the plan
        flown through the actuators, and a dispersed closed loop flying it, stays inside them:
        default 1.0 deg above the steepest dive (a plan ending on it was flown 0.35 deg steeper)
        and 0.2 deg under the skip limit (dispersed, the closed loop reached 0.57 deg without it,
        0.518 deg with 0.1 deg, and held 0.5 deg in 8 of 8 samples with 0.2); (0, 0): the paper's.
      bank_margin_deg: the nodes keep |sigma| this far [deg] inside the vehicle's bank limit, so
        the polynomials between them (about 1 deg over at a 90-deg limit) and the actuators'
        tracking do not run into the limit the actuator clips at (the nominal direct plan flew
        4.7 km from itself without it, 1.0 km with it).
    """

    segments: int = 33
    nodes_per_segment: int = 4
    formulation: str = "direct"
    objective: str = "heat_load"
    heading_weight: float = 0.02
    heading_sign: float = 0.0
    max_lossless_gap: float = 0.01
    lossless_rate_limit: bool = True
    path_margin: float | None = None
    path_margin_ramp_s: float = 60.0
    flight_path_margins_deg: tuple = (1.0, 0.2)
    bank_margin_deg: float = 2.0

    def __post_init__(self):
        if self.formulation not in FORMULATIONS:
            raise FieldError("EntryProblemSettings", "formulation", f"= '{self.formulation}'; allowed: "
                                f"{', '.join(FORMULATIONS)}")
        if self.objective not in OBJECTIVES:
            raise FieldError("EntryProblemSettings", "objective", f"= '{self.objective}'; allowed: {', '.join(OBJECTIVES)}")
        if self.objective in RATE_OBJECTIVES and self.formulation == "lossless":
            raise FieldError("EntryProblemSettings", "objective", f"= '{self.objective}' needs a formulation with rate "
                                f"controls (hybrid, direct_bank, direct), not 'lossless'")
        if not (isinstance(self.segments, int) and 1 <= self.segments <= 2000):
            raise FieldError("EntryProblemSettings", "segments", f"= {self.segments} must be an integer in [1, 2000]")
        if not (isinstance(self.nodes_per_segment, int) and 2 <= self.nodes_per_segment <= 12):
            raise FieldError("EntryProblemSettings", "nodes_per_segment", f"= {self.nodes_per_segment} must be an "
                                f"integer in [2, 12]")
        if not 0.0 <= self.heading_weight <= 10.0:
            raise FieldError("EntryProblemSettings", "heading_weight", f"= {self.heading_weight} must be in [0, 10]")
        if not 1e-4 <= self.max_lossless_gap <= 1.0:
            raise FieldError("EntryProblemSettings", "max_lossless_gap", f"= {self.max_lossless_gap} must be in "
                                f"[1e-4, 1] (1: the paper's relaxation, no floor on |u|)")
        if self.path_margin is None:
            self.path_margin = DEFAULT_PATH_MARGIN[FORMULATIONS[self.formulation].bank]
        if not 0.0 <= self.path_margin <= 0.5:
            raise FieldError("EntryProblemSettings", "path_margin", f"= {self.path_margin} must be in [0, 0.5]")
        if not 0.0 <= self.path_margin_ramp_s <= 600.0:
            raise FieldError("EntryProblemSettings", "path_margin_ramp_s", f"= {self.path_margin_ramp_s} must be in "
                                f"[0, 600] s")
        margins = tuple(self.flight_path_margins_deg)
        if len(margins) != 2 or not all(isinstance(v, (int, float)) and 0.0 <= v <= 5.0 for v in margins):
            raise FieldError("EntryProblemSettings", "flight_path_margins_deg", f"= {margins} needs two margins in "
                                f"[0, 5] deg (above the lower bound, below the upper)")
        self.flight_path_margins_deg = tuple(float(v) for v in margins)
        if not 0.0 <= self.bank_margin_deg <= 20.0:
            raise FieldError("EntryProblemSettings", "bank_margin_deg", f"= {self.bank_margin_deg} must be in [0, 20] deg")
        if self.heading_sign not in (-1.0, 0.0, 1.0):
            raise FieldError("EntryProblemSettings", "heading_sign", f"= {self.heading_sign} must be -1, 0 or +1")


#: EntryProblemSettings.path_margin by the bank's form (Formulation.bank) when not given
DEFAULT_PATH_MARGIN = {"lossless": 0.04, "rate": 0.02}

#: EntryProblemSettings fields of the paper's lossless relaxation (Table 3 'Lossless Bank'):
#: no floor on |u|, no bank-rate limit, no path margin, the heading regulariser closing the gap
PAPER_LOSSLESS = {"formulation": "lossless", "max_lossless_gap": 1.0, "lossless_rate_limit": False, "path_margin": 0.0}


@dc.dataclass(frozen=True)
class FlightCheck:
    """How a plan's controls are flown to verify it: as the closed loop flies them.

    Attributes:
      period_s: the guidance period [s]: the plan's bank and alpha are sampled and held this
        long and tracked by the closed loop's actuator law (drake_entry.models.actuator); None flies
        the plan's own bank and alpha directly (no actuator).
      lead_s: each command is read this far ahead on the plan [s] (the actuators' lag: half
        the period for the hold plus 1/omega of the 2 rad/s position loop, 1.0 s at a 1-s period), as the SCvx guidance does.
      alpha_acceleration_deg_s2: the alpha actuator's acceleration limit (not in paper 001: a
        labelled choice well above what a 1 deg/s planned alpha rate needs).
      feedback, feedback_state_weight, feedback_offset_limits: the closed loop's tracking law
        between re-plans ("tvlqr" or "none"; guidance.spec.ReplanningSpec), its LQR path weight
        and its bank and alpha offset bounds [rad]: the plan is verified flown with it.
    """

    period_s: float | None = 1.0
    lead_s: float = 1.0
    alpha_acceleration_deg_s2: float = 5.0
    feedback: str = "none"
    feedback_state_weight: float = 1.0e-3
    feedback_offset_limits: tuple = (0.0, 0.0)
