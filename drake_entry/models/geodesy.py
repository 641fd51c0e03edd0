"""Great-circle geometry on a sphere: the one place for bearings, central angles, down- and
cross-track distances and terminal miss geometry. Angles in radians, distances in metres
(``radius`` is the sphere's radius, usually ``Earth.reference_radius``).

Headings and bearings are measured from north, clockwise (the canonical state of docs/architecture.md).
"""
from __future__ import annotations

import math

import numpy as np

__all__ = ["central_angle", "central_angle_smooth", "bearing", "bearings", "range_and_crossrange",
           "downtrack_crosstrack", "crossrange_from_great_circle", "destination"]


def central_angle(lon1, lat1, lon2, lat2):
    """Central angle [rad] between two points (haversine form; floats or arrays)."""
    a = np.sin((lat2 - lat1) / 2) ** 2 + np.cos(lat1) * np.cos(lat2) * np.sin((lon2 - lon1) / 2) ** 2
    return 2.0 * np.arcsin(np.sqrt(np.clip(a, 0.0, 1.0)))


def central_angle_smooth(lon1, lat1, lon2, lat2):
    """Central angle [rad] for optimisers: the haversine form without clipping, so it takes
    Drake AutoDiffXd (and object arrays) and is differentiable at zero distance."""
    fn = math if isinstance(lon1, float) else np
    s = fn.sin(0.5 * (lat2 - lat1)) ** 2 + fn.cos(lat1) * fn.cos(lat2) * fn.sin(0.5 * (lon2 - lon1)) ** 2
    return 2.0 * fn.arcsin(fn.sqrt(s + 1e-30)) if fn is np else 2.0 * math.asin(math.sqrt(s + 1e-30))


def bearing(lon1, lat1, lon2, lat2) -> float:
    """Initial great-circle bearing [rad] from point 1 to point 2, from north, clockwise."""
    dlon = lon2 - lon1
    return math.atan2(math.sin(dlon) * math.cos(lat2),
                      math.cos(lat1) * math.sin(lat2) - math.sin(lat1) * math.cos(lat2) * math.cos(dlon))


def bearings(lon1, lat1, lon2, lat2):
    """``bearing`` for numpy arrays (the same formula; tests hold the two equal)."""
    dlon = lon2 - lon1
    return np.arctan2(np.sin(dlon) * np.cos(lat2), np.cos(lat1) * np.sin(lat2) - np.sin(lat1) * np.cos(lat2) * np.cos(dlon))


def range_and_crossrange(lon, lat, heading, target_lon, target_lat, radius: float) -> tuple[float, float, float]:
    """(range to go, cross-range, distance) [m] of a target seen from (lon, lat) flying along
    ``heading``: the distance projected on the heading (+ target ahead, i.e. short of it) and
    across it (+ target to the right)."""
    dist = float(radius * central_angle(lon, lat, target_lon, target_lat))
    rel = bearing(lon, lat, target_lon, target_lat) - heading
    return dist * math.cos(rel), dist * math.sin(rel), dist


def _unit(lon, lat):
    return np.stack([np.cos(lat) * np.cos(lon), np.cos(lat) * np.sin(lon), np.sin(lat)], axis=-1)


def downtrack_crosstrack(lon, lat, lon0: float, lat0: float, lonf: float, latf: float, radius: float):
    """Paper 002 appendix eqs. 24-30: downtrack d and crosstrack c [m] of points (lon, lat)
    in the frame of the initial position r0 and the final position rf (arrays)."""
    u1 = _unit(lon0, lat0)
    rf = _unit(lonf, latf)
    u3 = np.cross(u1, rf)
    u3 = u3 / np.linalg.norm(u3)
    u2 = np.cross(u3, u1)
    r = _unit(np.asarray(lon, float), np.asarray(lat, float))
    rdc = r @ np.vstack([u1, u2, u3]).T  # eq. 28
    a = np.arctan2(rdc[..., 1], rdc[..., 0])  # eq. 29
    b = np.arcsin(np.clip(rdc[..., 2], -1.0, 1.0))
    return radius * a, radius * b  # eq. 30


def crossrange_from_great_circle(lon, lat, lon0: float, lat0: float, heading0: float, radius: float):
    """Signed distance [m] of (lon, lat) from the great circle through (lon0, lat0) along
    ``heading0`` (+ right of the heading). Takes floats or Drake AutoDiffXd for (lon, lat)."""
    fn = math if isinstance(lon, float) else np
    e = np.array([math.cos(lat0) * math.cos(lon0), math.cos(lat0) * math.sin(lon0), math.sin(lat0)])
    north = np.array([-math.sin(lat0) * math.cos(lon0), -math.sin(lat0) * math.sin(lon0), math.cos(lat0)])
    east = np.array([-math.sin(lon0), math.cos(lon0), 0.0])
    v = math.cos(heading0) * north + math.sin(heading0) * east
    n = np.cross(e, v)  # left of the heading
    p = [fn.cos(lat) * fn.cos(lon), fn.cos(lat) * fn.sin(lon), fn.sin(lat)]
    s = -(n[0] * p[0] + n[1] * p[1] + n[2] * p[2])
    return radius * (math.asin(s) if isinstance(s, float) else np.arcsin(s))


def destination(lon, lat, heading, distance, radius: float):
    """(lon, lat) [rad] reached from (lon, lat) along the great circle with initial
    ``heading`` (from north, clockwise) after ``distance`` [m]."""
    d = distance / radius
    lat2 = math.asin(math.sin(lat) * math.cos(d) + math.cos(lat) * math.sin(d) * math.cos(heading))
    lon2 = lon + math.atan2(math.sin(heading) * math.sin(d) * math.cos(lat), math.cos(d) - math.sin(lat) * math.sin(lat2))
    return lon2, lat2
