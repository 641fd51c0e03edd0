"""What the vectorised transcriptions (LGL, Hermite-Simpson) share: decision variables
z = [X (N x nx), U (N x nu), t_f] (scaled); the collocation and path rows held by one
constraint per part of the nodes (a part: contiguous nodes, e.g. one LGL segment; Drake
packs a Python constraint's Jacobian as AutoDiff over every variable it is bound to, so
parts over their own nodes cost far less than one over all), each with its Jacobian
assembled from the node Jacobians of a _NodeEvaluator and its sparsity pattern declared;
and a running cost by a quadrature over each part with its exact gradient. A subclass gives
the node times, its parts, their rows and Jacobians (``_collocation``, ``_collocation_sparsity``)
and quadrature weights (``_quadrature_weights``)."""
from __future__ import annotations

import dataclasses as dc
import functools

import numpy as np
from pydrake.autodiffutils import ExtractGradient, ExtractValue, InitializeAutoDiff
from pydrake.solvers import MathematicalProgram

from drake_entry.planning.nlp.evaluator import _chain, _NodeEvaluator
from drake_entry.planning.nlp.transcription import _Transcription

__all__ = []


@dc.dataclass(frozen=True)
class _Part:
    """Nodes [start, stop) of one constraint and one running-cost term: ``n_rows``
    collocation rows, then the path rows of the part's first ``path_nodes`` nodes (a node
    two parts share holds its path rows in one of them)."""

    start: int
    stop: int
    n_rows: int
    path_nodes: int
    index: int = 0

    @property
    def size(self) -> int:
        return self.stop - self.start


class _NodeProgram(_Transcription):
    """Node variables; per part, one constraint of its collocation rows (= 0) followed by its
    path rows (path-major: row n_rows + c path_nodes + k) over the part's own variables
    [X[start:stop], U[start:stop], t_f]; bounds, terminal and Mayer terms."""

    description = "collocation and path"

    def __init__(self, problem, nodes, scaling, parts: list):
        super().__init__(problem, nodes, scaling)
        prog = self.prog = MathematicalProgram()
        nx, nu = self.nx, self.nu
        self.X = prog.NewContinuousVariables(nodes, nx, "x")
        self.U = prog.NewContinuousVariables(nodes, nu, "u")
        self.tf = None if self.fixed_tf else prog.NewContinuousVariables(1, "tf")[0]
        if self.tf is not None:
            prog.AddBoundingBoxConstraint(self.t_lo / self.ts, self.t_hi / self.ts, self.tf)
        self.nodes_eval = _NodeEvaluator(self)
        self.n_path = len(problem.path)
        self.parts = list(parts)
        self.nodes_eval.capacity = max(self.nodes_eval.capacity, len(self.parts) + 1)
        self.n_rows = sum(p.n_rows for p in self.parts)
        self.z = self.part_variables(_Part(0, nodes, self.n_rows, nodes))
        path_lo, path_hi = self.scaled_bounds(problem.path)
        self.collocation = []
        for p in self.parts:
            lo = np.concatenate([np.zeros(p.n_rows), np.repeat(path_lo, p.path_nodes)])
            hi = np.concatenate([np.zeros(p.n_rows), np.repeat(path_hi, p.path_nodes)])
            where = f" (part {p.index + 1} of {len(self.parts)}: nodes {p.start}-{p.stop - 1})" if len(self.parts) > 1 \
                else ""
            binding = prog.AddConstraint(self.timer.wrap(functools.partial(self._constraint, p), bounds=(lo, hi),
                                                         evaluation=p.index == 0),
                                         lo, hi, self.part_variables(p), description=self.description + where)
            binding.evaluator().SetGradientSparsityPattern(self._sparsity(p))
            self.collocation.append(binding)
            if problem.has_lagrange:
                prog.AddCost(self.timer.wrap(functools.partial(self._lagrange_cost, p), cost=True),
                             self.part_variables(p))
        self.add_bounds(prog, self.X, self.U, self.X[0], self.X[-1])
        self.add_terminal(prog, self.X[-1], self.U[-1])
        self.mayer_cost(prog, self.X[-1], None if self.tf is None else [self.tf])

    #: what a collocation row's index // nx counts from the part's first node (LGL: its node)
    row_unit = "node"

    def row_words(self, binding, row: int) -> str:
        """': the <state> collocation row at node k' or ': path <quantity> at node k' for a row
        of a part's constraint (node indices of the whole mesh)."""
        name = binding.evaluator().get_description()  # each part's constraint names its nodes
        part = next((p for p, b in zip(self.parts, self.collocation) if b.evaluator().get_description() == name), None)
        if part is None:
            return ""
        if row < part.n_rows:
            node, i = divmod(row, self.nx)
            return f": the {self.problem.state_names[i]} collocation row at {self.row_unit} {part.start + node}"
        c, k = divmod(row - part.n_rows, part.path_nodes)
        return f": path {self.problem.path[c].label} at node {part.start + k}"

    # -- layout (local to a part: z_p = [X[start:stop], U[start:stop], t_f]) ----------------
    def part_variables(self, part: _Part) -> np.ndarray:
        """The decision variables a part's constraint and cost are bound to, in z_p order."""
        s = slice(part.start, part.stop)
        return np.concatenate([self.X[s].ravel(), self.U[s].ravel()] + ([[self.tf]] if self.tf is not None else []))

    def _split(self, zv, n: int):
        nx, nu = self.nx, self.nu
        Xs = zv[:n * nx].reshape(n, nx)
        Us = zv[n * nx:n * (nx + nu)].reshape(n, nu)
        tf = zv[-1] if self.tf is not None else self.t_lo / self.ts
        return Xs, Us, tf

    def _x_col(self, k, i):
        return k * self.nx + i

    def _node_cols(self, k, n: int) -> list:
        """Local columns of node k of a part of n nodes."""
        return [self._x_col(k, m) for m in range(self.nx)] + [n * self.nx + k * self.nu + j for j in range(self.nu)]

    def _tf_cols(self, n: int) -> list:
        return [n * (self.nx + self.nu)] if self.tf is not None else []

    def _sparsity(self, part: _Part) -> list:
        pairs = self._collocation_sparsity(part)
        for c in range(self.n_path):
            for k in range(part.path_nodes):
                pairs += [(part.n_rows + c * part.path_nodes + k, col) for col in self._node_cols(k, part.size)]
        return pairs

    # -- what a subclass gives ------------------------------------------------------------
    def _collocation_sparsity(self, part: _Part) -> list:  # pragma: no cover - interface
        """(row, local column) pairs of the part's collocation rows."""
        raise NotImplementedError

    def _collocation(self, part: _Part, Xs, Us, tf, J) -> np.ndarray:  # pragma: no cover - interface
        """The part's collocation row values; their Jacobian written into J's first rows."""
        raise NotImplementedError

    def _quadrature_weights(self, part: _Part) -> np.ndarray:  # pragma: no cover - interface
        """w with the part's running cost = t_f (w @ L) (scaled time)."""
        raise NotImplementedError

    # -- rows, cost and the callbacks the solver sees -------------------------------------
    def _values_jacobian(self, part: _Part, zv):
        """The part's rows at its local variables ``zv`` and their dense Jacobian."""
        n, nx, nu = part.size, self.nx, self.nu
        Xs, Us, tf = self._split(zv, n)
        J = np.zeros((part.n_rows + self.n_path * part.path_nodes, zv.size))
        rows = self._collocation(part, Xs, Us, tf, J)
        _, g, _, _, dg, _ = self.nodes_eval.evaluate(Xs, Us)
        k = np.arange(part.path_nodes)
        for c in range(self.n_path):
            r = part.n_rows + c * part.path_nodes + k
            J[r[:, None], (k * nx)[:, None] + np.arange(nx)] = dg[k, c, :nx]
            J[r[:, None], (n * nx + k * nu)[:, None] + np.arange(nu)] = dg[k, c, nx:]
        return np.concatenate([rows, g[:part.path_nodes].T.ravel()]), J

    def _lagrange_value_gradient(self, part: _Part, zv):
        n, nx, nu = part.size, self.nx, self.nu
        Xs, Us, tf = self._split(zv, n)
        *_, L, _, _, dL = self.nodes_eval.evaluate(Xs, Us)
        w = self._quadrature_weights(part)
        c = self.cost_factor
        value = c * tf * float(w @ L)
        grad = np.zeros(zv.size)
        grad[:n * nx] = (c * tf * w[:, None] * dL[:, :nx]).ravel()
        grad[n * nx:n * (nx + nu)] = (c * tf * w[:, None] * dL[:, nx:]).ravel()
        if self.tf is not None:
            grad[-1] = c * float(w @ L)
        return value, grad

    def _constraint(self, part, z):
        if z.dtype != object:
            return self._values_jacobian(part, np.asarray(z, float))[0]
        zv = ExtractValue(z).ravel()
        values, J = self._values_jacobian(part, zv)
        return InitializeAutoDiff(values, _chain(J, ExtractGradient(z))).ravel()

    def _lagrange_cost(self, part, z):
        if z.dtype != object:
            return self._lagrange_value_gradient(part, np.asarray(z, float))[0]
        value, grad = self._lagrange_value_gradient(part, ExtractValue(z).ravel())
        return InitializeAutoDiff(np.array([value]), _chain(grad[None, :], ExtractGradient(z)))[0, 0]

    # -- guess and solution ---------------------------------------------------------------
    def node_times(self, tf: float) -> np.ndarray:  # pragma: no cover - interface
        """The node times [s] for final time tf [s]."""
        raise NotImplementedError

    def set_guess(self, t, X, U):
        t = np.asarray(t, float)
        tf = float(np.clip(t[-1], self.t_lo, self.t_hi))
        tk = self.node_times(t[-1])
        Xk = np.column_stack([np.interp(tk, t, np.asarray(X)[:, i]) for i in range(self.nx)]) / self.sx
        Uk = np.column_stack([np.interp(tk, t, np.asarray(U)[:, j]) for j in range(self.nu)]) / self.su
        guess = np.zeros(self.prog.num_vars())
        self.initial_guess = guess
        self.prog.SetDecisionVariableValueInVector(self.X, Xk, guess)
        self.prog.SetDecisionVariableValueInVector(self.U, Uk, guess)
        if self.tf is not None:
            self.prog.SetDecisionVariableValueInVector(self.tf, tf / self.ts, guess)

    def solution(self, res):
        """(node times [s], states [SI], controls [SI], the collocation rows' multipliers in part
        order, or None)."""
        Xs = np.reshape(res.GetSolution(self.X), (self.N, self.nx))
        Us = np.reshape(res.GetSolution(self.U), (self.N, self.nu))
        tf = self.t_lo if self.tf is None else float(res.GetSolution(self.tf)) * self.ts
        try:
            nu = np.concatenate([np.asarray(res.GetDualSolution(b))[:p.n_rows]
                                 for b, p in zip(self.collocation, self.parts)])
        except Exception:  # noqa: BLE001 - a solver without duals
            nu = None
        return self.node_times(tf), Xs * self.sx, Us * self.su, nu
