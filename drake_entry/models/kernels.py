"""Compiled kernels of the models' symbolic expressions: ``compile_kernels``.

The models (drake_entry.models) are written once for float, AutoDiffXd and symbolic Expression
scalars. Called with symbolic Variables they return Drake Expressions; this module writes those
Expressions out as straight-line Python (common sub-expressions shared, each ``if_then_else``
an ``if``/``else`` block so only the branch taken is computed: a US76 or Mach-table look-up costs
its log2(pieces) comparisons and one piece, as in the float model) and compiles the result with
numba. The equations therefore stay written once: a kernel is a second *form* of the model, not
a second copy of it, and the tests hold every kernel to the model it came from.

A generated module holds the kernels and, optionally, the source of "driver" functions (plain
Python written against the kernels' names, e.g. a whole predicted flight: an integrator loop,
no physics), so the driver and its kernels compile as one unit. The module is written to the
kernel cache directory under the SHA-256 of its text and compiled with ``cache=True``: the
machine code is kept on disk and a later process (a campaign worker) loads it instead of
compiling. ``DRAKE_ENTRY_KERNEL_CACHE`` sets the directory (default
``kernels`` in the user's cache, drake_entry.user_cache; where it cannot be
written, a directory of this user's under the system's temporary one).

Semantics are the float model's: ``min``/``max``, ``abs``, comparisons and logic as in Python;
numba's NumPy error model (a sqrt of a negative or a 0/0 gives NaN, not an exception), so a
caller checks its results for NaN where the Drake evaluation would have raised.
"""
from __future__ import annotations

import dataclasses as dc
import hashlib
import importlib.util
import inspect
import math
import os
import sys
import tempfile
import time
from pathlib import Path

from pydrake.symbolic import Expression, ExpressionKind, Formula, FormulaKind, Variable

from drake_entry.errors import UnsupportedScalarError
from drake_entry.user_cache import cache_root

__all__ = ["Kernel", "CompiledModule", "kernel_cache_dir", "kernel_source", "compile_kernels"]

#: kernels of the generated module: the name of a Python function and its operator or numba call
_UNARY = {ExpressionKind.Log: "math.log", ExpressionKind.Exp: "math.exp", ExpressionKind.Sqrt: "math.sqrt",
          ExpressionKind.Sin: "math.sin", ExpressionKind.Cos: "math.cos", ExpressionKind.Tan: "math.tan",
          ExpressionKind.Asin: "math.asin", ExpressionKind.Acos: "math.acos", ExpressionKind.Atan: "math.atan",
          ExpressionKind.Sinh: "math.sinh", ExpressionKind.Cosh: "math.cosh", ExpressionKind.Tanh: "math.tanh",
          ExpressionKind.Abs: "abs", ExpressionKind.Floor: "math.floor", ExpressionKind.Ceil: "math.ceil"}
_BINARY = {ExpressionKind.Atan2: "math.atan2", ExpressionKind.Min: "min", ExpressionKind.Max: "max"}
_COMPARE = {FormulaKind.Lt: "<", FormulaKind.Leq: "<=", FormulaKind.Gt: ">", FormulaKind.Geq: ">=",
            FormulaKind.Eq: "==", FormulaKind.Neq: "!="}


@dc.dataclass(frozen=True)
class Kernel:
    """One kernel: ``name(v, out)`` writes ``outputs`` (Expressions or floats) of ``variables``
    (v[i] is variables[i]) into ``out`` [len(outputs)]."""

    name: str
    outputs: tuple
    variables: tuple


def _literal(c: float) -> str:
    """A float as Python source (infinities and NaN as math's names)."""
    if math.isfinite(c):
        return repr(c)
    return "math.nan" if math.isnan(c) else ("math.inf" if c > 0 else "-math.inf")


class _Writer:
    """The statements of one kernel: a name per distinct sub-expression, scoped by branch (a value
    computed inside an ``if`` block is reused only inside it)."""

    def __init__(self, variables, prefix: str):
        self.prefix = prefix
        self.globals: list[str] = []  # module-level constant arrays (the tables)
        self.tables = 0
        self.lines: list[str] = []
        self.scopes: list[dict] = [{}]
        self.count = 0
        self.indent = 1
        for i, v in enumerate(variables):
            self._bind(Expression(v), f"v[{i}]")

    @staticmethod
    def _key(e: Expression) -> str:
        return e.to_string()

    def _lookup(self, e):
        key = self._key(e)
        for scope in reversed(self.scopes):
            if key in scope:
                return scope[key]
        return None

    def _known(self, e):
        """The name of ``e`` if it is computed already (a variable always is), else None."""
        found = self._lookup(e)
        if found is None and e.get_kind() == ExpressionKind.Var:
            raise UnsupportedScalarError(f"compiled kernel: variable {e} is not among the kernel's variables")
        return found

    def _bind(self, e, name):
        self.scopes[-1][self._key(e)] = name

    def _emit(self, text: str) -> str:
        name = f"t{self.count}"
        self.count += 1
        self.lines.append("    " * self.indent + f"{name} = {text}")
        return name

    def value(self, e) -> str:
        """The name (or literal) holding ``e``, emitting its statements if needed."""
        if isinstance(e, Variable):
            e = Expression(e)
        if not isinstance(e, Expression):
            return _literal(float(e))
        kind = e.get_kind()
        if kind == ExpressionKind.Constant:
            return _literal(float(e.Evaluate()))
        found = self._known(e)
        if found is not None:
            return found
        _, args = e.Unapply()
        if kind == ExpressionKind.IfThenElse:
            name = self._table(e) or self._branch(args)
        else:
            name = self._emit(self._operation(kind, args, e))
        self._bind(e, name)
        return name

    def _operation(self, kind, args, e) -> str:
        if kind == ExpressionKind.Add:  # constant + sum of terms
            terms = [self.value(a) for a in args[1:]]
            c = float(args[0])
            return " + ".join(([_literal(c)] if c != 0.0 else []) + terms)
        if kind == ExpressionKind.Mul:  # constant * product of factors
            factors = [self.value(a) for a in args[1:]]
            c = float(args[0])
            return " * ".join(([_literal(c)] if c != 1.0 else []) + factors)
        if kind == ExpressionKind.Div:
            return f"{self.value(args[0])} / {self.value(args[1])}"
        if kind == ExpressionKind.Pow:
            base, exponent = self.value(args[0]), args[1]
            if exponent.get_kind() == ExpressionKind.Constant and float(exponent.Evaluate()) == 2.0:
                return f"{base} * {base}"
            return f"{base} ** {self.value(exponent)}"
        if kind in _UNARY:
            return f"{_UNARY[kind]}({self.value(args[0])})"
        if kind in _BINARY:
            return f"{_BINARY[kind]}({self.value(args[0])}, {self.value(args[1])})"
        raise UnsupportedScalarError(f"compiled kernel: no compiled form of {kind.name} ({e.to_string()[:80]})")

    def _branch(self, args) -> str:
        condition = self.condition(args[0])
        name = f"t{self.count}"
        self.count += 1
        for keyword, branch in (("if", args[1]), ("else", args[2])):
            self.lines.append("    " * self.indent + (f"if {condition}:" if keyword == "if" else "else:"))
            self.indent += 1
            self.scopes.append({})
            self.lines.append("    " * self.indent + f"{name} = {self.value(branch)}")
            self.scopes.pop()
            self.indent -= 1
        return name

    def _table(self, e) -> str | None:
        """A piecewise table (``models.atmosphere.piecewise``: a tree of ``x < break`` whose
        leaves are one formula with different constants) as a binary search of module-level
        arrays: the compiled code grows with the formula, not with the number of pieces. None
        when ``e`` is not such a table (then it is written as the if/else tree)."""
        found = _piecewise_leaves(e)
        if found is None:
            return None
        x, breaks, leaves = found
        shapes, rows = [], []  # the distinct leaf shapes; per leaf (shape, constants)
        for leaf in leaves:
            sig = self._signature(leaf)
            if sig is None:
                return None
            if sig[0] not in shapes:
                shapes.append(sig[0])
            rows.append((shapes.index(sig[0]), sig[1]))
        if len(shapes) > TABLE_MAX_SHAPES:
            return None
        table = f"{self.prefix}_table{self.tables}"
        self.tables += 1
        self.globals.append(f"{table}_breaks = np.array([{', '.join(_literal(float(b)) for b in breaks)}])")
        index = self._emit(f"np.searchsorted({table}_breaks, {self.value(x)}, side='right')")
        name = f"t{self.count}"
        self.count += 1
        if len(shapes) > 1:
            self.globals.append(f"{table}_shape = np.array({[g for g, _ in rows]!r})")
            shape = self._emit(f"{table}_shape[{index}]")
        for g in range(len(shapes)):
            members = [i for i, (k, _) in enumerate(rows) if k == g]
            width = len(rows[members[0]][1])
            columns = [[rows[i][1][k] if rows[i][0] == g else 0.0 for k in range(width)] for i in range(len(rows))]
            varying = [len({rows[i][1][k] for i in members}) > 1 for k in range(width)]
            if any(varying):
                rows_text = ", ".join("[" + ", ".join(_literal(float(c)) for c in row) + "]" for row in columns)
                self.globals.append(f"{table}_constants{g} = np.array([{rows_text}])")
            constants = iter(range(width))

            def constant(g=g, constants=constants, varying=varying, first=rows[members[0]][1]) -> str:
                k = next(constants)
                return f"{table}_constants{g}[{index}, {k}]" if varying[k] else _literal(float(first[k]))

            text = self._template(leaves[members[0]], constant)
            if len(shapes) == 1:
                self.lines.append("    " * self.indent + f"{name} = {text}")
                continue
            keyword = "if" if g == 0 else ("elif" if g < len(shapes) - 1 else "else")
            test = f" {shape} == {g}" if keyword != "else" else ""
            self.lines.append("    " * self.indent + f"{keyword}{test}:")
            self.lines.append("    " * (self.indent + 1) + f"{name} = {text}")
        return name

    def _signature(self, e):
        """(shape, constants) of a table leaf: its tree with the constants taken out (in the order
        ``_template`` writes them) and values already computed left as their names; None if
        the leaf holds what a template does not write (a condition, a function call)."""
        constants = []

        def walk(e):
            if not isinstance(e, Expression):
                constants.append(float(e))
                return "c"
            kind = e.get_kind()
            if kind == ExpressionKind.Constant:
                constants.append(float(e.Evaluate()))
                return "c"
            found = self._known(e)
            if found is not None:
                return found
            _, args = e.Unapply()
            if kind in (ExpressionKind.Add, ExpressionKind.Mul):
                constants.append(float(args[0]))
                return (kind, tuple(walk(a) for a in args[1:]))
            if kind in _UNARY or kind in _BINARY or kind in (ExpressionKind.Div, ExpressionKind.Pow):
                return (kind, tuple(walk(a) for a in args))
            raise _NotTemplate

        try:
            return walk(e), constants
        except _NotTemplate:
            return None

    def _template(self, e, constant) -> str:
        """``e`` written as one expression, its constants from ``constant()`` (``_signature``'s
        order)."""
        if not isinstance(e, Expression) or e.get_kind() == ExpressionKind.Constant:
            return constant()
        found = self._lookup(e)
        if found is not None:
            return found
        kind = e.get_kind()
        _, args = e.Unapply()
        if kind == ExpressionKind.Add:
            c = constant()
            return "(" + " + ".join([c, *(self._template(a, constant) for a in args[1:])]) + ")"
        if kind == ExpressionKind.Mul:
            c = constant()
            return "(" + " * ".join([c, *(self._template(a, constant) for a in args[1:])]) + ")"
        parts = [self._template(a, constant) for a in args]
        if kind == ExpressionKind.Div:
            return f"({parts[0]} / {parts[1]})"
        if kind == ExpressionKind.Pow:
            return f"({parts[0]} ** {parts[1]})"
        return f"{(_UNARY | _BINARY)[kind]}({', '.join(parts)})"

    def condition(self, f: Formula) -> str:
        kind = f.get_kind()
        if kind in (FormulaKind.True_, FormulaKind.False_):
            return str(kind == FormulaKind.True_)
        _, args = f.Unapply()
        if kind in _COMPARE:
            return f"({self.value(args[0])} {_COMPARE[kind]} {self.value(args[1])})"
        if kind in (FormulaKind.And, FormulaKind.Or):
            return "(" + f" {kind.name.lower()} ".join(self.condition(a) for a in args) + ")"
        if kind == FormulaKind.Not:
            return f"(not {self.condition(args[0])})"
        raise UnsupportedScalarError(f"compiled kernel: no compiled form of the condition {f.to_string()[:80]}")


class _NotTemplate(Exception):
    """A table leaf with something a template does not write."""


#: the fewest pieces written as a table look-up rather than an if/else tree, and the most distinct
#: piece formulas a look-up dispatches on (a piece at a zero break, say, drops a term)
TABLE_MIN_PIECES, TABLE_MAX_SHAPES = 8, 4


def _piecewise_leaves(e):
    """(x, breaks, leaves) when ``e`` is a tree of ``if_then_else(x < break, ...)`` on one
    Expression x with constant breaks increasing left to right and at least TABLE_MIN_PIECES
    leaves (``models.atmosphere.piecewise``), else None."""
    key, breaks, leaves = [None, None], [], []

    def walk(node) -> bool:
        if not isinstance(node, Expression) or node.get_kind() != ExpressionKind.IfThenElse:
            leaves.append(node)
            return True
        _, (cond, left, right) = node.Unapply()
        if cond.get_kind() != FormulaKind.Lt:
            return False
        _, (x, b) = cond.Unapply()
        if b.get_kind() != ExpressionKind.Constant:
            return False
        text = x.to_string()
        if key[0] is None:
            key[:] = [text, x]
        elif key[0] != text:
            return False
        if not walk(left):
            return False
        breaks.append(float(b.Evaluate()))
        return walk(right)

    if not walk(e) or len(leaves) < TABLE_MIN_PIECES or any(b <= a for a, b in zip(breaks, breaks[1:])):
        return None
    return key[1], breaks, leaves


def _children(e):
    """The sub-expressions and conditions an Expression or Formula is made of."""
    if isinstance(e, Formula):
        kind = e.get_kind()
        return [] if kind in (FormulaKind.True_, FormulaKind.False_) else list(e.Unapply()[1])
    if e.get_kind() in (ExpressionKind.Var, ExpressionKind.Constant):
        return []
    return [a for a in e.Unapply()[1] if isinstance(a, (Expression, Formula))]


def _shared(outputs) -> list:
    """The Expressions used more than once in ``outputs`` (as the DAG they are), children before
    parents: computed once, outside every branch, so a value used in several branches (the lift
    in the bank law's limits, say) is not written again in each."""
    uses, order, seen = {}, [], set()
    stack = [(o, False) for o in reversed(outputs) if isinstance(o, Expression)]
    while stack:
        e, done = stack.pop()
        key = e.to_string()
        if done:
            order.append((key, e))
            continue
        uses[key] = uses.get(key, 0) + 1
        if key in seen:
            continue
        seen.add(key)
        stack.append((e, True))
        table = _piecewise_leaves(e) if e.get_kind() == ExpressionKind.IfThenElse else None
        # a table's pieces are its own (a look-up, _Writer._table): only its argument is shared
        stack.extend((c, False) for c in reversed([table[0]] if table else _children(e)))
    return [e for key, e in order if uses[key] > 1 and isinstance(e, Expression)
            and e.get_kind() not in (ExpressionKind.Var, ExpressionKind.Constant)]


def kernel_source(kernel: Kernel) -> str:
    """The Python source of ``kernel`` (module docstring): ``def name(v, out): ...``."""
    w = _Writer(kernel.variables, kernel.name)
    outputs = [Expression(o) if isinstance(o, Variable) else o for o in kernel.outputs]
    for e in _shared(outputs):
        w.value(e)
    results = [w.value(o) for o in outputs]
    body = w.lines + [f"    out[{i}] = {r}" for i, r in enumerate(results)]
    return "".join(g + "\n" for g in w.globals) + f"def {kernel.name}(v, out):\n" + "\n".join(body) + "\n"


def kernel_cache_dir() -> Path:
    """Where generated modules and their machine code are kept (module docstring)."""
    explicit = os.environ.get("DRAKE_ENTRY_KERNEL_CACHE")
    if explicit:
        return Path(explicit)
    return cache_root() / "kernels"


def _scratch_dir() -> Path:
    """The fallback when the cache directory cannot be written: this user's temporary one."""
    return Path(tempfile.gettempdir()) / f"drake_entry_kernels_{os.getuid()}"


@dc.dataclass
class CompiledModule:
    """A generated module: ``functions`` name -> numba dispatcher (kernels and drivers);
    ``path`` the module file; ``generate_s`` the seconds spent writing it; ``statements`` per
    kernel. Compilation is lazy (numba compiles, or loads from its cache, at the first call):
    ``warm(name, *args)`` calls a function once and returns the seconds it took."""

    functions: dict
    path: Path
    generate_s: float
    statements: dict

    def __getitem__(self, name):
        return self.functions[name]

    def warm(self, name: str, *args) -> float:
        t0 = time.perf_counter()
        self.functions[name](*args)
        return time.perf_counter() - t0


_LOADED: dict = {}  # module file -> CompiledModule, once per process


def compile_kernels(kernels: list, driver=None, *, tag: str = "kernels") -> CompiledModule:
    """Write ``kernels`` (Kernel) and the source of the module ``driver`` (plain Python whose
    functions call the kernels and each other by name) as one module, and compile every function
    in it with numba (``njit(cache=True)``, NumPy error model). ``tag`` starts the module's file
    name. The same text is written and compiled once per machine (the cache) and imported once
    per process."""
    t0 = time.perf_counter()
    parts = ["import math", "import numpy as np", ""]
    statements = {}
    for k in kernels:
        source = kernel_source(k)
        statements[k.name] = source.count("\n") - 1
        parts.append(source)
    names = [k.name for k in kernels]
    if driver is not None:
        parts.append(inspect.getsource(driver))
        names += [n for n, f in inspect.getmembers(driver, inspect.isfunction) if f.__module__ == driver.__name__]
    text = "\n\n".join(parts)
    digest = hashlib.sha256(text.encode()).hexdigest()[:20]
    name = f"{tag}_{digest}.py"
    for directory in (kernel_cache_dir(), _scratch_dir()):
        path = directory / name
        if path in _LOADED:
            return _LOADED[path]
        try:
            if not path.exists():
                directory.mkdir(parents=True, exist_ok=True)
                scratch = path.with_suffix(f".{os.getpid()}.tmp")
                scratch.write_text(text)
                os.replace(scratch, path)  # atomic: campaign workers may write the same module at once
            break
        except OSError:  # a read-only or full cache directory: compile in a temporary one
            continue
    else:
        raise OSError(f"compiled kernels: neither {kernel_cache_dir()} nor {_scratch_dir()} is writable; "
                      f"set DRAKE_ENTRY_KERNEL_CACHE to a writable directory")
    generate_s = time.perf_counter() - t0
    spec = importlib.util.spec_from_file_location(f"drake_entry_kernels_{digest}", path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # numba's cache locates a function through its module
    spec.loader.exec_module(module)
    import numba

    for name in names:  # jitted in the module's namespace, so the drivers call the jitted kernels
        setattr(module, name, numba.njit(cache=True, error_model="numpy")(getattr(module, name)))
    compiled = CompiledModule({n: getattr(module, n) for n in names}, path, generate_s, statements)
    _LOADED[path] = compiled
    return compiled
