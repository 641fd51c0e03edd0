"""The dynamics of an optimal-control problem as a Drake system: OptimalControlPlant (Python,
for Drake's DirectCollocation, which needs a System converting to AutoDiffXd, and the
reference) and ``native_ocp_plant`` (the same dynamics as a SymbolicVectorSystem evaluated in
C++, for propagating NLP controls with the Simulator: the verification).

The plant runs in scaled units: state x_s = x / state_scale, input u_s = u / control_scale
and time t_s = t / time_scale, so dx_s/dt_s = time_scale / state_scale * f(x, u). With all
scales 1 it is the physical plant.

Ports:
  - input  "u"  [n_controls]  scaled controls (the problem's control order)
  - output "x"  [n_states]    scaled state (the problem's state order)
"""
from __future__ import annotations

import numpy as np
from pydrake.symbolic import Expression, Variable
from pydrake.systems.framework import BasicVector_, ContinuousStateIndex, LeafSystem_
from pydrake.systems.primitives import SymbolicVectorSystem
from pydrake.systems.scalar_conversion import TemplateSystem

from drake_entry.errors import DrakeEntryError, UnsupportedScalarError
from drake_entry.models.symbolic_system import expression

__all__ = ["OptimalControlPlant_", "OptimalControlPlant", "native_ocp_plant"]


@TemplateSystem.define("OptimalControlPlant_")
def OptimalControlPlant_(T):
    class Impl(LeafSystem_[T]):
        def _construct(self, problem, state_scale=None, control_scale=None, time_scale: float = 1.0,
                       undefined_as_nan: bool = False, timer=None, converter=None):
            """Args: problem with n_states, n_controls and dynamics(x, u) (SI); scales (SI per
            scaled unit; default 1); undefined_as_nan: where a model is undefined (a
            DrakeEntryError, e.g. an altitude below the atmosphere's range) the derivatives
            are NaN instead of the error, which a solver's line search backs off from (an NLP
            may probe such points, e.g. a Hermite-Simpson midpoint); the Simulator's users
            keep the error."""
            LeafSystem_[T].__init__(self, converter)
            self.problem = problem
            self.undefined_as_nan = undefined_as_nan
            self.timer = timer
            self._derivatives = self._time_derivatives if timer is None else timer.wrap(self._time_derivatives)
            nx, nu = problem.n_states, problem.n_controls
            self.sx = np.ones(nx) if state_scale is None else np.asarray(state_scale, float)
            self.su = np.ones(nu) if control_scale is None else np.asarray(control_scale, float)
            self.ts = float(time_scale)
            self.DeclareContinuousState(BasicVector_[T](np.zeros(nx)))
            self.u_port = self.DeclareVectorInputPort("u", nu)
            self.DeclareStateOutputPort("x", ContinuousStateIndex(0))

        def _construct_copy(self, other, converter=None):
            Impl._construct(self, other.problem, other.sx, other.su, other.ts, other.undefined_as_nan, other.timer,
                            converter=converter)

        def DoCalcTimeDerivatives(self, context, derivatives):
            self._derivatives(context, derivatives)

        def _time_derivatives(self, context, derivatives):
            xs = context.get_continuous_state_vector().CopyToVector()
            us = self.u_port.Eval(context)
            try:
                f = np.asarray(self.problem.dynamics(xs * self.sx, us * self.su)) * (self.ts / self.sx)
            except DrakeEntryError:
                if not self.undefined_as_nan:
                    raise
                f = np.array([T(np.nan) for _ in range(len(xs))]) if T != float else np.full(len(xs), np.nan)
            derivatives.get_mutable_vector().SetFromVector(f)

    return Impl


OptimalControlPlant = OptimalControlPlant_[None]


def native_ocp_plant(problem) -> SymbolicVectorSystem | None:
    """``problem.dynamics`` (SI) built once with symbolic scalars into a SymbolicVectorSystem:
    input port 0 the controls u [n_controls], state and output port 0 the state x [n_states],
    every derivative evaluated in C++ (no Python call per integrator stage). None when a model
    of the problem has no symbolic form (an aerodynamic table, a user function written
    with ``math``): the caller then propagates with OptimalControlPlant.

    Unlike OptimalControlPlant it checks no model range (the symbolic atmosphere extends its end
    pieces, drake_entry.models.atmosphere.Atmosphere.symbolic_profile): a caller that needs the
    check tests the flown states against the ranges (diagrams.verification does)."""
    x = [Variable(name) for name in problem.state_names]
    u = [Variable(f"u{j}") for j in range(problem.n_controls)]
    try:
        with np.errstate(all="ignore"):  # numpy's object loops report stray FP flags as warnings
            f = problem.dynamics(np.array([Expression(v) for v in x]), np.array([Expression(v) for v in u]))
    except (UnsupportedScalarError, TypeError):
        return None
    return SymbolicVectorSystem(state=x, input=u, dynamics=[expression(v) for v in np.ravel(f)], output=x)
