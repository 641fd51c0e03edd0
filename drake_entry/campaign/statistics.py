"""Monte-Carlo statistics of a signable report, in the form of NASA entry, descent and landing
Monte-Carlo practice (Hanson & Beard 2010, NASA/TP-2010-216447; docs/references.md):

- ``success_lower_bound``: the one-sided Clopper-Pearson lower confidence bound on the success
  probability (scipy.stats.binomtest; for n successes in n runs it is (1 - level)^(1/n):
  0.9772 at 90 % for 100 of 100);
- ``success_upper_bound``: the one-sided Clopper-Pearson upper bound (1 - (1 - level)^(1/n)
  for 0 successes in n runs);
- ``order_statistic_bound``: the distribution-free (Wilks) bound: the r-th largest of n
  samples exceeds the ``coverage`` quantile with probability ``confidence`` when
  P(Binomial(n, 1 - coverage) >= r) >= confidence (scipy.stats.binom); with the maximum
  (r = 1) 99 % coverage at 90 % confidence needs 230 runs, 95 %/95 % needs 59;
- ``describe``: min, P0.13, P1, P50, mean, sigma, P99, P99.87, max of one quantity. P0.13 and
  P99.87 are the 3-sigma levels of a normal distribution (99.73 % two-sided); an empirical
  percentile is reported only where the sample holds at least one point beyond it
  (n >= 1 / min(p, 1 - p)), else it is None and the report says why.
"""
from __future__ import annotations

import math

import numpy as np
from scipy import stats

from drake_entry.errors import ScenarioError

__all__ = ["PERCENTILES", "COVERAGE", "CONFIDENCE", "SUCCESS_LEVELS", "success_lower_bound",
           "success_upper_bound", "runs_for_bound",
           "order_statistic_rank", "order_statistic_bound", "finite_column", "describe", "percentile_key", "convergence_counts", "running_estimates",
           "MODE_PROMINENCE", "principal_axis_modes", "FILL_MIN_SAMPLES", "FILL_SIGMAS", "fill_tolerance",
           "normal_ellipse_fill"]

#: the percentiles of the report [%] (P0.13 and P99.87: the normal distribution's 3-sigma levels)
PERCENTILES = (0.13, 1.0, 50.0, 99.0, 99.87)
#: the default coverage and confidence of the order-statistic bound
COVERAGE, CONFIDENCE = 0.99, 0.90
#: the confidence levels of the success-probability bound
SUCCESS_LEVELS = (0.90, 0.95)


def success_lower_bound(successes: int, runs: int, level: float) -> float:
    """One-sided lower ``level`` confidence bound on the success probability (Clopper-Pearson,
    exact): the lower end of the equal-tailed two-sided interval at 2 level - 1."""
    if not (isinstance(runs, (int, np.integer)) and runs >= 1):
        raise ScenarioError(f"runs must be an integer >= 1, got {runs}")
    if not (isinstance(successes, (int, np.integer)) and 0 <= successes <= runs):
        raise ScenarioError(f"successes must be an integer in [0, runs = {runs}], got {successes}")
    if not 0.5 < level < 1.0:
        raise ScenarioError(f"level must be in (0.5, 1), got {level}")
    if successes == 0:
        return 0.0
    return float(stats.binomtest(int(successes), int(runs)).proportion_ci(confidence_level=2.0 * level - 1.0,
                                                                          method="exact").low)


def success_upper_bound(successes: int, runs: int, level: float) -> float:
    """One-sided upper ``level`` confidence bound on the success probability (Clopper-Pearson,
    exact): the upper end of the equal-tailed two-sided interval at 2 level - 1."""
    if runs >= 1 and isinstance(successes, (int, np.integer)) and 0 <= successes <= runs:
        return 1.0 - success_lower_bound(int(runs - successes), runs, level)  # the failures' lower bound
    return success_lower_bound(successes, runs, level)  # its error names the field


def runs_for_bound(coverage: float = COVERAGE, confidence: float = CONFIDENCE) -> int:
    """Fewest runs whose maximum bounds the ``coverage`` quantile at ``confidence`` (Wilks,
    first order): the least n with 1 - coverage^n >= confidence."""
    _check_fraction("coverage", coverage)
    _check_fraction("confidence", confidence)
    n = math.ceil(math.log(1.0 - confidence) / math.log(coverage))
    while stats.binom.sf(0, n, 1.0 - coverage) < confidence:  # guard the rounding of the logarithms
        n += 1
    return int(n)


def order_statistic_rank(runs: int, coverage: float = COVERAGE, confidence: float = CONFIDENCE) -> int:
    """The largest r such that the r-th largest of ``runs`` samples bounds the ``coverage``
    quantile from above with probability >= ``confidence`` (0 when even the maximum does not)."""
    _check_fraction("coverage", coverage)
    _check_fraction("confidence", confidence)
    p_exceed = 1.0 - coverage
    r = 0
    while r < runs and stats.binom.sf(r, runs, p_exceed) >= confidence:  # P(X >= r + 1)
        r += 1
    return r


def order_statistic_bound(values, coverage: float = COVERAGE, confidence: float = CONFIDENCE,
                          upper: bool = True) -> float | None:
    """The distribution-free bound on the ``coverage`` quantile (``upper``) or the 1 - coverage
    quantile (lower) at ``confidence``: the r-th largest (smallest) sample, r from
    ``order_statistic_rank``; None when the sample is too small (``runs_for_bound``)."""
    v = np.sort(np.asarray(values, float)[np.isfinite(values)])
    r = order_statistic_rank(v.size, coverage, confidence)
    if r == 0:
        return None
    return float(v[-r] if upper else v[r - 1])


def finite_column(rows: dict, col: str, n: int) -> np.ndarray:
    """A column as floats (missing column or entry = nan)."""
    v = rows.get(col)
    return np.full(n, np.nan) if v is None else np.array([np.nan if x is None else x for x in v], float)


def describe(values) -> dict:
    """min, P0.13, P1, P50, mean, sigma (n - 1), P99, P99.87, max and n of the finite values
    (percentiles the sample cannot resolve are None, see the module docstring)."""
    v = np.asarray(values, float)
    v = v[np.isfinite(v)]
    n = int(v.size)
    if n == 0:
        return {"n": 0}
    out = {"n": n, "min": float(v.min()), "mean": float(v.mean()), "sigma": float(v.std(ddof=1)) if n > 1 else 0.0,
           "max": float(v.max())}
    for p in PERCENTILES:
        tail = min(p, 100.0 - p) / 100.0
        resolved = tail == 0.5 or n * tail >= 1.0
        out[percentile_key(p)] = float(np.percentile(v, p, method="linear")) if resolved else None
    return out


#: a density peak counts as a mode when it rises this fraction of the highest peak above the
#: valleys beside it (scipy.signal.find_peaks' prominence)
MODE_PROMINENCE = 0.1


def principal_axis_modes(x, y, grid: int = 512) -> int:
    """The most modes of the cloud (x, y) along either of its principal axes: the peaks of its
    Gaussian kernel density (scipy.stats.gaussian_kde, Scott's bandwidth) on the projection,
    counted where their prominence is at least MODE_PROMINENCE of the highest. 1 for a normal
    cloud; a footprint in separate arms (a cluster per reversal count) has several, and its
    normal 99 % ellipse would cover empty ground. Fewer than 4 points or a degenerate cloud: 1."""
    from scipy.signal import find_peaks

    pts = np.vstack([np.asarray(x, float), np.asarray(y, float)])
    pts = pts[:, np.isfinite(pts).all(axis=0)]
    if pts.shape[1] < 4:
        return 1
    _, vecs = np.linalg.eigh(np.cov(pts))
    most = 1
    for axis in vecs.T:
        u = axis @ (pts - pts.mean(axis=1, keepdims=True))
        if np.ptp(u) <= 0.0:
            continue
        kde = stats.gaussian_kde(u)
        pad = 0.1 * np.ptp(u)
        density = kde(np.linspace(u.min() - pad, u.max() + pad, grid))
        peaks, _ = find_peaks(np.concatenate([[0.0], density, [0.0]]), prominence=MODE_PROMINENCE * density.max())
        most = max(most, len(peaks))
    return most


#: fewer samples than this: normal_ellipse_fill does not judge (too few to tell a normal from another)
FILL_MIN_SAMPLES = 20
#: normal_ellipse_fill's band about each contour's probability, in binomial standard deviations
FILL_SIGMAS = 3.0


def fill_tolerance(p: float, n: int) -> float:
    """The half-width of normal_ellipse_fill's band about the fraction ``p`` of ``n`` samples:
    FILL_SIGMAS binomial standard deviations."""
    return FILL_SIGMAS * math.sqrt(p * (1.0 - p) / n)


def normal_ellipse_fill(x, y) -> tuple[float, float, bool]:
    """(f50, f99, fits): the fractions of the cloud (x, y) inside the 50 % and 99 % contours of
    the normal with its own mean and covariance, and whether both are what a normal sample of this
    size gives, each within 3 binomial standard deviations of 0.50 and 0.99. A star of arms from
    one centre (one mode, so principal_axis_modes passes it), a ring, or a core with far outliers
    that inflate the covariance fails, and its ellipse would misstate where the samples land.
    Fewer than FILL_MIN_SAMPLES finite points, or a degenerate cloud: (nan, nan, True)."""
    pts = np.vstack([np.asarray(x, float), np.asarray(y, float)])
    pts = pts[:, np.isfinite(pts).all(axis=0)]
    n = pts.shape[1]
    if n < FILL_MIN_SAMPLES:
        return math.nan, math.nan, True
    cov = np.cov(pts)
    if np.linalg.matrix_rank(cov) < 2:
        return math.nan, math.nan, True
    centred = pts - pts.mean(axis=1, keepdims=True)
    d2 = np.einsum("in,ij,jn->n", centred, np.linalg.inv(cov), centred)
    fits, fractions = True, []
    for p in (0.5, 0.99):
        f = float(np.mean(d2 <= stats.chi2.ppf(p, 2)))
        fractions.append(f)
        fits &= abs(f - p) <= fill_tolerance(p, n)
    return fractions[0], fractions[1], bool(fits)


def convergence_counts(runs: int, points: int = 60) -> np.ndarray:
    """The sample counts the running estimates are computed at: every count up to 20, then about
    ``points`` more spaced evenly in log n up to ``runs`` (ending at it)."""
    first = np.arange(1, min(runs, 20) + 1)
    if runs <= 20:
        return first
    later = np.unique(np.round(np.geomspace(21, runs, points)).astype(int))
    return np.unique(np.concatenate([first, later]))


def running_estimates(success, quantities: dict, level: float = CONFIDENCE, points: int = 60) -> dict:
    """How a campaign's estimates settle as its samples accumulate (in sample order): at each of
    ``convergence_counts`` n, the success fraction of the first n samples with its one-sided
    ``level`` lower and upper Clopper-Pearson bounds, and for each of ``quantities`` ({name:
    values in sample order}) its min, P1, P50, P99 and max over the finite values among the
    first n (None where ``describe`` would not resolve them: P1 and P99 from 100 values).
    Returns {"n", "level", "fraction", "lower", "upper", "quantities": {name: {"min", "p1",
    "p50", "p99", "max"}}}, lists."""
    ok = np.cumsum(np.asarray(success, bool))
    counts = convergence_counts(int(ok.size), points) if ok.size else np.zeros(0, int)
    out = {"n": counts.tolist(), "level": level, "fraction": [float(ok[n - 1] / n) for n in counts],
           "lower": [success_lower_bound(int(ok[n - 1]), int(n), level) for n in counts],
           "upper": [success_upper_bound(int(ok[n - 1]), int(n), level) for n in counts], "quantities": {}}
    for name, values in quantities.items():
        v = np.asarray(values, float)
        rows = [describe(v[:n]) for n in counts]
        out["quantities"][name] = {k: [r.get(k) for r in rows] for k in ("min", "p1", "p50", "p99", "max")}
    return out


def percentile_key(p: float) -> str:
    """'p0.13', 'p1', 'p50', ... (the keys of ``describe``)."""
    return f"p{p:g}"


def _check_fraction(name: str, value: float) -> None:
    if not 0.0 < value < 1.0:
        raise ScenarioError(f"{name} must be in (0, 1), got {value}")
