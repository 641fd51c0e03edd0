"""Markdown reference of the YAML schemas (scenario, vehicle, optimal-control problem), made
from the schema dataclasses themselves: field names, types, defaults and the comment lines
written beside each field in the source, so the reference cannot drift from the code. The
documentation site generates its reference pages with it (docs/hooks/reference.py).

    from drake_entry.schema_doc import schema_markdown
    from drake_entry.scenario import Scenario
    print(schema_markdown(Scenario, "Scenario YAML"))
"""
from __future__ import annotations

import dataclasses as dc
import inspect
import re
import typing

__all__ = ["field_comments", "schema_markdown"]

_FIELD = re.compile(r"^    (\w+)\s*:\s*([^=#]+?)\s*(?:=\s*(.*?))?\s*(?:#\s*(.*))?$")


def field_comments(cls) -> dict[str, str]:
    """{field: description} from the comment lines directly above each field of ``cls`` (not
    its bases) and the field line's trailing comment."""
    try:
        lines = inspect.getsource(cls).splitlines()
    except (OSError, TypeError):
        return {}
    out, pending = {}, []
    for line in lines[1:]:
        stripped = line.strip()
        if line.startswith("    #") and not line.startswith("     "):
            pending.append(stripped.lstrip("#").strip())
            continue
        m = _FIELD.match(line)
        if m and not stripped.startswith(("def ", "@", "return")):
            text = " ".join(pending + ([m.group(4)] if m.group(4) else []))
            out[m.group(1)] = text.strip()
        pending = []
    return out


def _is_schema(t) -> bool:
    return dc.is_dataclass(t) and isinstance(t, type)


def _members(t) -> tuple:
    """The types of a Union (or Optional) annotation, else (t,)."""
    return typing.get_args(t) if typing.get_origin(t) is typing.Union else (t,)


def _type_name(t) -> str:
    if t is type(None):
        return "null"
    origin = typing.get_origin(t)
    if origin is typing.Union:
        return " or ".join(_type_name(a) for a in typing.get_args(t))
    if origin in (list, tuple):
        args = typing.get_args(t)
        return f"list of {_type_name(args[0])}" if args else "list"
    if origin is dict:
        return "mapping"
    if _is_schema(t):
        module = t.__module__
        tag = f"!{t.__name__}" if module.startswith("pydrake") or ".guidance." in module else t.__name__
        return tag
    return getattr(t, "__name__", str(t)).replace("typing.", "")


def _default(f: dc.Field) -> str:
    if f.default is not dc.MISSING:
        value = f.default
    elif f.default_factory is not dc.MISSING:
        value = f.default_factory()
    else:
        return "required"
    if _is_schema(type(value)):
        return f"{type(value).__name__}()" if type(value).__module__.startswith("pydrake") else "see below"
    if isinstance(value, str):
        return f'"{value}"'
    return "null" if value is None else repr(value)


def schema_markdown(root, title: str, *, intro: str = "") -> str:
    """Markdown: one table per schema dataclass reachable from ``root`` (breadth first), with
    each field's YAML key, type, default and description."""
    sections, queue, seen = [], [(root, "")], set()
    while queue:
        cls, path = queue.pop(0)
        if cls in seen:
            continue
        seen.add(cls)
        hints = typing.get_type_hints(cls)
        comments = {}
        for base in reversed(cls.__mro__):
            if _is_schema(base):
                comments.update(field_comments(base))
        doc = inspect.cleandoc(cls.__doc__ or "") if cls.__doc__ and not cls.__doc__.startswith(cls.__name__ + "(") \
            else ""
        where = f"`{path}`" if path else "top level"
        tag = f" (YAML tag `!{cls.__name__}`)" if ".guidance." in cls.__module__ else ""
        rows = ["| key | type | default | description |", "|---|---|---|---|"]
        for f in dc.fields(cls):
            t = hints.get(f.name, f.type)
            cells = (f"`{f.name}`", _type_name(t), f"`{_default(f)}`", comments.get(f.name, ""))
            rows.append("| " + " | ".join(c.replace("|", "\\|") for c in cells) + " |")
            for member in _members(t):
                for inner in (typing.get_args(member) or (member,)):
                    if _is_schema(inner) and not inner.__module__.startswith("pydrake"):
                        queue.append((inner, f"{path}.{f.name}" if path else f.name))
        sections.append(f"## {cls.__name__}{tag}\n\nWhere: {where}. Python: `{cls.__module__}.{cls.__name__}`."
                        + (f"\n\n{doc}" if doc else "") + "\n\n" + "\n".join(rows))
    head = f"# {title}\n\n" + (intro + "\n\n" if intro else "")
    return head + "\n\n".join(sections) + "\n"
