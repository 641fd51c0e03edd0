"""Scenario spec of the bank-profile guidance; YAML tag ``guidance: !BankProfile``."""

import dataclasses as dc

from drake_entry.errors import check_range
from drake_entry.guidance.spec import ReversingBankSpec

__all__ = ["BankProfile"]


@dc.dataclass
class BankProfile(ReversingBankSpec):
    """|sigma| linear in normalised energy e = (E0 - E)/(E0 - E_f) from ``bank_start_deg``
    (e = 0, the entry interface) to ``bank_end_deg`` (e = 1, the terminal interface), the
    form of paper 004 eq. 17, flown open loop in magnitude with closed-loop bank reversals."""

    bank_start_deg: float = 45.0
    bank_end_deg: float = 45.0

    def validate(self, scenario) -> None:
        super().validate(scenario)
        limit = scenario.make_vehicle().bank_limit_deg
        for name in ("bank_start_deg", "bank_end_deg"):
            check_range(f"guidance.{name}", getattr(self, name), 0.0, limit)
