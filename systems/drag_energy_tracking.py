"""DragTrackingController: feedback-linearised drag tracking in the energy domain (paper 000
eqs. 97-101), run at a fixed period, bank magnitude held between updates.

u = u_FF + (-2 zeta omega dD' - omega^2 dD - k int dD dE) / b_D, u_FF = (D''_ref - a_D)/b_D,
with omega constant (the paper) or scheduled as bandwidth / (D V) (constant time-domain
bandwidth; an option beyond the paper),
|sigma| = acos(clip(u / (L/D), cos(sigma_max), 1)) (eq. 96). E decreases along the flight,
so a stable error dynamics needs zeta < 0 and k < 0 (paper 000 Sec. VI.D); k is set as a
fraction of its Routh-Hurwitz limit, k = -ratio * 2 |zeta| omega^3. Before the guidance
engages, the pre-guidance bank is commanded.

Ports:
  - input  "estimated_state"  [6]
  - input  "reference"        [4]  DragEnergyGuidance output
  - input  "flight_conditions" [9] (optional) the accelerometer's drag is fed back, with the
                                 model's drag dynamics scaled to it (planner.drag_state)
  - output "bank_magnitude"   [1]  |sigma_cmd| [rad] (discrete state: no feedthrough)
  - output "vertical_control" [1]  u = (L/D) cos(sigma) demanded (before saturation)
"""
from __future__ import annotations

import math

import numpy as np
from pydrake.systems.framework import BasicVector, LeafSystem

from drake_entry.errors import ScenarioError
from drake_entry.guidance.drag_energy.planner import DragEnergyPlanner
from drake_entry.models.dynamics import FLIGHT_CONDITION_NAMES
from drake_entry.systems.drag_energy_guidance import sensed_drag
from drake_entry.systems.lifetime import weak_element, weak_method

__all__ = ["DragTrackingController"]


class DragTrackingController(LeafSystem):
    def __init__(self, planner: DragEnergyPlanner, *, zeta: float, omega: float, integral_ratio: float = 0.0,
                 period: float = 1.0, pre_guidance_bank: float = 0.0, sigma_max: float | None = None,
                 bandwidth: float = 0.0):
        """Args: zeta (< 0), omega [1/(J/kg)] (paper 000's constant pseudo-frequency),
        integral_ratio in [0, 1), period [s], pre_guidance_bank [rad], sigma_max [rad],
        bandwidth [rad/s]: if > 0, omega = bandwidth / (D V) at each update instead."""
        super().__init__()
        if not zeta < 0:
            raise ScenarioError(f"DragTrackingController.zeta must be < 0 (energy decreases), got {zeta}")
        if not omega > 0:
            raise ScenarioError(f"DragTrackingController.omega must be > 0 per J/kg, got {omega}")
        if not 0 <= integral_ratio < 1:
            raise ScenarioError(f"DragTrackingController.integral_ratio must be in [0, 1), got {integral_ratio}")
        self.planner = planner
        self.zeta, self.omega, self.bandwidth = zeta, omega, bandwidth
        self.integral_ratio = integral_ratio
        self.pre_bank = pre_guidance_bank
        self.sigma_max = planner.sigma_max if sigma_max is None else sigma_max
        self.est_port = self.DeclareVectorInputPort("estimated_state", 6)
        self.ref_port = self.DeclareVectorInputPort("reference", 4)
        self.fc_port = self.DeclareVectorInputPort("flight_conditions", len(FLIGHT_CONDITION_NAMES))
        # [|sigma|, u, integral of dD dE, E at last update (nan before engagement)]
        self._state = self.DeclareDiscreteState(BasicVector([pre_guidance_bank, 0.0, 0.0, np.nan]))
        self.DeclarePeriodicDiscreteUpdateEvent(period, 0.0, weak_method(self._update))
        self.DeclareVectorOutputPort("bank_magnitude", 1, weak_element(self._held, 0),
                                     prerequisites_of_calc={self.xd_ticket()})
        self.DeclareVectorOutputPort("vertical_control", 1, weak_element(self._held, 1),
                                     prerequisites_of_calc={self.xd_ticket()})

    def _held(self, context) -> np.ndarray:
        """The held state [|sigma| rad, u, integral of dD dE, E at the last update]."""
        return context.get_discrete_state(self._state).get_value()

    def control(self, x, ref, integral: float, sensed: float | None = None):
        """(|sigma|, u) for estimate x and reference [D, D', D''] (eq. 101)."""
        d = self.planner.drag_state(x, sensed)
        dD = d.D - ref[0]
        dDp = d.D_prime - ref[1]
        w = self.bandwidth / (d.D * x[3]) if self.bandwidth > 0 else self.omega
        k_i = -self.integral_ratio * 2.0 * abs(self.zeta) * w**3
        u = d.feedforward(ref[2]) + (-2.0 * self.zeta * w * dDp - w * w * dD - k_i * integral) / d.b_D
        ratio = u / d.lift_to_drag
        return math.acos(min(max(ratio, math.cos(self.sigma_max)), 1.0)), u, dD, d

    def _update(self, context, discrete_state):
        s = context.get_discrete_state(self._state).get_value().copy()
        ref = self.ref_port.Eval(context)
        if ref[3] < 0.5:
            s[0] = self.pre_bank
        else:
            x = self.est_port.Eval(context)
            sensed = sensed_drag(self.fc_port, context)
            E = self.planner.energy(x)
            s[0], s[1], dD, _ = self.control(x, ref, s[2], sensed)
            if np.isfinite(s[3]):
                s[2] += dD * (E - s[3])
            s[3] = E
        discrete_state.get_mutable_vector(self._state).SetFromVector(s)
