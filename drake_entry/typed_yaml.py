"""Typed YAML: the one way scenario, vehicle and problem files and ``--set`` overrides are read.

Every input goes through the same two steps:

1. ``check``: the YAML tree (read by PyYAML's safe loader, ``!Tags`` kept as ``Tagged``, never
   a Python object) is walked against the dataclass schema. Each problem is reported as one
   line naming the full field path: an unknown field with the closest valid name
   ("entry.velocty_m_s: unknown field; did you mean velocity_m_s?"), a value of the wrong kind
   ("entry.altitude_km: expected a number, got 'high'"; an integer field given 40.5; a boolean
   given 'maybe'), a block of fields given a scalar or null (Drake's loader would silently take
   the first type of a tagged union for ``guidance: 3``), an unknown type tag.
2. Drake's ``yaml_load_typed`` builds the objects (its own errors, if any remain, are turned
   into one line too).
3. ``check_numbers``: every number of the loaded tree is finite (a NaN never reaches a solver);
   a field may be infinite only where its default is (an unbounded limit such as a vehicle's
   ``dynamic_pressure_max_kPa: .inf``). Validators of objects built in Python call it too.

An override (``override(root, "guidance.period_s", "2.5")``) walks the dotted path on the
loaded objects, checks the value against the field's declared type as a file's value would
be, and loads it with Drake's loader on top of the object's current values (``defaults``),
so a file and an override accept and refuse exactly the same values.
"""
from __future__ import annotations

import dataclasses as dc
import difflib
import os
import re
import textwrap
import types
import typing
from typing import Any, NamedTuple

import yaml
from pydrake.common.yaml import yaml_load_typed

from drake_entry.errors import ScenarioError

__all__ = ["Tagged", "DuplicateKeyError", "parse", "check", "check_numbers", "packaged_names",
           "load_packaged_or_file", "load_yaml_typed", "resolve_file_fields", "override"]


class Tagged(NamedTuple):
    """A YAML node with a local tag (``!Uniform {min: 0, max: 1}``): the tag without '!'."""

    tag: str
    value: Any


class DuplicateKeyError(yaml.YAMLError):
    """A mapping that names one key twice (YAML keeps the last silently)."""

    def __init__(self, key, mark):
        super().__init__(f"the field {key!r} is given twice")
        self.problem_mark = mark


class _TagKeepingLoader(yaml.SafeLoader):
    """PyYAML's safe loader that keeps local ``!Tags`` as ``Tagged`` (never constructs objects)
    and refuses a key given twice in one mapping."""

    def construct_mapping(self, node, deep=False):
        if isinstance(node, yaml.MappingNode):
            seen = set()
            for key_node, _ in node.value:
                if key_node.tag == "tag:yaml.org,2002:merge":  # '<<': merged keys may be overridden
                    continue
                key = self.construct_object(key_node, deep=True)
                try:
                    duplicate = key in seen
                    seen.add(key)
                except TypeError:  # an unhashable key: the base loader says so
                    duplicate = False
                if duplicate:
                    raise DuplicateKeyError(key, key_node.start_mark)
        return super().construct_mapping(node, deep=deep)


def _construct_tagged(loader, suffix, node):
    if isinstance(node, yaml.MappingNode):
        value = loader.construct_mapping(node, deep=True)
    elif isinstance(node, yaml.SequenceNode):
        value = loader.construct_sequence(node, deep=True)
    else:
        value = loader.construct_scalar(node)
    return Tagged(suffix, value)


_TagKeepingLoader.add_multi_constructor("!", _construct_tagged)


def parse(text: str, where: str):
    """The YAML tree of ``text`` (tags kept), or a one-line ScenarioError saying why not."""
    try:
        return yaml.load(text, Loader=_TagKeepingLoader)  # noqa: S506 (a safe loader subclass)
    except yaml.YAMLError as e:
        first = str(e).splitlines()[0] if str(e) else type(e).__name__
        mark = getattr(e, "problem_mark", None)
        at = f" (line {mark.line + 1}, column {mark.column + 1})" if mark is not None else ""
        raise ScenarioError(f"{where}: not valid YAML{at}: {first}") from None


def _describe(value) -> str:
    if isinstance(value, Tagged):
        return f"a !{value.tag} block"
    if isinstance(value, dict):
        return "a block of fields"
    if isinstance(value, list):
        return "a list"
    if value is None:
        return "nothing (null)"
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def _hints(cls) -> dict:
    try:
        return typing.get_type_hints(cls)
    except Exception:  # a schema whose annotations cannot be resolved: Drake's loader decides
        return {}


def _closest(name: str, names) -> str:
    match = difflib.get_close_matches(name, list(names), n=1, cutoff=0.6)
    if match:
        return f"did you mean {match[0]}?"
    return "allowed: " + ", ".join(sorted(names))


def _join(path: str, name) -> str:
    return f"{path}[{name}]" if isinstance(name, int) else (f"{path}.{name}" if path else str(name))


def _union_args(hint) -> tuple | None:
    if typing.get_origin(hint) in (typing.Union, types.UnionType):
        return typing.get_args(hint)
    return None


#: the scalar kinds a schema field may declare, in the order a Union tries them, and their words
_KIND = {float: "a number", int: "an integer", bool: "true or false", str: "text"}


def _scalar(hint, value):
    """``value`` as Drake's loader converts it to ``hint`` (bool, int or float), None when it
    refuses: int -> float, an integral float -> int, number text by Python's parsers (YAML
    1.1 reads '1.0e6' as text), booleans only as true/false."""
    if type(value) is hint:
        return value
    if hint is float and type(value) is int:
        return float(value)
    if hint is int and type(value) is float and value.is_integer():
        return int(value)
    if type(value) is str and hint in (float, int):
        try:
            return hint(value)
        except ValueError:
            return None
    if type(value) is str and hint is bool and value in ("true", "false"):
        return value == "true"
    return None


def check(hint, value, path: str) -> None:
    """Raise a ScenarioError (no file prefix) for the first value of ``value`` that ``hint``
    (a dataclass, a Union, float, int, bool, str, list[...], dict[...]) cannot take."""
    alternatives = _union_args(hint)
    if alternatives is not None:
        _check_union(alternatives, value, path)
    elif dc.is_dataclass(hint) and isinstance(hint, type):
        if isinstance(value, Tagged):
            if value.tag != hint.__name__:
                raise ScenarioError(f"{path}: unknown type tag '!{value.tag}'; allowed: !{hint.__name__}")
            value = value.value
        if not isinstance(value, dict):
            raise ScenarioError(f"{path or 'the file'}: expected a block of fields (a mapping), "
                                f"got {_describe(value)}")
        hints = _hints(hint)
        names = [f.name for f in dc.fields(hint)]
        for key, item in value.items():
            if not isinstance(key, str) or key not in names:
                raise ScenarioError(f"{_join(path, key)}: unknown field; {_closest(str(key), names)}")
            if key in hints:
                check(hints[key], item, _join(path, key))
    elif hint in (bool, int, float):
        if _scalar(hint, value) is None:
            raise ScenarioError(f"{path}: expected {_KIND[hint]}, got {_describe(value)}")
    elif hint is str:
        if not isinstance(value, str):
            raise ScenarioError(f"{path}: expected {_KIND[str]}, got {_describe(value)}")
    elif typing.get_origin(hint) in (list, typing.List):
        if not isinstance(value, list):
            raise ScenarioError(f"{path}: expected a list, got {_describe(value)}")
        (item_hint,) = typing.get_args(hint) or (Any,)
        for i, item in enumerate(value):
            check(item_hint, item, _join(path, i))
    elif typing.get_origin(hint) in (dict, typing.Dict):
        if not isinstance(value, dict):
            raise ScenarioError(f"{path}: expected a block of entries (a mapping), got {_describe(value)}")
        args = typing.get_args(hint)
        for key, item in value.items():
            if args:
                check(args[1], item, _join(path, key))
    # anything else (Drake's schema classes, Any): Drake's loader decides


def _default(field):
    """A dataclass field's default value (None when it has none or a factory)."""
    return field.default if field.default is not dc.MISSING else None


def _fields(obj) -> list[tuple[str, object]]:
    """(name, default) of the fields of a dataclass or a Drake schema struct (``__fields__``)."""
    if dc.is_dataclass(obj) and not isinstance(obj, type):
        return [(f.name, _default(f)) for f in dc.fields(obj)]
    return [(f.name, None) for f in getattr(type(obj), "__fields__", ())]


def check_numbers(root, path: str = "", default=None) -> None:
    """Raise a ScenarioError (no file prefix) for the first number of ``root`` (a loaded tree:
    dataclasses, Drake schema structs, lists, tuples, dicts, numpy arrays) that is NaN, or
    infinite where its field's default is not an infinity of that sign."""
    import numpy as np

    if isinstance(root, bool) or root is None or isinstance(root, (str, bytes)):
        return
    if isinstance(root, (int, float, np.integer, np.floating)):
        x = float(root)
        if x != x:
            raise ScenarioError(f"{path or 'value'} = nan is not a finite number")
        if x in (np.inf, -np.inf) and not (isinstance(default, (int, float)) and default == x):
            raise ScenarioError(f"{path or 'value'} = {x} is not a finite number"
                                + (" (this field has no unbounded value)" if path else ""))
        return
    if isinstance(root, np.ndarray):
        root = root.tolist()
    if isinstance(root, (list, tuple)):
        for i, item in enumerate(root):
            check_numbers(item, _join(path, i))
    elif isinstance(root, dict):
        for key, item in root.items():
            check_numbers(item, _join(path, key))
    else:
        for name, field_default in _fields(root):
            check_numbers(getattr(root, name, None), _join(path, name), field_default)


def _tag_name(cls) -> str:
    return cls.__name__.split("\U0001d4e3")[0]  # Drake's template instances: DeterministicVector𝓣None𝓤


def _check_union(alternatives: tuple, value, path: str) -> None:
    optional = type(None) in alternatives
    options = [a for a in alternatives if a is not type(None)]
    if value is None and optional:
        return
    if len(options) == 1:
        return check(options[0], value, path)
    classes = [a for a in options if isinstance(a, type) and a not in _KIND]
    if isinstance(value, Tagged):
        chosen = {_tag_name(a): a for a in classes}.get(value.tag)
        if chosen is not None and dc.is_dataclass(chosen):
            return check(chosen, value.value, path)
        if chosen is None and all(dc.is_dataclass(a) for a in classes):
            raise ScenarioError(f"{path}: unknown type tag '!{value.tag}'; allowed: "
                                + ", ".join("!" + _tag_name(a) for a in classes))
        return  # one of Drake's own schema types (distributions): its loader decides
    for scalar in _KIND:
        if scalar in options:
            try:
                return check(scalar, value, path)
            except ScenarioError:
                pass
    if isinstance(value, dict) and classes:  # untagged: Drake takes the first alternative
        if dc.is_dataclass(classes[0]):
            check(classes[0], value, path)
        return
    kinds = [_KIND[s] for s in _KIND if s in options]
    tags = ", ".join("!" + _tag_name(a) for a in classes)
    wanted = " or ".join(kinds + ([f"a tagged block ({tags})"] if tags else []))
    raise ScenarioError(f"{path}: expected {wanted}, got {_describe(value)}")


def _drake_load(schema, text: str, where: str, defaults=None):
    try:
        if defaults is None:
            return yaml_load_typed(schema=schema, data=text)
        return yaml_load_typed(schema=schema, data=text, defaults=defaults)
    except RuntimeError as e:  # unknown fields, wrong structure (normally caught by check)
        msg = str(e)
        if "were unknown to the schema" in msg:
            names = msg[msg.index("["):msg.index("]") + 1]
            msg = f"unknown field(s) {names}; check the spelling against the {schema.__name__} schema"
        elif "did not match any of the allowed type options for" in msg:  # a Union field's !Tag
            m = re.search(r"tag value '([^']*)'.*options for '([^']*)' \((.*)\)", msg)
            if m:
                allowed = ", ".join("!" + t for t in re.findall(r"\.(\w+)'>", m.group(3)))
                msg = f"{m.group(2)}: unknown type tag '!{m.group(1)}'; allowed: {allowed}"
        raise ScenarioError(f"{where}: {msg.splitlines()[0]}") from None
    except (ValueError, TypeError) as e:  # wrong scalar types (normally caught by check)
        raise ScenarioError(f"{where}: {str(e).splitlines()[0]}") from None
    except Exception as e:  # the YAML parser itself
        raise ScenarioError(f"{where}: not valid YAML: {str(e).splitlines()[0]}") from None


def packaged_names(folder: str) -> tuple:
    """The names of the YAML files shipped in drake_entry/<folder> (``<name>.yaml``), sorted."""
    from importlib import resources

    return tuple(sorted(p.name[:-5] for p in resources.files("drake_entry").joinpath(folder).iterdir()
                        if p.name.endswith(".yaml")))


def load_packaged_or_file(schema, name_or_path, *, kind: str, folder: str, _chain: tuple = ()):
    """``schema`` read from a packaged file by name (drake_entry/<folder>/<name>.yaml) or from a
    YAML file path (``load_yaml_typed``); anything else is one ScenarioError naming the packaged
    ones. ``kind`` names the file in messages ('scenario', 'comparison'). A schema with a
    ``based_on`` field starts from the file it names (read the same way) when one is given."""
    from importlib import resources

    packaged = packaged_names(folder)
    chain = _chain + (os.fspath(name_or_path),) if isinstance(name_or_path, (str, os.PathLike)) else _chain

    def base_of(base: str, path: str | None):
        """The schema a ``based_on: base`` starts from (a packaged name, or a path relative to ``path``)."""
        if base not in packaged and path is not None and not os.path.isabs(base):
            base = os.path.join(os.path.dirname(os.path.abspath(path)), base)
        if base in chain or len(chain) > 8:
            raise ScenarioError(f"{kind} '{chain[0]}': based_on makes a loop ({' -> '.join(chain)} -> {base})")
        return load_packaged_or_file(schema, base, kind=kind, folder=folder, _chain=chain)

    if not isinstance(name_or_path, (str, os.PathLike)):
        raise ScenarioError(f"a {kind} is a packaged name ({', '.join(packaged)}) or a YAML file path; got "
                            f"{type(name_or_path).__name__}")
    name_or_path = os.fspath(name_or_path)
    if name_or_path in packaged:
        text = resources.files("drake_entry").joinpath(f"{folder}/{name_or_path}.yaml").read_text()
        return load_yaml_typed(schema, text=text, where=f"{kind} '{name_or_path}'", base_of=base_of)
    if os.path.isdir(name_or_path):
        raise ScenarioError(f"{kind} '{name_or_path}' is a directory, not a YAML file")
    if os.path.exists(name_or_path):
        return load_yaml_typed(schema, path=name_or_path, base_of=base_of)
    raise ScenarioError(f"{kind} '{name_or_path}' is neither a packaged {kind} ({', '.join(packaged)}) nor a file "
                        f"(a relative path written in a YAML file is read beside that file, then here)")


def load_yaml_typed(schema, *, path: str | None = None, text: str | None = None, where: str | None = None,
                    base_of=None):
    """Read ``schema`` from a YAML file (``path``) or ``text``: checked field by field
    (``check``), then built by Drake's ``yaml_load_typed``; every problem is one
    ScenarioError naming the file (``where``) and the field path. ``base_of(name, path)``, when
    given, loads the schema a ``based_on: name`` field starts from (the file's fields then
    replace the base's, blocks merged field by field)."""
    where = where or path or "YAML"
    if path is not None:
        if not isinstance(path, (str, os.PathLike)):
            raise ScenarioError(f"{where}: a file path must be text, got {type(path).__name__}")
        if not os.path.exists(path):
            raise ScenarioError(f"file not found: {path}")
        if os.path.isdir(path):
            raise ScenarioError(f"{path} is a directory, not a YAML file")
        try:
            with open(path, encoding="utf-8") as f:
                text = f.read()
        except UnicodeDecodeError:
            raise ScenarioError(f"{path} is not a text (UTF-8) YAML file") from None
        except OSError as e:
            raise ScenarioError(f"{path}: cannot be read ({e.strerror or e})") from None
    if text is not None and not isinstance(text, str):
        raise ScenarioError(f"{where}: text must be YAML text (a str), got {type(text).__name__}; to build a "
                            f"{schema.__name__} from Python values, construct it and call its validate()")
    empty = f"{where}: the file is empty (no fields, only comments or blanks); a {schema.__name__} needs its fields"
    if not text or not text.strip():
        raise ScenarioError(empty)
    data = parse(text, where)
    if data is None:
        raise ScenarioError(empty)
    try:
        check(schema, data, "")
    except ScenarioError as e:
        raise ScenarioError(f"{where}: {e}") from None
    base = data.get("based_on") if isinstance(data, dict) and base_of is not None else None
    if base:
        try:
            defaults = base_of(base, path)
        except ScenarioError as e:
            raise ScenarioError(f"{where}: based_on '{base}': {e}") from None
        hints = _hints(schema)
        for name, value in data.items():  # an untagged block of a tagged field would replace the base's
            variants = _union_args(hints.get(name))
            if isinstance(value, dict) and variants and all(dc.is_dataclass(v) for v in variants):
                raise ScenarioError(f"{where}: {name}: write the tag of the block it changes (the base '{base}' "
                                    f"has !{_tag_name(type(getattr(defaults, name)))}); an untagged block "
                                    f"starts from the default")
        loaded = _drake_load(schema, text, where, defaults=defaults)
    else:
        loaded = _drake_load(schema, text, where)
    try:
        check_numbers(loaded)
    except ScenarioError as e:
        raise ScenarioError(f"{where}: {e}") from None
    if path is not None:
        resolve_file_fields(loaded, os.path.dirname(os.path.abspath(path)))
    if callable(getattr(loaded, "loaded_from", None)):
        loaded.loaded_from(data)  # what the file stated (e.g. a scenario's guidance block)
    return loaded


def resolve_file_fields(root, folder: str) -> None:
    """Read the relative file names of a loaded tree beside the file that names them: in every
    block of ``root`` (a dataclass tree, its lists and dicts included), each field its class lists
    in ``FILE_FIELDS`` that names a file relative to ``folder`` becomes that file's absolute path.
    Other values (packaged names, absolute paths, files not there) are left for the field's own
    loader, which then tries the packaged names and the working directory."""
    if dc.is_dataclass(root) and not isinstance(root, type):
        for name in getattr(type(root), "FILE_FIELDS", ()):
            value = getattr(root, name)
            if isinstance(value, str) and value and not os.path.isabs(value):
                beside = os.path.join(folder, value)
                if os.path.exists(beside):  # a file, or a directory its loader then refuses by name
                    setattr(root, name, os.path.abspath(beside))
        children = [getattr(root, f.name) for f in dc.fields(root)]
    elif isinstance(root, dict):
        children = list(root.values())
    elif isinstance(root, (list, tuple)):
        children = list(root)
    else:
        return
    for child in children:
        if dc.is_dataclass(child) or isinstance(child, (dict, list, tuple)):
            resolve_file_fields(child, folder)


def _as_yaml_text(value) -> str:
    """An override's value as YAML text: a string is taken as YAML text (as typed after
    ``--set FIELD=``); anything else is written as YAML."""
    if isinstance(value, str):
        return value
    if hasattr(value, "item") and callable(value.item) and getattr(value, "ndim", 1) == 0:
        value = value.item()  # numpy scalars
    try:
        dumped = yaml.safe_dump(value, default_flow_style=True, width=10 ** 6)
    except yaml.YAMLError:
        raise ScenarioError(f"a value of type {type(value).__name__} cannot be written as YAML") from None
    return dumped.removesuffix("\n...\n").strip()


def override(root, dotted: str, value, where: str = "override") -> None:
    """Set the field at the dotted path ``dotted`` of ``root`` (a loaded dataclass tree) to
    ``value`` (YAML text, or a plain Python value), through the same checks and loader as a
    file (the blocks on the path are mutable dataclasses, as the scenario schema's are)."""
    if not isinstance(dotted, str) or not re.fullmatch(r"[A-Za-z_]\w*(\.[A-Za-z_]\w*)*", dotted):
        raise ScenarioError(f"{where} {dotted!r}: a field path is names joined by dots, e.g. guidance.period_s")
    parts = dotted.split(".")
    chain = [root]
    for i, name in enumerate(parts):
        obj, here = chain[-1], ".".join(parts[:i])
        if not dc.is_dataclass(obj):
            raise ScenarioError(f"{where} {dotted}: {here} is a value ({_describe(obj)}), not a block of fields")
        names = [f.name for f in dc.fields(obj)]
        if name not in names:
            inside = f" in {here}" if here else ""
            raise ScenarioError(f"{where} {dotted}: unknown field '{name}'{inside}; {_closest(name, names)}")
        if i < len(parts) - 1:
            chain.append(getattr(obj, name))
    parent, last = chain[-1], parts[-1]
    text = _as_yaml_text(value)
    data = parse(text, f"{where} {dotted}")
    hint = _hints(type(parent)).get(last, Any)
    try:
        check(hint, data, dotted)
    except ScenarioError as e:
        raise ScenarioError(f"{where} {e}") from None
    document = f"{last}:\n{textwrap.indent(text, '  ')}" if "\n" in text else f"{last}: {text}"
    loaded = _drake_load(type(parent), document, f"{where} {dotted}", defaults=parent)
    field_default = dict(_fields(parent)).get(last)
    try:
        check_numbers(getattr(loaded, last), dotted, field_default)
    except ScenarioError as e:
        raise ScenarioError(f"{where} {e}") from None
    setattr(parent, last, getattr(loaded, last))
