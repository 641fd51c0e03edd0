"""AtmosphereSystem: air data along the trajectory, with an optional density dispersion.

Ports:
  input  "state"     [6]  vehicle state [h m, lon, lat rad, V m/s, gamma, psi rad]
  output "air_data"  [2]  density rho [kg/m^3], speed of sound a [m/s]

A density scale factor (1 + bias) is a parameter, so one diagram serves every
Monte-Carlo sample.
"""
from __future__ import annotations

import numpy as np
from pydrake.systems.framework import LeafSystem_
from pydrake.systems.scalar_conversion import TemplateSystem

from drake_entry.atmosphere import Atmosphere
from drake_entry.planet import Earth


@TemplateSystem.define("AtmosphereSystem_")
def AtmosphereSystem_(T):
    class Impl(LeafSystem_[T]):
        def _construct(self, atmosphere: Atmosphere, planet: Earth, *, density_scale: float = 1.0,
                       converter=None):
            LeafSystem_[T].__init__(self, converter)
            if not density_scale > 0:
                raise ValueError(f"AtmosphereSystem density_scale must be > 0, got {density_scale}")
            self.atmosphere = atmosphere
            self.planet = planet
            self.density_scale = float(density_scale)
            self.state_port = self.DeclareVectorInputPort("state", 6)
            self.DeclareVectorOutputPort("air_data", 2, self._calc,
                                         prerequisites_of_calc={self.state_port.ticket()})

        def _construct_copy(self, other, converter=None):
            Impl._construct(self, other.atmosphere, other.planet, density_scale=other.density_scale,
                            converter=converter)

        def _calc(self, context, output):
            x = self.state_port.Eval(context)
            rho, _, a = self.atmosphere.properties(self.planet.atmospheric_altitude(x[0], x[2]))
            output.SetFromVector(np.array([self.density_scale * rho, a]))

    return Impl


AtmosphereSystem = AtmosphereSystem_[None]
