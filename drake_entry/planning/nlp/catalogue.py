"""Published optimal-control problems with known optima, posed as a user would pose them
(issue 14's suite): each function returns (problem, published) where ``published`` holds the
optimum and its source (tests/test_nlp.py). The Brachistochrone is reached with the defaults;
the shuttle is not yet from the built-in guess (docs/methods/nlp.md, issue 14).
"""
from __future__ import annotations

import math

import numpy as np
from scipy.optimize import brentq

from ...aerodynamics import PolynomialAero
from ...atmosphere import ExponentialAtmosphere
from ...planet import Earth
from ...vehicles import Vehicle
from ..ocp import CustomProblem, ObjectiveTerm, OptimalControlProblem

FT = 0.3048  # m
SLUG = 14.593902937  # kg
G_BRACHISTOCHRONE = 9.81  # m/s^2


def brachistochrone(xf: float = 2.0, yf: float = 1.0, g: float = G_BRACHISTOCHRONE):
    """Minimum time from rest at (0, 0) to (xf, yf), y down, theta the path angle from the
    vertical; published optimum: the cycloid through (xf, yf) (Bernoulli 1696; the optimum
    is exact, computed here)."""
    problem = CustomProblem(
        state_names=("x", "y", "v"), control_names=("theta",),
        dynamics_function=lambda s, u: np.array([s[2] * np.sin(u[0]), s[2] * np.cos(u[0]), g * np.cos(u[0])]),
        initial={"x": 0.0, "y": 0.0, "v": 0.0}, final={"x": xf, "y": yf}, final_time=None,
        mayer_function=lambda x_f, t_f: t_f, control_bounds={"theta": (0.0, math.pi)}, name="brachistochrone")
    p = brentq(lambda p: (p - math.sin(p)) / (1 - math.cos(p)) - xf / yf, 1e-6, 2 * math.pi - 1e-6)
    radius = yf / (1 - math.cos(p))
    return problem, {"objective": p * math.sqrt(radius / g), "final_time_s": p * math.sqrt(radius / g),
                     "source": "the cycloid (exact)"}


def shuttle_crossrange():
    """Space Shuttle re-entry, maximum crossrange without a heating limit (Betts, Practical
    Methods for Optimal Control, 2nd ed., 2010, Sec. 6.1, p. 248): from 260 000 ft at
    25 600 ft/s, gamma -1 deg, heading east, to 80 000 ft at 2 500 ft/s, gamma -5 deg,
    maximise the final latitude with alpha in [-90, 90] deg and bank in [-89, 1] deg; free
    final time. Non-rotating spherical Earth, rho = 0.002378 exp(-h / 23 800 ft) slug/ft^3,
    C_L = 0.20704 + 0.029244 alpha, C_D = 0.07854 - 0.61592e-2 alpha + 0.621408e-3 alpha^2
    (alpha in deg), W = 203 000 lb, S = 2 690 ft^2; converted to SI exactly.
    Published: final latitude 34.1412 deg, t_f = 2008.59 s."""
    earth = Earth(mu=0.14076539e17 * FT ** 3, reference_radius=20902900.0 * FT,
                  equatorial_radius=20902900.0 * FT, j2=0.0, omega=0.0, flattening=0.0)
    aero = PolynomialAero(CL=[[0.20704], [0.029244]], CD=[[0.07854], [-0.61592e-2], [0.621408e-3]],
                          alpha_unit="deg")
    vehicle = Vehicle(name="space_shuttle_betts", mass=203000.0 / 32.174 * SLUG, reference_area=2690.0 * FT ** 2,
                      nose_radius=1.0, aero=aero, bank_limit=math.pi,
                      source="Betts 2010, Sec. 6.1 (nose radius unused: no heating limit)")
    deg = math.radians
    problem = OptimalControlProblem(
        vehicle=vehicle, planet=earth,
        atmosphere=ExponentialAtmosphere(rho0=0.002378 * SLUG / FT ** 3, scale_height=23800.0 * FT),
        controls="direct",
        initial={"h": 260000.0 * FT, "lon": 0.0, "lat": 0.0, "V": 25600.0 * FT, "gamma": deg(-1.0), "psi": deg(90.0)},
        final={"h": 80000.0 * FT, "V": 2500.0 * FT, "gamma": deg(-5.0)},
        final_time=None,
        control_bounds={"alpha": (deg(-90.0), deg(90.0)), "sigma": (deg(-89.0), deg(1.0))},
        objective=[ObjectiveTerm("final_latitude", weight=-1.0)], name="shuttle_crossrange")
    return problem, {"objective": -deg(34.1412), "final_latitude_deg": 34.1412, "final_time_s": 2008.59,
                     "source": "Betts 2010, Sec. 6.1, p. 248"}
