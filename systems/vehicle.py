"""EntryVehicle: the 3-DOF point-mass entry plant as a Drake LeafSystem (float, AutoDiffXd,
symbolic Expression through Drake's scalar conversion).

Ports:
  - input  "bank"               [1]  bank angle sigma [rad]
  - input  "alpha"              [1]  angle of attack [rad]
  - input  "air_data"           [2]  (only with air_data_input=True) density [kg/m^3] and
                                   speed of sound [m/s] from an ``AtmosphereSystem``
  - input  "wind"               [2]  (only with air_data_input=True and wind_input=True) east and
                                   north wind [m/s] (the air-relative velocity sets the aerodynamics)
  - output "state"              [6]  [h m, lon rad, lat rad, V m/s, gamma rad, psi rad]
  - output "flight_conditions"  [9]  rho kg/m^3, Mach, q Pa, heat flux W/m^2, n_z g, n g,
                                   L m/s^2, D m/s^2, E J/kg (drake_entry.models.dynamics.FlightConditions)
"""
from __future__ import annotations

import numpy as np
from pydrake.systems.framework import BasicVector_, ContinuousStateIndex, LeafSystem_
from pydrake.systems.scalar_conversion import TemplateSystem

from drake_entry.models import dynamics
from drake_entry.models.atmosphere import Atmosphere
from drake_entry.models.planet import Earth
from drake_entry.models.vehicles import Vehicle
from drake_entry.systems.lifetime import weak_method

__all__ = ["N_STATE", "N_CONDITIONS", "EntryVehicle_", "EntryVehicle"]

N_STATE = 6
N_CONDITIONS = len(dynamics.FLIGHT_CONDITION_NAMES)


@TemplateSystem.define("EntryVehicle_")
def EntryVehicle_(T):
    class Impl(LeafSystem_[T]):
        def _construct(self, vehicle: Vehicle, planet: Earth, atmosphere: Atmosphere, *,
                       initial_state=None, air_data_input: bool = False, wind_input: bool = False,
                       converter=None):
            LeafSystem_[T].__init__(self, converter)
            self.vehicle = vehicle
            self.planet = planet
            self.atmosphere = atmosphere
            self.air_data_input = air_data_input
            self.wind_input = wind_input and air_data_input
            x0 = np.zeros(N_STATE) if initial_state is None else np.asarray(initial_state, float)
            self._x0 = x0
            self.DeclareContinuousState(BasicVector_[T](x0))
            self.bank_port = self.DeclareVectorInputPort("bank", 1)
            self.alpha_port = self.DeclareVectorInputPort("alpha", 1)
            self.air_port = self.DeclareVectorInputPort("air_data", 2) if air_data_input else None
            self.wind_port = self.DeclareVectorInputPort("wind", 2) if self.wind_input else None
            self.DeclareStateOutputPort("state", ContinuousStateIndex(0))  # native copy, no Python call
            deps = {self.all_state_ticket(), self.alpha_port.ticket()}
            for port in (self.air_port, self.wind_port):
                if port is not None:
                    deps.add(port.ticket())
            self.DeclareVectorOutputPort("flight_conditions", N_CONDITIONS, weak_method(self._calc_conditions),
                                         prerequisites_of_calc=deps)

        def _construct_copy(self, other, converter=None):
            Impl._construct(self, other.vehicle, other.planet, other.atmosphere,
                            initial_state=other._x0, air_data_input=other.air_data_input,
                            wind_input=other.wind_input, converter=converter)

        # -- helpers ----------------------------------------------------------------
        def _inputs(self, context):
            x = context.get_continuous_state_vector().CopyToVector()
            bank = self.bank_port.Eval(context)[0]
            alpha = self.alpha_port.Eval(context)[0]
            if x.dtype == float:  # Python floats: the scalar models run about twice as fast
                return x.tolist(), float(bank), float(alpha)
            return x, bank, alpha

        def _aero(self, context, x, alpha):
            """(rho, Mach, L, D, wind or None, air-relative velocity or None) at state x (the
            air-relative velocity computed once, for the aerodynamics and the equations)."""
            if self.air_port is not None:
                rho, a = self.air_port.Eval(context).tolist()
                wind = None if self.wind_port is None else tuple(self.wind_port.Eval(context).tolist())
            else:
                rho, a = dynamics.air_data(x, self.planet, self.atmosphere)
                wind = dynamics.wind_at(x, self.planet, self.atmosphere)
            velocity = None if wind is None else dynamics.air_relative_velocity(x, wind)
            speed = None if velocity is None else velocity[2]
            return (rho, *dynamics.aero_accelerations(x, alpha, rho, a, self.vehicle, wind, speed), wind, velocity)

        # -- Drake callbacks --------------------------------------------------------
        def DoCalcTimeDerivatives(self, context, derivatives):
            x, bank, alpha = self._inputs(context)
            _, _, L, D, wind, velocity = self._aero(context, x, alpha)
            derivatives.get_mutable_vector().SetFromVector(dynamics.equations_of_motion(x, bank, L, D, self.planet, wind,
                                                                                        velocity))

        def _calc_conditions(self, context, output):
            x, _, alpha = self._inputs(context)
            rho, mach, L, D, _, velocity = self._aero(context, x, alpha)
            output.SetFromVector(np.array(dynamics.conditions_from(x, alpha, rho, mach, L, D, self.vehicle, self.planet,
                                                                   None if velocity is None else velocity[2])))

        def state_derivatives(self, context) -> np.ndarray:
            """dx/dt [6] (SI per s) at this plant's ``context`` (as NativeEntryVehicle's)."""
            return self.EvalTimeDerivatives(context).CopyToVector()

        def set_initial_state(self, context, x0):
            """Set the continuous state [h, lon, lat, V, gamma, psi] (SI) in ``context``."""
            context.get_mutable_continuous_state_vector().SetFromVector(np.asarray(x0))

    return Impl


EntryVehicle = EntryVehicle_[None]
