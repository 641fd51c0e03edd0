"""Aerodynamic coefficient models with one interface.

``model.coefficients(alpha, mach) -> (C_L, C_D)`` takes alpha in radians and works for
float, ndarray and AutoDiffXd (analytic models also for symbolic Expression).
``model.derivatives(alpha, mach) -> AeroDerivatives`` gives C_L, C_D and their first and
second partial derivatives in alpha [1/rad] and Mach, as paper 000 eqs. 44 and 60-61 need.

Models:
  TableAero            smooth (C2) bicubic interpolating spline in (alpha, ln Mach).
  HorusFitAero         the functional forms of paper 000 eqs. 32-33 (least-squares fit).
  CavHAero             the CAV-H analytic fit (Phillips 2003; Jorris & Cobb 2009).
  DragPolarAero        C_L = C_L_alpha alpha, C_D = C_D0 + K C_L^2 (paper 002 eqs. 4-5).
  PolynomialAero       C = sum_ij c_ij alpha^i (1/M)^j (user YAML).
  NewtonianLiftingBodyAero  modified-Newtonian flat-plate model (representative vehicles).
  CallableAero         user callables C_L(alpha, M), C_D(alpha, M).
"""
from __future__ import annotations

import bisect
import functools
import math
from dataclasses import dataclass, field
from importlib import resources
from typing import Callable, NamedTuple, Sequence

import numpy as np
from pydrake.autodiffutils import AutoDiffXd
from scipy.interpolate import CubicSpline

from drake_entry.errors import ScenarioError
from drake_entry.models.data_tables import read_csv_rows
from drake_entry.models.scalar import clamp, is_autodiff, is_symbolic, lift, value_of

__all__ = ["DEG", "CoefficientDerivatives", "AeroDerivatives", "AeroModel", "TableAero", "read_wide_table",
           "packaged_data", "horus2b_table", "HorusFitAero", "horus_cd_form", "horus_cl_form", "FitReport",
           "fit_horus_forms", "CavHAero", "DragPolarAero", "PolynomialAero", "NewtonianLiftingBodyAero",
           "CallableAero", "ScaledAero", "AERO_REGIMES", "RegimeAero"]

DEG = np.pi / 180.0


class CoefficientDerivatives(NamedTuple):
    """A coefficient and its partials: d/dalpha [1/rad], d/dM, and second partials."""

    value: float
    d_alpha: float
    d_mach: float
    d_alpha_alpha: float
    d_alpha_mach: float
    d_mach_mach: float


def _checked_coefficients(coefficients):
    """Wrap a model's coefficients(alpha, mach): a NaN alpha or a Mach <= 0, NaN or infinite
    in float input is a ScenarioError naming the model, not a silent NaN or clamp."""
    @functools.wraps(coefficients)
    def checked(self, alpha, mach):
        if type(mach) is float and type(alpha) is float:
            if not (0.0 < mach < math.inf) or alpha - alpha != 0.0:
                _bad_input(self, alpha, mach)
        elif isinstance(mach, np.ndarray) and mach.dtype.kind == "f" and mach.size:
            # two reductions: a NaN or inf anywhere makes the sum non-finite
            total = mach.sum() + (alpha.sum() if isinstance(alpha, np.ndarray) else alpha)
            if not (mach.min() > 0.0 and math.isfinite(total)):
                _bad_input(self, alpha, mach)
        return coefficients(self, alpha, mach)
    return checked


def _bad_input(model, alpha, mach):
    raise ScenarioError(f"{type(model).__name__}.coefficients: alpha = {alpha} rad must be finite and "
                        f"mach = {mach} in (0, inf)")


def _check_mach_range(model):
    if not 0.0 < model.mach_min < model.mach_max < math.inf:
        raise ScenarioError(f"{type(model).__name__}: mach_min = {model.mach_min} and mach_max = {model.mach_max} "
                            f"need 0 < mach_min < mach_max < inf")


class AeroDerivatives(NamedTuple):
    CL: CoefficientDerivatives
    CD: CoefficientDerivatives


class AeroModel:
    """Base class. Subclasses implement ``coefficients`` generically over the scalar type;
    float inputs are checked here (alpha finite, Mach > 0 and finite) before they run."""

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        if "coefficients" in cls.__dict__:
            cls.coefficients = _checked_coefficients(cls.__dict__["coefficients"])

    def coefficients(self, alpha, mach):  # pragma: no cover - interface
        raise NotImplementedError

    def lift_to_drag(self, alpha, mach):
        cl, cd = self.coefficients(alpha, mach)
        return cl / cd

    def derivatives(self, alpha: float, mach: float, *, step: float = 1e-4) -> AeroDerivatives:
        """First partials by AutoDiff (exact); second partials by central differences of
        the AutoDiff gradients (relative error about step^2)."""

        def grad(a, m):
            A = AutoDiffXd(a, np.array([1.0, 0.0]))
            M = AutoDiffXd(m, np.array([0.0, 1.0]))
            cl, cd = self.coefficients(A, M)
            return [(c.value(), *c.derivatives()) if is_autodiff(c) else (float(c), 0.0, 0.0) for c in (cl, cd)]

        alpha = float(alpha)
        mach = float(mach)
        base = grad(alpha, mach)
        ha = step
        hm = step * max(mach, 1.0)
        ap, am = grad(alpha + ha, mach), grad(alpha - ha, mach)
        mp, mm = grad(alpha, mach + hm), grad(alpha, mach - hm)
        out = []
        for k in range(2):
            v, da, dm = base[k]
            daa = (ap[k][1] - am[k][1]) / (2 * ha)
            dam = (mp[k][1] - mm[k][1]) / (2 * hm)
            dmm = (mp[k][2] - mm[k][2]) / (2 * hm)
            out.append(CoefficientDerivatives(v, da, dm, daa, dam, dmm))
        return AeroDerivatives(*out)


    def drag_derivatives(self, alpha: float, mach: float) -> tuple[CoefficientDerivatives, float]:
        """C_D with its partials and the C_L value: what the drag dynamics need
        (paper 000 eqs. 44, 61). Subclasses with analytic C_D partials override this."""
        d = self.derivatives(alpha, mach)
        return d.CD, d.CL.value


# ---------------------------------------------------------------------------------------
# Tables
# ---------------------------------------------------------------------------------------
class _BicubicSpline:
    """Tensor-product not-a-knot cubic spline through a full grid, evaluated per cell."""

    def __init__(self, x: np.ndarray, y: np.ndarray, values: np.ndarray):
        # spline along y for each x, then spline those polynomial coefficients along x
        sy = CubicSpline(y, values, axis=1)  # c: (4, ny-1, nx)
        sx = CubicSpline(x, sy.c, axis=2)  # c: (4, nx-1, 4, ny-1)
        self.x = x.tolist()
        self.y = y.tolist()
        # coeffs[i][j] = 4x4 list, [p][q] multiplies tx^(3-p) ty^(3-q)
        c = np.transpose(sx.c, (1, 3, 0, 2))
        self.coeffs = c.tolist()

    @staticmethod
    def _cell(grid, v):
        return min(max(bisect.bisect_right(grid, v) - 1, 0), len(grid) - 2)

    def __call__(self, x: float, y: float):
        """Value and partials (f, f_x, f_y, f_xx, f_xy, f_yy) at (x, y) inside the grid."""
        i = self._cell(self.x, x)
        j = self._cell(self.y, y)
        tx = x - self.x[i]
        ty = y - self.y[j]
        C = self.coeffs[i][j]
        px = (tx**3, tx**2, tx, 1.0)
        dpx = (3 * tx**2, 2 * tx, 1.0, 0.0)
        ddpx = (6 * tx, 2.0, 0.0, 0.0)
        py = (ty**3, ty**2, ty, 1.0)
        dpy = (3 * ty**2, 2 * ty, 1.0, 0.0)
        ddpy = (6 * ty, 2.0, 0.0, 0.0)
        # g_q = sum_p C[p][q] px[p] and its x-derivatives
        g = [sum(C[p][q] * px[p] for p in range(4)) for q in range(4)]
        gx = [sum(C[p][q] * dpx[p] for p in range(4)) for q in range(4)]
        gxx = [sum(C[p][q] * ddpx[p] for p in range(4)) for q in range(4)]

        def dot(a, b):
            return a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3]

        return dot(g, py), dot(gx, py), dot(g, dpy), dot(gxx, py), dot(gx, dpy), dot(g, ddpy)


@dataclass
class TableAero(AeroModel):
    """C_L, C_D tabulated on a full (alpha, Mach) grid, interpolated by a C2 bicubic spline
    in (alpha, ln Mach) that reproduces every table value exactly.

    Outside the table alpha and Mach are held at the nearest edge (hypersonic Mach
    independence above the last Mach column); partials are zero there.

    Attributes:
      alpha_deg: grid of angle of attack [deg], increasing.
      mach: grid of Mach numbers, increasing.
      CL, CD: arrays of shape (len(alpha_deg), len(mach)).
    """

    alpha_deg: np.ndarray
    mach: np.ndarray
    CL: np.ndarray
    CD: np.ndarray
    source: str = ""

    def __post_init__(self):
        self.alpha_deg = np.asarray(self.alpha_deg, dtype=float)
        self.mach = np.asarray(self.mach, dtype=float)
        shape = (self.alpha_deg.size, self.mach.size)
        for name in ("CL", "CD"):
            arr = np.asarray(getattr(self, name), dtype=float)
            if arr.shape != shape:
                raise ScenarioError(f"TableAero.{name} has shape {arr.shape}; expected {shape} (alpha x Mach)")
            if np.isnan(arr).any():
                raise ScenarioError(f"TableAero.{name} has empty cells; fill them before building a table model")
            setattr(self, name, arr)
        if np.any(np.diff(self.alpha_deg) <= 0) or np.any(np.diff(self.mach) <= 0):
            raise ScenarioError("TableAero.alpha_deg and TableAero.mach must be strictly increasing")
        if self.mach[0] <= 0:
            raise ScenarioError(f"TableAero.mach must be > 0, got {self.mach[0]}")
        a = self.alpha_deg * DEG
        lnm = np.log(self.mach)
        self._splines = (_BicubicSpline(a, lnm, self.CL), _BicubicSpline(a, lnm, self.CD))
        self._a_range = (float(a[0]), float(a[-1]))
        self._m_range = (float(self.mach[0]), float(self.mach[-1]))

    def _eval(self, k: int, alpha: float, mach: float):
        """Value, d/dalpha, d/dM and second partials of coefficient k (0 CL, 1 CD)."""
        a_in = self._a_range[0] <= alpha <= self._a_range[1]
        m_in = self._m_range[0] <= mach <= self._m_range[1]
        a = min(max(alpha, self._a_range[0]), self._a_range[1])
        m = min(max(mach, self._m_range[0]), self._m_range[1])
        f, fa, fl, faa, fal, fll = self._splines[k](a, math.log(m))
        # chain rule from ln M to M
        fm = fl / m
        fam = fal / m
        fmm = (fll - fl) / (m * m)
        if not a_in:
            fa = faa = fam = 0.0
        if not m_in:
            fm = fam = fmm = 0.0
        return CoefficientDerivatives(f, fa, fm, faa, fam, fmm)

    def coefficients(self, alpha, mach):
        av, mv = value_of(alpha), value_of(mach)
        if isinstance(av, np.ndarray) or isinstance(mv, np.ndarray):
            av, mv = np.broadcast_arrays(np.asarray(av, float), np.asarray(mv, float))
            out = np.array([[self._eval(k, a, m).value for k in (0, 1)] for a, m in zip(av.ravel(), mv.ravel())])
            return out[:, 0].reshape(av.shape), out[:, 1].reshape(av.shape)
        res = []
        for k in (0, 1):
            d = self._eval(k, float(av), float(mv))
            res.append(lift([alpha, mach], d.value, [d.d_alpha, d.d_mach]))
        return tuple(res)

    def derivatives(self, alpha: float, mach: float, **_) -> AeroDerivatives:
        return AeroDerivatives(self._eval(0, float(alpha), float(mach)), self._eval(1, float(alpha), float(mach)))

    def drag_derivatives(self, alpha: float, mach: float):
        return self._eval(1, float(alpha), float(mach)), self._eval(0, float(alpha), float(mach)).value


def read_wide_table(path_or_file, *, fill=None) -> TableAero:
    """Read a table CSV in the M-692 layout (coefficient, alpha_deg, M1.2, M1.5, ...),
    optionally filling empty cells from a long-format CSV (coefficient, alpha_deg, mach, value)."""
    name = getattr(path_or_file, "name", path_or_file)
    rows = read_csv_rows(path_or_file)
    if len(rows) < 3 or len(rows[0]) < 4:
        raise ScenarioError(f"aero table {name}: needs a header (coefficient, alpha_deg, M<mach>, ...) and data rows "
                            f"for at least two angles of attack and two Mach numbers")
    header = rows[0]
    try:
        mach = np.array([float(h.strip().lstrip("Mm")) for h in header[2:]])
        alphas = sorted({float(r[1]) for r in rows[1:]})
        data = {c: np.full((len(alphas), mach.size), np.nan) for c in ("CL", "CD")}
        seen = {}  # (coefficient, alpha) -> the row that gave it
        for k, r in enumerate(rows[1:], start=2):
            if r[0] not in data or len(r) > len(header):
                raise ValueError(f"row {k}: coefficient '{r[0]}' (allowed CL, CD) with {len(r)} cells "
                                 f"(header has {len(header)})")
            if (r[0], float(r[1])) in seen:
                raise ValueError(f"row {k}: {r[0]} at alpha {float(r[1]):g} deg is given twice (row "
                                 f"{seen[(r[0], float(r[1]))]} too): one row per coefficient and angle of attack")
            seen[(r[0], float(r[1]))] = k
            i = alphas.index(float(r[1]))
            for j, v in enumerate(r[2:]):
                if v.strip():
                    data[r[0]][i, j] = float(v)
        if fill is not None:
            for c, a, m, v in read_csv_rows(fill)[1:]:
                if c not in data:
                    raise ValueError(f"fill table: coefficient '{c}' (allowed CL, CD)")
                i = alphas.index(float(a))
                j = int(np.argmin(np.abs(mach - float(m))))
                data[c][i, j] = float(v)
    except (ValueError, IndexError) as e:
        raise ScenarioError(f"aero table {name}: {e}") from None
    return TableAero(np.array(alphas), mach, data["CL"], data["CD"])


def packaged_data(name: str):
    """Open a file shipped in drake_entry/data."""
    return resources.files("drake_entry").joinpath(f"data/{name}").open()


def horus2b_table() -> TableAero:
    """HORUS-2B clean, untrimmed table: M-692 Tables 5.3/5.6 with the empty cells from
    Mooij (2024) Tables B.7/B.8."""
    with packaged_data("horus2b_clean_aero_m692.csv") as t, packaged_data("horus2b_clean_aero_fill_2024.csv") as f:
        table = read_wide_table(t, fill=f)
    table.source = "Mooij M-692 (1995) Tables 5.3/5.6 + Mooij (2024) Tables B.7/B.8; clean, untrimmed"
    return table


# ---------------------------------------------------------------------------------------
# Analytic models
# ---------------------------------------------------------------------------------------
@dataclass
class HorusFitAero(AeroModel):
    """Paper 000 eqs. 32-33 with alpha in degrees and Mach clamped to [mach_min, mach_max].

    The paper's trimmed coefficients (Bergsma & Mooij 2016) are not public; the packaged
    ``horus2b`` vehicle uses a least-squares fit of these forms to the clean, untrimmed
    M-692 table (``fit_horus_forms``), a labelled substitute.
    """

    aD: Sequence[float]
    aL: Sequence[float]
    mach_min: float = 1.2
    mach_max: float = 20.0

    def __post_init__(self):
        if len(self.aD) != 10:
            raise ScenarioError(f"HorusFitAero.aD needs 10 coefficients (paper 000 eq. 32), got {len(self.aD)}")
        if len(self.aL) != 14:
            raise ScenarioError(f"HorusFitAero.aL needs 14 coefficients (paper 000 eq. 33), got {len(self.aL)}")
        self.aD = [float(v) for v in self.aD]
        self.aL = [float(v) for v in self.aL]
        _check_mach_range(self)

    def coefficients(self, alpha, mach):
        if isinstance(alpha, float) and isinstance(mach, float):  # plain floats are faster than numpy scalars
            alpha, mach = float(alpha), float(mach)
            a = alpha / DEG
            M = min(max(mach, self.mach_min), self.mach_max)
            arg = self.aL[7] * a + self.aL[8] * a / (M + self.aL[9])
            return _horus_cl(self.aL, a, M, math.sin(arg), math.cos(arg)), horus_cd_form(self.aD, a, M)
        a = alpha / DEG
        M = clamp(mach, self.mach_min, self.mach_max)
        return horus_cl_form(self.aL, a, M), horus_cd_form(self.aD, a, M)

    def drag_derivatives(self, alpha: float, mach: float):
        """Analytic partials of the eq. 32 polynomial (alpha in rad outside, deg inside)."""
        d = self.aD
        a = float(alpha) / DEG
        inside = self.mach_min <= mach <= self.mach_max
        M = min(max(float(mach), self.mach_min), self.mach_max)
        cd = horus_cd_form(d, a, M)
        c_a = d[1] + 2 * d[2] * a + 3 * d[3] * a * a + d[6] * M + d[7] / M + 2 * d[8] * a / M + d[9] / M**2
        c_aa = 2 * d[2] + 6 * d[3] * a + 2 * d[8] / M
        c_M = d[4] + 2 * d[5] * M + d[6] * a - d[7] * a / M**2 - d[8] * a * a / M**2 - 2 * d[9] * a / M**3
        c_MM = 2 * d[5] + 2 * d[7] * a / M**3 + 2 * d[8] * a * a / M**3 + 6 * d[9] * a / M**4
        c_aM = d[6] - d[7] / M**2 - 2 * d[8] * a / M**2 - 2 * d[9] / M**3
        k = 1.0 / DEG  # d/d(alpha rad) = (1/DEG) d/d(alpha deg)
        if not inside:
            c_M = c_MM = c_aM = 0.0
        cl, _ = self.coefficients(float(alpha), float(mach))
        return CoefficientDerivatives(cd, c_a * k, c_M, c_aa * k * k, c_aM * k, c_MM), float(cl)


def horus_cd_form(d, a, M):
    """Paper 000 eq. 32 (alpha a in degrees)."""
    return (d[0] + d[1] * a + d[2] * a**2 + d[3] * a**3 + d[4] * M + d[5] * M**2 + d[6] * a * M
            + d[7] * a / M + d[8] * a**2 / M + d[9] * a / M**2)


def horus_cl_form(p, a, M):
    """Paper 000 eq. 33 (alpha a in degrees)."""
    arg = p[7] * a + p[8] * a / (M + p[9])
    return _horus_cl(p, a, M, np.sin(arg), np.cos(arg))


def _horus_cl(p, a, M, s, c):
    return (p[0] + p[1] * M + p[2] / (M + p[3]) + (p[4] + p[5] / (M + p[6])) * s
            + (p[10] + p[11] * M + p[12] / (M + p[13])) * c)


class FitReport(NamedTuple):
    aD: list
    aL: list
    rms_CD: float
    max_CD: float
    rms_CL: float
    max_CL: float
    cells_CD: int
    cells_CL: int


def fit_horus_forms(table_csv=None, *, pole_offset_min: float = -1.0, initial_aL=None) -> FitReport:
    """Least-squares fit of paper 000 eqs. 32-33 to the published cells of a wide table.

    C_D is linear in its coefficients (exact linear least squares). C_L is fitted with
    scipy's bounded trust-region least squares; the pole offsets a_L3, a_L6, a_L9, a_L13
    are kept >= ``pole_offset_min`` so no denominator M + a vanishes for M >= 1.2.
    """
    from scipy.optimize import least_squares

    if table_csv is None:
        with packaged_data("horus2b_clean_aero_m692.csv") as f:
            rows = read_csv_rows(f)
    else:
        rows = read_csv_rows(table_csv)
    mach = [float(h.lstrip("Mm")) for h in rows[0][2:]]
    pts = {"CD": [], "CL": []}
    for r in rows[1:]:
        for M, v in zip(mach, r[2:]):
            if v.strip():
                pts[r[0]].append((float(r[1]), M, float(v)))
    A = np.array(pts["CD"])
    basis = np.stack([horus_cd_form(np.eye(10)[k], A[:, 0], A[:, 1]) for k in range(10)], -1)
    aD, *_ = np.linalg.lstsq(basis, A[:, 2], rcond=None)
    rD = basis @ aD - A[:, 2]
    B = np.array(pts["CL"])
    if initial_aL is None:
        # a generic start: lift ~ sin(alpha) with mild Mach terms
        initial_aL = [0.0, 0.0, 0.0, 1.0, 0.0, 1.0, 1.0, 0.05, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]
    lo = np.full(14, -np.inf)
    lo[[3, 6, 9, 13]] = pole_offset_min
    x0 = np.maximum(np.asarray(initial_aL, float), lo + 1e-9)
    sol = least_squares(lambda p: horus_cl_form(p, B[:, 0], B[:, 1]) - B[:, 2], x0, bounds=(lo, np.inf),
                        x_scale="jac", max_nfev=20000)
    rL = sol.fun
    return FitReport(aD.tolist(), sol.x.tolist(), float(np.sqrt(np.mean(rD**2))), float(np.abs(rD).max()),
                     float(np.sqrt(np.mean(rL**2))), float(np.abs(rL).max()), len(A), len(B))


@dataclass
class CavHAero(AeroModel):
    """CAV-H fit, alpha in degrees inside the formula (Phillips 2003; docs/references.md):
    C_L = -0.2317 + 0.0513 alpha + 0.2945 exp(-0.1028 M),
    C_D = 0.024 + 7.24e-4 alpha^2 + 0.406 exp(-0.323 M)."""

    def coefficients(self, alpha, mach):
        a = alpha / DEG
        return (-0.2317 + 0.0513 * a + 0.2945 * np.exp(-0.1028 * mach),
                0.024 + 7.24e-4 * a * a + 0.406 * np.exp(-0.323 * mach))


@dataclass
class DragPolarAero(AeroModel):
    """C_L = C_L_alpha alpha, C_D = C_D0 + K C_L^2 (paper 002 eqs. 4-5), alpha in rad."""

    cd0: float = 0.043
    k: float = 1.0
    cl_alpha: float = 1.0

    def __post_init__(self):
        if self.cd0 <= 0 or self.k < 0:
            raise ScenarioError(f"DragPolarAero needs cd0 > 0 and k >= 0, got cd0={self.cd0}, k={self.k}")

    def coefficients(self, alpha, mach):
        cl = self.cl_alpha * alpha
        return cl + 0.0 * mach, self.cd0 + self.k * cl * cl + 0.0 * mach

    @property
    def alpha_max_lift_to_drag(self) -> float:
        """alpha* = sqrt(C_D0 / K) / C_L_alpha [rad] (paper 002, alpha-bar)."""
        return float(np.sqrt(self.cd0 / self.k) / self.cl_alpha)


@dataclass
class PolynomialAero(AeroModel):
    """``C = sum_ij c[i][j] alpha^i (1/M)^j`` for C_L and C_D, Mach clamped to [mach_min, mach_max].

    Attributes:
      CL, CD: coefficient matrices, rows = powers of alpha, columns = powers of 1/M.
      alpha_unit: 'deg' or 'rad', the unit alpha takes inside the polynomial.
    """

    CL: list
    CD: list
    alpha_unit: str = "deg"
    mach_min: float = 0.1
    mach_max: float = 1e3

    def __post_init__(self):
        if self.alpha_unit not in ("deg", "rad"):
            raise ScenarioError(f"PolynomialAero.alpha_unit must be 'deg' or 'rad', got '{self.alpha_unit}'")
        for name in ("CL", "CD"):
            m = getattr(self, name)
            if not m or not all(isinstance(r, (list, tuple)) and len(r) == len(m[0]) for r in m) or not m[0]:
                raise ScenarioError(f"PolynomialAero.{name} = {m!r} must be a non-empty rectangular list of lists "
                                    f"(rows: powers of alpha, columns: powers of 1/M)")
            for i, row in enumerate(m):
                for j, c in enumerate(row):
                    if isinstance(c, bool) or not isinstance(c, (int, float)) or not math.isfinite(c):
                        raise ScenarioError(f"PolynomialAero.{name}[{i}][{j}] = {c!r} must be a finite number")
        _check_mach_range(self)

    @staticmethod
    def _poly(c, a, x):
        total = 0.0
        for i, row in enumerate(c):
            for j, cij in enumerate(row):
                if cij:
                    total = total + cij * a**i * x**j
        return total

    def coefficients(self, alpha, mach):
        a = alpha / DEG if self.alpha_unit == "deg" else alpha
        x = 1.0 / clamp(mach, self.mach_min, self.mach_max)
        return self._poly(self.CL, a, x), self._poly(self.CD, a, x)


@dataclass
class NewtonianLiftingBodyAero(AeroModel):
    """Modified-Newtonian flat-plate lifting body (a representative model, not flight data).

    Normal force C_N = cn_linear sin(a) cos(a) + cp_max sin^2(a); axial force
    C_A = ca0 + ca_wave exp(-(M - 1)) (a transonic/supersonic wave-drag bump);
    C_L = C_N cos a - C_A sin a, C_D = C_N sin a + C_A cos a. Below Mach
    ``subsonic_blend_mach[0]`` C_D is multiplied by ``subsonic_drag_factor`` (a Newtonian
    model overpredicts subsonic drag of a lifting body); a quintic blend in Mach brings the
    factor to 1 at ``subsonic_blend_mach[1]``.
    """

    cp_max: float = 1.84
    cn_linear: float = 0.0
    ca0: float = 0.05
    ca_wave: float = 0.0
    subsonic_drag_factor: float = 1.0
    subsonic_blend_mach: tuple = (0.8, 2.0)

    def __post_init__(self):
        lo, hi = self.subsonic_blend_mach
        if not 0.0 < self.subsonic_drag_factor <= 10.0:
            raise ScenarioError(f"NewtonianLiftingBodyAero.subsonic_drag_factor = {self.subsonic_drag_factor} "
                                f"must be in (0, 10]")
        if not 0.0 < lo < hi < math.inf:
            raise ScenarioError(f"NewtonianLiftingBodyAero.subsonic_blend_mach = {self.subsonic_blend_mach} "
                                f"needs 0 < low < high < inf")

    def coefficients(self, alpha, mach):
        s, c = np.sin(alpha), np.cos(alpha)
        cn = self.cn_linear * s * c + self.cp_max * s * s
        ca = self.ca0 + self.ca_wave * np.exp(-(clamp(mach, 1.0, 1e3) - 1.0))
        cl, cd = cn * c - ca * s, cn * s + ca * c
        if self.subsonic_drag_factor == 1.0:
            return cl, cd
        lo, hi = self.subsonic_blend_mach  # C_D times a factor blended (C2) to 1 above Mach `hi`
        t = clamp((mach - lo) / (hi - lo), 0.0, 1.0)
        blend = t * t * t * (10.0 - 15.0 * t + 6.0 * t * t)
        return cl, cd * (self.subsonic_drag_factor + (1.0 - self.subsonic_drag_factor) * blend)


@dataclass
class CallableAero(AeroModel):
    """User callables C_L(alpha [rad], M), C_D(alpha [rad], M). Write them with numpy
    functions (np.sin, ...) and they work with AutoDiff and symbolic scalars too."""

    cl: Callable = field(default=None)
    cd: Callable = field(default=None)

    def __post_init__(self):
        if not callable(self.cl) or not callable(self.cd):
            raise ScenarioError("CallableAero needs callables cl(alpha, mach) and cd(alpha, mach)")

    def coefficients(self, alpha, mach):
        return self.cl(alpha, mach), self.cd(alpha, mach)


@dataclass
class ScaledAero(AeroModel):
    """A dispersed vehicle's true aerodynamics: C_L and C_D of ``base`` times scale factors."""

    base: AeroModel
    lift_scale: float = 1.0
    drag_scale: float = 1.0

    def __post_init__(self):
        if is_symbolic(self.lift_scale) or is_symbolic(self.drag_scale):  # a trace: scales are inputs
            return
        if not self.lift_scale > 0 or not self.drag_scale > 0:
            raise ScenarioError(f"ScaledAero scales must be > 0, got {self.lift_scale}, {self.drag_scale}")

    def coefficients(self, alpha, mach):
        cl, cd = self.base.coefficients(alpha, mach)
        return cl * self.lift_scale, cd * self.drag_scale

    def drag_derivatives(self, alpha: float, mach: float):
        cd, cl = self.base.drag_derivatives(alpha, mach)
        return CoefficientDerivatives(*(self.drag_scale * v for v in cd)), cl * self.lift_scale


#: the Mach regimes of aerodynamic uncertainty, slowest first (RegimeAero)
AERO_REGIMES = ("subsonic", "transonic", "supersonic", "hypersonic")


@dataclass
class RegimeAero(AeroModel):
    """A dispersed vehicle's aerodynamics with errors by Mach regime and a trim error:
    C_L = C_L,base(alpha + trim_alpha, M) (1 + dC_L(M)) and likewise C_D, where dC_L(M) is the
    relative error of the regime M lies in (AERO_REGIMES, split at ``boundaries``), changing
    linearly from one regime's to the next over ``blend_mach`` centred on each boundary (so the
    coefficients stay continuous in Mach). Float, array, AutoDiffXd and symbolic inputs.

    Args: base; lift_errors, drag_errors: one relative error per regime (> -1); boundaries:
    increasing Mach numbers between the regimes; blend_mach: the width of each blend (> 0, at
    most the narrowest regime); trim_alpha [rad]: the angle-of-attack error of the trim.
    """

    base: AeroModel
    lift_errors: tuple = (0.0, 0.0, 0.0, 0.0)
    drag_errors: tuple = (0.0, 0.0, 0.0, 0.0)
    boundaries: tuple = (0.8, 1.2, 5.0)
    blend_mach: float = 0.2
    trim_alpha: float = 0.0

    def __post_init__(self):
        self.trim_alpha, self.blend_mach = float(self.trim_alpha), float(self.blend_mach)
        self.lift_errors, self.drag_errors = tuple(map(float, self.lift_errors)), tuple(map(float, self.drag_errors))
        self.boundaries = tuple(map(float, self.boundaries))
        n = len(self.boundaries) + 1
        if len(self.lift_errors) != n or len(self.drag_errors) != n:
            raise ScenarioError(f"RegimeAero needs one lift and one drag error per regime ({n}), got "
                                f"{len(self.lift_errors)} and {len(self.drag_errors)}")
        if not all(math.isfinite(e) and e > -1.0 for e in (*self.lift_errors, *self.drag_errors)):
            raise ScenarioError(f"RegimeAero errors must be finite and > -1 (a coefficient stays positive), got "
                                f"{self.lift_errors}, {self.drag_errors}")
        gaps = np.diff((0.0, *self.boundaries))
        if not (np.all(gaps > 0) and 0 < self.blend_mach <= gaps.min() and math.isfinite(self.trim_alpha)):
            raise ScenarioError(f"RegimeAero needs increasing positive boundaries {self.boundaries}, a blend width "
                                f"0 < {self.blend_mach} <= the narrowest regime, and a finite trim error")

    def factors(self, mach):
        """(1 + dC_L, 1 + dC_D) at Mach ``mach`` (the regimes' errors blended at the boundaries)."""
        kl, kd = 1.0 + self.lift_errors[0], 1.0 + self.drag_errors[0]
        for i, b in enumerate(self.boundaries):
            w = clamp((mach - (b - 0.5 * self.blend_mach)) / self.blend_mach, 0.0, 1.0)
            kl = kl + w * (self.lift_errors[i + 1] - self.lift_errors[i])
            kd = kd + w * (self.drag_errors[i + 1] - self.drag_errors[i])
        return kl, kd

    def coefficients(self, alpha, mach):
        cl, cd = self.base.coefficients(alpha + self.trim_alpha, mach)
        kl, kd = self.factors(mach)
        return cl * kl, cd * kd
