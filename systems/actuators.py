"""BankActuator: second-order bank-angle actuator with angle, rate and acceleration limits.

The law is drake_entry.actuator.bank_actuator_rates: the command is clipped to
+-bank_limit and tracked with rate and acceleration limits, so a bank reversal (a sign
flip of the command) rotates through wings-level at the rate limit.

Ports:
  input  "bank_command"  [1]  sigma_cmd [rad]
  output "bank"          [1]  sigma [rad] (state: no direct feedthrough)
  output "bank_rate"     [1]  sigma_dot [rad/s]
"""
from __future__ import annotations

from pydrake.systems.framework import BasicVector, LeafSystem

from drake_entry.actuator import bank_actuator_rates


class BankActuator(LeafSystem):
    def __init__(self, *, bank_limit: float, rate_limit: float, accel_limit: float,
                 bandwidth: float = 2.0, initial_bank: float = 0.0):
        """Args: bank_limit [rad], rate_limit [rad/s], accel_limit [rad/s^2],
        bandwidth omega [rad/s] of the position loop (the rate loop runs at 4 omega)."""
        super().__init__()
        for name, v in (("bank_limit", bank_limit), ("rate_limit", rate_limit),
                        ("accel_limit", accel_limit), ("bandwidth", bandwidth)):
            if not v > 0:
                raise ValueError(f"BankActuator.{name} must be > 0, got {v}")
        self.bank_limit, self.rate_limit, self.accel_limit = bank_limit, rate_limit, accel_limit
        self.omega = bandwidth
        self.DeclareContinuousState(BasicVector([initial_bank, 0.0]))
        self.cmd_port = self.DeclareVectorInputPort("bank_command", 1)
        state = {self.all_state_ticket()}
        self.DeclareVectorOutputPort("bank", 1, lambda c, o: o.SetAtIndex(0, c.get_continuous_state_vector()[0]),
                                     prerequisites_of_calc=state)
        self.DeclareVectorOutputPort("bank_rate", 1,
                                     lambda c, o: o.SetAtIndex(0, c.get_continuous_state_vector()[1]),
                                     prerequisites_of_calc=state)

    def DoCalcTimeDerivatives(self, context, derivatives):
        sigma, rate = context.get_continuous_state_vector().CopyToVector()
        derivatives.get_mutable_vector().SetFromVector(bank_actuator_rates(
            sigma, rate, self.cmd_port.Eval(context)[0], bank_limit=self.bank_limit, rate_limit=self.rate_limit,
            accel_limit=self.accel_limit, bandwidth=self.omega))
