"""Published optimal-control problems with known optima, posed as a user would pose them
(the verification suite): each function returns (problem, published) where ``published`` holds the
optimum and its source (tests/test_nlp.py, examples/10_published_optima.py, benchmarks/dymos_peer.py).
"""
from __future__ import annotations

import math

import numpy as np
from scipy.optimize import brentq

from drake_entry.models.aerodynamics import PolynomialAero
from drake_entry.models.atmosphere import ExponentialAtmosphere
from drake_entry.models.constraints import BTU_FT2_S, FT, SLUG, HeatFlux
from drake_entry.models.planet import Earth
from drake_entry.models.vehicles import Vehicle
from drake_entry.planning.ocp import CustomProblem, ObjectiveTerm, OptimalControlProblem, PathConstraint

__all__ = ["G_BRACHISTOCHRONE", "brachistochrone", "goddard_rocket", "shuttle_crossrange"]

G_BRACHISTOCHRONE = 9.81  # m/s^2


def brachistochrone(xf: float = 2.0, yf: float = 1.0, g: float = G_BRACHISTOCHRONE):
    """Minimum time from rest at (0, 0) to (xf, yf), y down, theta the path angle from the
    vertical; published optimum: the cycloid through (xf, yf) (Bernoulli 1696; the optimum
    is exact, computed here). The speed is bounded below by 0: without it (v, theta) and
    (-v, theta + pi) describe the same path and a coarse mesh can settle on the mirrored
    branch (4 DirectCollocation samples: t_f 96 % above the cycloid's, refined and verified)."""
    problem = CustomProblem(
        state_names=("x", "y", "v"), control_names=("theta",),
        dynamics_function=lambda s, u: np.array([s[2] * np.sin(u[0]), s[2] * np.cos(u[0]), g * np.cos(u[0])]),
        initial={"x": 0.0, "y": 0.0, "v": 0.0}, final={"x": xf, "y": yf}, final_time=None,
        mayer_function=lambda x_f, t_f: t_f, control_bounds={"theta": (0.0, math.pi)},
        state_bounds={"v": (0.0, math.inf)}, name="brachistochrone")
    p = brentq(lambda p: (p - math.sin(p)) / (1 - math.cos(p)) - xf / yf, 1e-6, 2 * math.pi - 1e-6)
    radius = yf / (1 - math.cos(p))
    return problem, {"objective": p * math.sqrt(radius / g), "final_time_s": p * math.sqrt(radius / g),
                     "source": "the cycloid (exact)"}


def goddard_rocket():
    """Goddard rocket, maximum final altitude (Dolan, More & Munson, Benchmarking
    Optimization Software with COPS 3.0, ANL/MCS-TM-273, 2004: the Goddard rocket), dimensionless:
    h' = v, v' = (T - D) / m - 1 / h^2, m' = -T / c, D = D_c v^2 exp(-h_c (h - 1)), with
    h_c = 500, c = 0.5, D_c = 310 (0.5 v_c, v_c = 620), T in [0, 3.5]; from (1, 0, 1) to the
    final mass 0.6, free final time. Published: h(t_f) = 1.01283 (COPS 3.0, to the digits
    printed there; the thrust has a singular arc)."""
    h_c, c, d_c, t_max, m_f = 500.0, 0.5, 0.5 * 620.0, 3.5, 0.6

    def dynamics(x, u):
        drag = d_c * x[1] * x[1] * np.exp(-h_c * (x[0] - 1.0))
        return [x[1], (u[0] - drag) / x[2] - 1.0 / (x[0] * x[0]), -u[0] / c]

    problem = CustomProblem(
        state_names=("h", "v", "m"), control_names=("T",), dynamics_function=dynamics,
        initial={"h": 1.0, "v": 0.0, "m": 1.0}, final={"m": m_f}, final_time=None,
        mayer_function=lambda x_f, t_f: -x_f[0], control_bounds={"T": (0.0, t_max)},
        state_bounds={"h": (1.0, 2.0), "v": (0.0, 1.0), "m": (m_f, 1.0)}, name="goddard_rocket")
    return problem, {"objective": -1.01283, "final_altitude": 1.01283,
                     "source": "COPS 3.0 (Dolan, More & Munson 2004)"}


def shuttle_crossrange(heating_limit: bool = False):
    """Space Shuttle re-entry, maximum crossrange (Betts, Practical Methods for Optimal
    Control, 2nd ed., 2010, Sec. 6.1): from 260 000 ft at 25 600 ft/s, gamma
    -1 deg, heading east, to 80 000 ft at 2 500 ft/s, gamma -5 deg, maximise the final
    latitude with alpha in [-90, 90] deg and bank in [-89, 1] deg; free final time.
    Non-rotating spherical Earth, rho = 0.002378 exp(-h / 23 800 ft) slug/ft^3,
    C_L = -0.20704 + 0.029244 alpha, C_D = 0.07854 - 0.61592e-2 alpha + 0.621408e-3 alpha^2
    (alpha in deg), W = 203 000 lb, S = 2 690 ft^2; converted to SI exactly.
    Published: final latitude 34.1412 deg, t_f = 2008.59 s; with ``heating_limit`` the wing
    leading-edge heating q = q_a(alpha) q_r <= 70 BTU/ft^2/s (constraints.HeatFlux.betts_shuttle):
    30.6255 deg, t_f = 2198.67 s."""
    earth = Earth(mu=0.14076539e17 * FT ** 3, reference_radius=20902900.0 * FT,
                  equatorial_radius=20902900.0 * FT, j2=0.0, omega=0.0, flattening=0.0)
    aero = PolynomialAero(CL=[[-0.20704], [0.029244]], CD=[[0.07854], [-0.61592e-2], [0.621408e-3]],
                          alpha_unit="deg")
    vehicle = Vehicle(name="space_shuttle_betts", mass=203000.0 / 32.174 * SLUG, reference_area=2690.0 * FT ** 2,
                      nose_radius=1.0, aero=aero, bank_limit=math.pi, heat_flux=HeatFlux.betts_shuttle(),
                      source="Betts 2010, Sec. 6.1 (nose radius unused: the heating form has none)")
    deg = math.radians
    path = [PathConstraint("heat_flux", max=70.0 * BTU_FT2_S, name="wing leading-edge heating")] if heating_limit \
        else []
    problem = OptimalControlProblem(
        vehicle=vehicle, planet=earth,
        atmosphere=ExponentialAtmosphere(rho0=0.002378 * SLUG / FT ** 3, scale_height=23800.0 * FT),
        controls="direct",
        initial={"h": 260000.0 * FT, "lon": 0.0, "lat": 0.0, "V": 25600.0 * FT, "gamma": deg(-1.0), "psi": deg(90.0)},
        final={"h": 80000.0 * FT, "V": 2500.0 * FT, "gamma": deg(-5.0)},
        final_time=None, path=path,
        control_bounds={"alpha": (deg(-90.0), deg(90.0)), "sigma": (deg(-89.0), deg(1.0))},
        objective=[ObjectiveTerm("final_latitude", weight=-1.0)],
        name="shuttle_crossrange_heating" if heating_limit else "shuttle_crossrange")
    lat, tf = (30.6255, 2198.67) if heating_limit else (34.1412, 2008.59)
    return problem, {"objective": -deg(lat), "final_latitude_deg": lat, "final_time_s": tf,
                     "source": "Betts 2010, Sec. 6.1"}
