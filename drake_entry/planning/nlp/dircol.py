"""Drake DirectCollocation (Hermite-Simpson) transcription of the problem as a Drake System
(planning.ocp_system)."""
from __future__ import annotations

import numpy as np

from drake_entry.planning.nlp.result import NlpResult
from drake_entry.planning.nlp.transcription import _Transcription

__all__ = ["DIRCOL_COSTATE_FACTOR"]

DIRCOL_COSTATE_FACTOR = 1.5


class _DircolTranscription(_Transcription):
    """Drake DirectCollocation (Hermite-Simpson) of the scaled plant."""

    def __init__(self, problem, nodes, scaling, guess_final_time):
        super().__init__(problem, nodes, scaling)
        from pydrake.planning import DirectCollocation

        from drake_entry.planning.ocp_system import OptimalControlPlant

        self.plant = OptimalControlPlant(problem, self.sx, self.su, self.ts, undefined_as_nan=True,
                                         timer=self.timer)
        # equal steps, loosely bounded (t_f's own bounds are the duration bounds): Drake needs
        # finite step bounds, so an open end becomes 1e-6 / 1e6 x the guess's final time (no
        # cap a solve can reach); a fixed t_f keeps a step range (Ipopt fails on lb = ub here)
        lo = 0.5 * self.t_lo if self.t_lo > 0 else 1e-6 * guess_final_time
        hi = 2.0 * self.t_hi if np.isfinite(self.t_hi) else 1e6 * guess_final_time
        self.dc = DirectCollocation(self.plant, self.plant.CreateDefaultContext(), nodes,
                                    lo / self.ts / (nodes - 1), hi / self.ts / (nodes - 1))
        self.dc.AddEqualTimeIntervalsConstraints()
        self.dc.AddDurationBounds(self.t_lo / self.ts, self.t_hi / self.ts)
        prog = self.prog = self.dc.prog()
        N, nx, nu = nodes, self.nx, self.nu
        self.X = np.array([self.dc.state(k) for k in range(N)])
        self.U = np.array([self.dc.input(k) for k in range(N)])
        self.H = np.array([self.dc.time_step(k)[0] for k in range(N - 1)])
        self.add_bounds(prog, self.X, self.U, self.dc.initial_state(), self.dc.final_state())
        self.add_path(prog, self.X, self.U)
        self.add_terminal(prog, self.X[-1], self.U[-1])
        if problem.has_lagrange:  # trapezoid rule over the samples
            for k in range(N - 1):
                prog.AddCost(self.timer.wrap(lambda z: 0.5 * self.cost_factor * z[-1] * (
                    self.L_scaled(z[:nx], z[nx:nx + nu]) + self.L_scaled(z[nx + nu:2 * nx + nu], z[2 * nx + nu:-1])),
                    cost=True),
                             np.concatenate([self.X[k], self.U[k], self.X[k + 1], self.U[k + 1], [self.H[k]]]))
        self.collocation = [b for b in prog.GetAllConstraints()
                            if b.evaluator().get_description().startswith("collocation constraint")]
        self.mayer_cost(prog, self.X[-1], None if self.fixed_tf else self.H)

    def set_guess(self, t, X, U):
        from pydrake.trajectories import PiecewisePolynomial

        t = np.asarray(t, float) / self.ts
        Xs = (np.asarray(X) / self.sx).T
        Us = (np.asarray(U) / self.su).T
        self.dc.SetInitialTrajectory(PiecewisePolynomial.FirstOrderHold(t, Us),
                                     PiecewisePolynomial.FirstOrderHold(t, Xs))
        self.initial_guess = self.prog.GetInitialGuess(self.prog.decision_variables())

    def result(self, res) -> NlpResult:
        t = self.dc.GetSampleTimes(res) * self.ts
        X = np.reshape(self.dc.GetStateSamples(res), (self.nx, self.N)).T * self.sx
        U = np.reshape(self.dc.GetInputSamples(res), (self.nu, self.N)).T * self.su
        costates, t_mid = None, 0.5 * (t[:-1] + t[1:])
        try:  # collocation multipliers at the segment midpoints
            h = np.diff(t) / self.ts
            nu = np.vstack([res.GetDualSolution(b) for b in self.collocation])
            costates = self.costates_from(DIRCOL_COSTATE_FACTOR * nu / h[:, None])
        except Exception:  # noqa: BLE001
            costates = None
        return self.make_result(res, t, X, U, costates, t_mid if costates is not None else None, "dircol")
