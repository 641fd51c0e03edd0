"""User-facing errors and the typed YAML loader that turns schema errors into one line."""
from __future__ import annotations

import os
import re

from pydrake.common.yaml import yaml_load_typed


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


def check_range(field: str, value, lo: float, hi: float):
    """Raise a one-line ScenarioError unless lo <= value <= hi (None and NaN fail)."""
    if value is None or not (lo <= value <= hi):
        raise ScenarioError(f"{field} = {value} is out of range; allowed [{lo:g}, {hi:g}]")


def load_yaml_typed(schema, *, path: str | None = None, text: str | None = None, where: str | None = None):
    """``yaml_load_typed`` with errors reported as a ScenarioError naming the file."""
    where = where or path or "YAML"
    if path is not None:
        if not os.path.exists(path):
            raise ScenarioError(f"file not found: {path}")
        if os.path.isdir(path):
            raise ScenarioError(f"{path} is a directory, not a YAML file")
        try:
            with open(path, encoding="utf-8") as f:
                text = f.read()
        except UnicodeDecodeError:
            raise ScenarioError(f"{path} is not a text (UTF-8) YAML file") from None
    if not text or not text.strip():
        raise ScenarioError(f"{where}: the file is empty; a {schema.__name__} needs its fields")
    try:
        return yaml_load_typed(schema=schema, data=text)
    except RuntimeError as e:  # unknown fields, wrong structure
        msg = str(e)
        if "were unknown to the schema" in msg:
            names = msg[msg.index("["):msg.index("]") + 1]
            msg = f"unknown field(s) {names}; check the spelling against the {schema.__name__} schema"
        elif "did not match any of the allowed type options for" in msg:  # a Union field's !Tag
            m = re.search(r"tag value '([^']*)'.*options for '([^']*)' \((.*)\)", msg)
            if m:
                allowed = ", ".join("!" + t for t in re.findall(r"\.(\w+)'>", m.group(3)))
                msg = f"{m.group(2)}: unknown type tag '!{m.group(1)}'; allowed: {allowed}"
        raise ScenarioError(f"{where}: {msg}") from None
    except (ValueError, TypeError) as e:  # wrong scalar types
        raise ScenarioError(f"{where}: {e}") from None
    except Exception as e:  # the YAML parser itself
        raise ScenarioError(f"{where}: not valid YAML: {str(e).splitlines()[0]}") from None
