"""AtmosphereSystem: air data along the trajectory.

Ports:
  - input  "state"     [6]  vehicle state [h m, lon, lat rad, V m/s, gamma, psi rad]
  - output "air_data"  [2]  density rho [kg/m^3], speed of sound a [m/s]
  - output "wind"      [2]  (only when the atmosphere has a wind) east, north wind [m/s]

A Monte-Carlo sample's density dispersion is a model, drake_entry.models.atmosphere.DispersedAtmosphere.
"""
from __future__ import annotations

import numpy as np
from pydrake.systems.framework import LeafSystem_
from pydrake.systems.scalar_conversion import TemplateSystem

from drake_entry.models.atmosphere import Atmosphere
from drake_entry.models.dynamics import air_data, wind_at
from drake_entry.models.planet import Earth
from drake_entry.systems.lifetime import weak_method

__all__ = ["AtmosphereSystem_", "AtmosphereSystem"]


@TemplateSystem.define("AtmosphereSystem_")
def AtmosphereSystem_(T):
    class Impl(LeafSystem_[T]):
        def _construct(self, atmosphere: Atmosphere, planet: Earth, *, converter=None):
            LeafSystem_[T].__init__(self, converter)
            self.atmosphere = atmosphere
            self.planet = planet
            self.state_port = self.DeclareVectorInputPort("state", 6)
            self.DeclareVectorOutputPort("air_data", 2, weak_method(self._calc),
                                         prerequisites_of_calc={self.state_port.ticket()})
            if atmosphere.has_wind:
                self.DeclareVectorOutputPort("wind", 2, weak_method(self._calc_wind),
                                             prerequisites_of_calc={self.state_port.ticket()})

        def _construct_copy(self, other, converter=None):
            Impl._construct(self, other.atmosphere, other.planet, converter=converter)

        def _calc(self, context, output):
            output.SetFromVector(np.array(air_data(self.state_port.Eval(context), self.planet, self.atmosphere)))

        def _calc_wind(self, context, output):
            output.SetFromVector(np.array(wind_at(self.state_port.Eval(context), self.planet, self.atmosphere)))

    return Impl


AtmosphereSystem = AtmosphereSystem_[None]
