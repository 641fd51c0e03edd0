"""An inertial navigation error model: what a strapdown INS (no external aiding after entry) adds
to the true state, and what its accelerometers read.

Error state e = [dr (3), dv (3), phi (3)] in the local level frame (east, north, up): position
[m], velocity [m/s] and platform tilt [rad] errors. Sources, drawn once per flight: the errors at
entry (a 6 x 6 covariance of dr, dv), an accelerometer bias b [m/s^2] and scale-factor error s
(per axis of the stability frame: x along the velocity, z along the lift, y completing the triad)
and a gyro drift eps [rad/s] (local level). Propagation (the standard error equations,
Titterton & Weston, "Strapdown Inertial Navigation Technology", 2nd ed., IEE 2004, ch. 12,
with the Coriolis terms dropped over an entry's minutes):

    dr' = dv
    dv' = C (b + s * f_stab) + phi x f + G dr
    phi' = eps

with f the specific force (drag and lift; stability axes f_stab = (-D, 0, L)), C the stability
to local-level rotation (flight-path angle, heading, bank), and G the gravity feedback:
-g/r on the horizontal components (the Schuler loop) and +2 g/r on the vertical one (the
unstable vertical channel). Without G and with f = 0, a bias b alone gives dv = b t and
dr = b t^2 / 2 exactly. The accelerometers read (1 + s) f_stab + b: the sensed drag and lift
(what drag tracking, FNPEG's density estimate and the acceleration-ratio filter use) carry the
bias and the scale-factor error; the tilt does not enter them (it misplaces the force in the
navigation frame, not its magnitude in the body). (No ``from __future__ import annotations``:
pydrake's YAML reads the spec's field types.)
"""
import dataclasses as dc
import math
import typing

import numpy as np

from drake_entry.errors import ScenarioError
from drake_entry.models.covariance import check_covariance, covariance_root

__all__ = ["InertialNavigationSpec", "validate_inertial_navigation", "InertialErrors", "draw_inertial_errors",
           "stability_to_local_level", "error_acceleration", "propagate", "navigated_state", "sensed_drag_lift"]


@dc.dataclass
class InertialNavigationSpec:
    """Inertial navigation errors of a Monte-Carlo sample (module docstring); 1-sigma values of
    zero-mean Gaussian draws."""

    # false: perfect navigation (guidance reads the true state and the true accelerations) with
    # the same draws, for paired studies
    enabled: bool = True
    # covariance of the errors at entry: [east m, north m, up m, east m/s, north m/s, up m/s]
    # (6 x 6, symmetric, positive semi-definite; none when absent)
    initial_covariance: typing.Optional[list[list[float]]] = None
    # accelerometer bias [m/s^2] and scale-factor error [ppm], per axis
    accelerometer_bias_sigma_m_s2: float = 0.0
    accelerometer_scale_factor_sigma_ppm: float = 0.0
    # gyro drift [deg/h], per axis
    gyro_drift_sigma_deg_h: float = 0.0
    # the Schuler and vertical-channel gravity feedback of the error equations
    gravity_feedback: bool = True


def validate_inertial_navigation(n: InertialNavigationSpec, where: str) -> None:
    """One-line ScenarioErrors naming the field."""
    checks = (("accelerometer_bias_sigma_m_s2", 1.0), ("accelerometer_scale_factor_sigma_ppm", 1e5),
              ("gyro_drift_sigma_deg_h", 1e3))
    for name, hi in checks:
        v = getattr(n, name)
        if not (math.isfinite(v) and 0.0 <= v <= hi):
            raise ScenarioError(f"{where}.{name} = {v} is out of range; allowed: [0, {hi:g}]")
    if n.initial_covariance is not None:
        check_covariance(n.initial_covariance, f"{where}.initial_covariance",
                         "[east m, north m, up m, east m/s, north m/s, up m/s]")


@dc.dataclass(frozen=True)
class InertialErrors:
    """One flight's drawn INS errors (SI): entry errors [dr (3) m, dv (3) m/s] (local level),
    accelerometer bias [3] m/s^2 and scale factor [3] (fractions) in stability axes, gyro drift
    [3] rad/s (local level); ``enabled`` False: perfect navigation."""

    initial: np.ndarray
    accelerometer_bias: np.ndarray
    scale_factor: np.ndarray
    gyro_drift: np.ndarray
    gravity_feedback: bool = True
    enabled: bool = True

    def columns(self) -> dict:
        """The drawn values in table units, for result rows."""
        out = {"disp_ins_dr0_m": float(np.linalg.norm(self.initial[:3])),
               "disp_ins_dv0_m_s": float(np.linalg.norm(self.initial[3:]))}
        for k, axis in enumerate("xyz"):
            out[f"disp_ins_accel_bias_{axis}_m_s2"] = float(self.accelerometer_bias[k])
            out[f"disp_ins_scale_factor_{axis}_ppm"] = float(self.scale_factor[k] * 1e6)
        for k, axis in enumerate("enu"):
            out[f"disp_ins_gyro_drift_{axis}_deg_h"] = float(math.degrees(self.gyro_drift[k]) * 3600.0)
        return out


def draw_inertial_errors(n: InertialNavigationSpec, normal) -> InertialErrors:
    """One flight's errors; ``normal()`` gives one standard normal draw (the sample's generator)."""
    z = np.array([normal() for _ in range(15)])
    initial = np.zeros(6) if n.initial_covariance is None else covariance_root(n.initial_covariance) @ z[:6]
    return InertialErrors(initial, n.accelerometer_bias_sigma_m_s2 * z[6:9],
                          n.accelerometer_scale_factor_sigma_ppm * 1e-6 * z[9:12],
                          math.radians(n.gyro_drift_sigma_deg_h) / 3600.0 * z[12:15], n.gravity_feedback, n.enabled)


def stability_to_local_level(gamma: float, psi: float, bank: float) -> np.ndarray:
    """The rotation [3 x 3] from stability axes (x along the velocity, z along the lift at bank
    sigma, y = z x x) to (east, north, up), at flight-path angle gamma and heading psi [rad]."""
    sg, cg, sp, cp = math.sin(gamma), math.cos(gamma), math.sin(psi), math.cos(psi)
    cb, sb = math.cos(bank), math.sin(bank)
    # t along the velocity, n the lift-up normal, h the right normal; z = cb n + sb h, y = z x t
    # = cb (n x t) + sb (h x t) = -cb h + sb n
    t = (cg * sp, cg * cp, sg)
    n = (-sg * sp, -sg * cp, cg)
    h = (cp, -sp, 0.0)
    return np.array([[t[k], sb * n[k] - cb * h[k], cb * n[k] + sb * h[k]] for k in range(3)])


def error_acceleration(e: np.ndarray, errors: InertialErrors, rotation: np.ndarray, drag: float, lift: float,
                       gravity: float, radius: float) -> np.ndarray:
    """dv' [3] m/s^2 (local level) at error state e [9] (module docstring)."""
    f_stab = np.array([-drag, 0.0, lift])
    fe, fn, fu = rotation @ f_stab
    pe, pn, pu = e[6:9]
    tilt = np.array([pn * fu - pu * fn, pu * fe - pe * fu, pe * fn - pn * fe])  # phi x f
    a = rotation @ (errors.accelerometer_bias + errors.scale_factor * f_stab) + tilt
    if errors.gravity_feedback:
        k = gravity / radius
        a = a + np.array([-k * e[0], -k * e[1], 2.0 * k * e[2]])
    return a


def propagate(e: np.ndarray, errors: InertialErrors, rotation: np.ndarray, drag: float, lift: float,
              gravity: float, radius: float, dt: float) -> np.ndarray:
    """The error state [9] after dt [s] with the inputs held (constant-acceleration step: exact
    for a bias alone, second order in dt with the gravity feedback and a growing tilt)."""
    a = error_acceleration(e, errors, rotation, drag, lift, gravity, radius)
    out = e.copy()
    out[0:3] = e[0:3] + e[3:6] * dt + 0.5 * a * dt * dt
    out[3:6] = e[3:6] + a * dt
    out[6:9] = e[6:9] + errors.gyro_drift * dt
    return out


def navigated_state(x, e: np.ndarray, radius: float) -> np.ndarray:
    """The INS state [h, lon, lat, V, gamma, psi] of the true state x with errors e [9] (the heading
    kept continuous with the true one)."""
    h, lon, lat, V, gamma, psi = (float(v) for v in x)
    cg = math.cos(gamma)
    v = np.array([V * cg * math.sin(psi), V * cg * math.cos(psi), V * math.sin(gamma)]) + e[3:6]
    speed = float(np.linalg.norm(v))
    heading = math.atan2(v[0], v[1])
    heading = psi + math.remainder(heading - psi, 2.0 * math.pi)
    return np.array([h + e[2], lon + e[0] / (radius * math.cos(lat)), lat + e[1] / radius, speed,
                     math.asin(max(-1.0, min(1.0, v[2] / speed))), heading])


def sensed_drag_lift(errors: InertialErrors, drag: float, lift: float) -> tuple[float, float]:
    """The accelerometers' drag and lift [m/s^2]: (1 + s) f_stab + b in stability axes."""
    b, s = errors.accelerometer_bias, errors.scale_factor
    x = (1.0 + s[0]) * -drag + b[0]
    z = (1.0 + s[2]) * lift + b[2]
    return -x, math.hypot(b[1], z)
