"""Scenario spec of the drag-energy guidance (paper 000 Secs. IV.A, VI.D); YAML tag
``guidance: !DragEnergy``."""

import dataclasses as dc
from typing import Optional

from drake_entry.errors import ScenarioError, check_range
from drake_entry.guidance.spec import ReplansOnBoard, ReversingBankSpec

__all__ = ["DragEnergy", "REPLAN_STARTS"]

#: where a re-plan's initial drag and slope come from (DragEnergy.replan_start)
REPLAN_STARTS = ("flown", "reference")


@dc.dataclass
class DragEnergy(ReversingBankSpec, ReplansOnBoard):
    """Drag-energy reference by a pseudospectral SOCP, drag tracking and bank reversals."""

    n_nodes: int = 40
    # constrain the terminal drag to the terminal interface's (eq. 85) instead of leaving it free
    terminal_drag: bool = True
    # clarabel | scs
    solver: str = "clarabel"
    # relative safety margin on both corridor bounds
    corridor_margin: float = 0.03
    corridor_points: int = 300
    # pre-guidance: this bank until the drag stops rising (D' >= 0) after pre_guidance_min_s
    pre_guidance_bank_deg: float = 0.0
    pre_guidance_min_s: float = 100.0
    # no re-planning past this normalised energy (little range is left to correct)
    replan_until_e: float = 0.9
    # re-plans take the corridor, the terminal drag and the drag-to-state maps of the vehicle with
    # the lift and drag ratios the flight has sensed (its q and heat-rate limits divided by the
    # sensed density ratio, as SCvx's re-plans hold them)
    replan_model_scales: bool = False
    # where each re-plan starts (eq. 84's initial drag and slope): "flown", the drag and slope
    # the vehicle has (as the first plan); "reference", the current reference's at the flight's
    # energy, so a tracking error is left to the tracking law and is not built into the new plan
    replan_start: str = "flown"
    # corridor centring (not paper 000's; 0: the paper's smoothest profile): the weight of the
    # profile's least distance from both bounds beside eq. 92 (DragEnergyProblem.centring)
    corridor_centring: float = 0.0
    # the plans fly the great-circle range to go plus this [m] (not paper 000's; 0: the range to
    # the target): the range a flight's end game adds beyond its plan, negative when it ends past
    # the target; never below a tenth of the range left (DragEnergyPlanner.range_to_go)
    range_offset_m: float = 0.0
    # the drag's reach (not paper 000's; null: the paper's SOCP): each plan's feedforward u_FF
    # (eq. 95) kept in the bank's range less this share of L/D on each side, by successive
    # linearisation (DragEnergyProblem.reach_margin): a low-L/D capsule cannot fly the drag
    # rises and falls the smoothest profile asks for
    reach_margin: Optional[float] = None
    # drag tracking (eq. 101), energy domain: zeta < 0 because E decreases (paper 000 Sec. VI.D)
    zeta: float = -0.7
    # pseudo-frequency omega_D [1/(J/kg)] = 2 pi / (energy per oscillation) (paper 000: constant)
    omega_per_J: float = 2.0e-6
    # if > 0: schedule omega_D = bandwidth / (D V) so the loop has this time-domain bandwidth
    # [rad/s] all along (a constant omega_D is 25x faster at peak drag than at the end)
    bandwidth_rad_s: float = 0.0
    # integral gain as a fraction of its stability limit: k_D^i = -ratio * 2 |zeta| omega^3
    # (Routh-Hurwitz on lambda^3 + 2 zeta omega lambda^2 + omega^2 lambda + k = 0, E decreasing)
    integral_ratio: float = 0.0

    def validate(self, scenario) -> None:
        super().validate(scenario)
        check_range("guidance.n_nodes", self.n_nodes, 5, 400)
        check_range("guidance.zeta", self.zeta, -10.0, -1e-3)
        check_range("guidance.omega_per_J", self.omega_per_J, 1e-9, 1e-3)
        check_range("guidance.integral_ratio", self.integral_ratio, 0.0, 0.99)
        check_range("guidance.bandwidth_rad_s", self.bandwidth_rad_s, 0.0, 10.0)
        check_range("guidance.replan_until_e", self.replan_until_e, 0.0, 1.0)
        check_range("guidance.corridor_margin", self.corridor_margin, 0.0, 0.49)
        check_range("guidance.corridor_centring", self.corridor_centring, 0.0, 1e5)
        check_range("guidance.range_offset_m", self.range_offset_m, -1e6, 1e6)
        check_range("guidance.corridor_points", self.corridor_points, 20, 100000)
        if self.reach_margin is not None:
            check_range("guidance.reach_margin", self.reach_margin, 0.0, 0.45)
        check_range("guidance.pre_guidance_min_s", self.pre_guidance_min_s, 0.0, 1e5)
        check_range("guidance.pre_guidance_bank_deg", self.pre_guidance_bank_deg, -180.0, 180.0)
        if self.replan_start not in REPLAN_STARTS:
            raise ScenarioError(f"guidance.replan_start '{self.replan_start}' is unknown; allowed: "
                                f"{', '.join(REPLAN_STARTS)}")
        if self.solver not in ("clarabel", "scs"):
            raise ScenarioError(f"guidance.solver '{self.solver}' is unknown; allowed: clarabel, scs")
