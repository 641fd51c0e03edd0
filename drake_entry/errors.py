"""User-facing errors: each is printed by the CLI as one line (drake_entry.typed_yaml reads
files and overrides into them)."""
from __future__ import annotations

__all__ = ["DrakeEntryError", "ScenarioError", "FieldError", "NonFiniteStateError", "ModelRangeError",
           "UnsupportedScalarError", "CampaignError", "Interrupted", "check_range"]


class DrakeEntryError(Exception):
    """Base of every user-facing error: the CLI prints it as one line and exits 2. Anything
    else that escapes is a bug and keeps its traceback."""


class ScenarioError(DrakeEntryError, ValueError):
    """Bad user input (scenario, vehicle or problem file, API argument): one line naming the
    field, the value and the allowed range."""


class FieldError(ScenarioError):
    """A ScenarioError about one field of a settings object: ``<owner>.<field> <complaint>``.
    A spec that passes its own fields on to a settings object re-raises it under its own name
    (``under("guidance")``), so the message names the field the user wrote."""

    def __init__(self, owner: str, field: str, complaint: str):
        super().__init__(f"{owner}.{field} {complaint}")
        self.owner, self.field, self.complaint = owner, field, complaint

    def under(self, owner: str) -> "FieldError":
        """The same complaint about the same field, owned by ``owner``."""
        return FieldError(owner, self.field, self.complaint)


class NonFiniteStateError(DrakeEntryError, FloatingPointError):
    """The equations of motion produced NaN or infinity (a NaN command, model or state):
    a simulation stops there with this as its reason instead of integrating garbage."""


class ModelRangeError(ScenarioError):
    """A model evaluated outside its range (e.g. an altitude above the atmosphere table): bad
    input to the API; inside a simulation, the run stops there with this as its reason."""


class UnsupportedScalarError(DrakeEntryError, TypeError):
    """A model asked for a scalar type it cannot take (a table look-up with a symbolic
    Expression)."""


class CampaignError(DrakeEntryError):
    """A campaign directory that cannot be used as asked (other settings, another writer,
    nothing to report)."""


class Interrupted(DrakeEntryError):
    """Ctrl-C (SIGINT) stopped a long run cleanly: what was finished is kept, and the message
    says how to go on. The CLI prints it as one line and exits 130."""


def check_range(field: str, value, lo: float, hi: float):
    """Raise a one-line ScenarioError unless lo <= value <= hi (None and NaN fail)."""
    if value is None or not (lo <= value <= hi):
        raise ScenarioError(f"{field} = {value} is out of range; allowed [{lo:g}, {hi:g}]")
