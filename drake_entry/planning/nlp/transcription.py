"""What both transcriptions share: scaling, bounds, boundary and path constraints, the
Mayer cost, the violation diagnosis, and assembling the NlpResult."""
from __future__ import annotations

import numpy as np

from drake_entry.planning.nlp.evaluator import CallbackTimer, model_values
from drake_entry.planning.nlp.result import NlpResult
from drake_entry.planning.nlp.scaling import objective_factor

__all__ = ["COSTATE_SIGN"]

COSTATE_SIGN = 1.0  # Drake's multiplier sign convention, checked on analytic problems (tests)


class _Transcription:
    """Scaling, bounds, boundary conditions, path constraints shared by both transcriptions."""

    def __init__(self, problem, nodes: int, scaling):
        self.problem = problem
        self.N = nodes
        self.scaling = scaling
        self.sx, self.su, self.ts = scaling.states, scaling.controls, scaling.time
        self.cost_factor = 1.0  # the solver minimises cost_factor * J / ts (set by scale_objective)
        self.nx, self.nu = problem.n_states, problem.n_controls
        self.t_lo, self.t_hi = problem.final_time_bounds
        self.fixed_tf = self.t_lo == self.t_hi
        self.timer = CallbackTimer()  # every Python callback handed to the solver goes through it

    def release(self) -> None:
        """Drop the program: its constraints hold Python callbacks bound to this transcription,
        a cycle through C++ that Python's collector cannot see, so a solved program and its
        transcription were never freed (about 0.25 MB per 30-node brachistochrone solve; an 81-node
        entry solve far more: docs/performance.md, "Memory")."""
        for name in ("prog", "dc", "plant", "collocation"):
            if hasattr(self, name):
                setattr(self, name, None)

    def scale_objective(self):
        """Choose the objective factor at the guess (scaling.objective_factor) unless the user
        gave one; record it as cost units per solver unit."""
        if self.scaling.objective is not None:
            self.cost_factor = self.ts / self.scaling.objective
            return
        factor, how = objective_factor(self.prog, self.initial_guess)
        self.cost_factor = factor
        self.scaling.objective = self.ts / factor
        self.scaling.source["objective"] = how

    def objective_value(self, res) -> float:
        """J [cost units] from the solver's optimal cost."""
        return float(res.get_optimal_cost()) * self.ts / self.cost_factor

    def costates_from(self, nu_scaled):
        """d J / d x [SI] from multipliers of scaled defect rows already divided by the
        quadrature weight (eq. 15)."""
        return COSTATE_SIGN * nu_scaled * self.ts / (self.sx * self.cost_factor)

    # scaled <-> SI
    def L_scaled(self, xs, us):
        """Lagrangian at scaled (x, u): integrated over scaled time it gives J / time_scale."""
        return self.problem.lagrangian(xs * self.sx, us * self.su)

    def _scaled_rows(self, values, constraints, xs, us):
        """``values(x, u)`` (path_values or terminal_values) at scaled (x, u), each row divided
        by its constraint's scale."""
        return np.array([v / c.scale for v, c in zip(values(xs * self.sx, us * self.su), constraints)])

    @staticmethod
    def scaled_bounds(constraints) -> tuple[np.ndarray, np.ndarray]:
        """(min, max) of ``constraints`` divided by their scales."""
        return np.array([c.min / c.scale for c in constraints]), np.array([c.max / c.scale for c in constraints])

    def add_bounds(self, prog, X, U, x_first, x_last):
        xl, xh, ul, uh = self.problem.bounds_arrays()
        for k in range(X.shape[0]):
            prog.AddBoundingBoxConstraint(xl / self.sx, xh / self.sx, X[k])
        for k in range(U.shape[0]):
            prog.AddBoundingBoxConstraint(ul / self.su, uh / self.su, U[k])
        for which, var in (("initial", x_first), ("final", x_last)):
            lo, hi = self.problem.boundary_bounds(which)
            prog.AddBoundingBoxConstraint(lo / self.sx, hi / self.sx, var)

    def add_path(self, prog, X, U):
        path = self.problem.path
        if not path:
            return
        lo, hi = self.scaled_bounds(path)
        nx = self.nx
        for k in range(X.shape[0]):
            prog.AddConstraint(self.timer.wrap(lambda z: self._scaled_rows(self.problem.path_values, path, z[:nx],
                                                                           z[nx:])), lo, hi,
                               np.concatenate([X[k], U[k]]), description=f"path[{k}]")

    def add_terminal(self, prog, x_last, u_last):
        """The problem's terminal constraints on the final node, each row scaled as a path row."""
        terminal = self.problem.terminal
        if not terminal:
            return
        nx = self.nx
        prog.AddConstraint(self.timer.wrap(lambda z: self._scaled_rows(self.problem.terminal_values, terminal,
                                                                       z[:nx], z[nx:])),
                           *self.scaled_bounds(terminal), np.concatenate([x_last, u_last]), description="terminal")

    def mayer_cost(self, prog, x_last, tf_vars):
        """Mayer cost M(x_f, t_f) / time_scale; t_f (scaled) is the sum of ``tf_vars`` (the
        LGL final time, or the DirectCollocation time steps), or fixed when None."""
        if not self.problem.has_mayer:
            return
        nx = self.nx
        if tf_vars is None:
            tf = self.t_lo
            prog.AddCost(self.timer.wrap(lambda z: self.problem.mayer(z * self.sx, tf) * (self.cost_factor / self.ts),
                                         cost=True), x_last)
        else:
            prog.AddCost(self.timer.wrap(lambda z: self.problem.mayer(z[:nx] * self.sx, z[nx:].sum() * self.ts)
                                         * (self.cost_factor / self.ts), cost=True),
                         np.concatenate([x_last, np.atleast_1d(tf_vars)]))

    def worst_violation(self, res) -> tuple[float, str]:
        """(largest scaled constraint violation, the constraint's description and, where the
        transcription names its rows, the row's: ``row_words``) at ``res``."""
        worst, where = 0.0, ""
        for b in self.prog.GetAllConstraints():
            v = res.EvalBinding(b)
            lo, hi = b.evaluator().lower_bound(), b.evaluator().upper_bound()
            viol = np.maximum(lo - v, 0.0) + np.maximum(v - hi, 0.0)
            viol = np.where(np.isfinite(viol), viol, 0.0)
            if viol.size and viol.max() > worst:
                worst, row = float(viol.max()), int(np.argmax(viol))
                where = (b.evaluator().get_description() or type(b.evaluator()).__name__) + self.row_words(b, row)
        return worst, where

    def row_words(self, binding, row: int) -> str:
        """What row ``row`` of ``binding`` is, as ': ...' (here: nothing; a transcription that
        knows its rows says)."""
        return ""

    def diagnose(self) -> str:
        """Name the worst violated constraint at the returned point (infeasible problems),
        as make_result measured it."""
        worst, where = self.worst
        return f"largest violation {worst:.3g} (scaled) in '{where}'" if worst > 0 else "no violated constraint"

    def make_result(self, res, t, X, U, costates, t_costate, transcription: str) -> NlpResult:
        """The solution as an NlpResult (SI, the Hamiltonian at the costate times); solve()
        adds the verdict, the verification and the timings."""
        problem = self.problem
        self.worst = self.worst_violation(res)
        ham = None
        if costates is not None:
            Xc = X if len(t_costate) == len(t) else 0.5 * (X[:-1] + X[1:])
            Uc = U if len(t_costate) == len(t) else 0.5 * (U[:-1] + U[1:])
            f, _, L, _ = model_values(problem, Xc.T, Uc.T)
            ham = L + np.sum(costates * f.T, axis=1)
        return NlpResult(time=t, states=X, controls=U, objective=self.objective_value(res), costates=costates,
                         costate_time=t_costate, hamiltonian=ham, transcription=transcription, nodes=self.N,
                         max_defect=self.worst[0], problem=problem, scaling=self.scaling)
