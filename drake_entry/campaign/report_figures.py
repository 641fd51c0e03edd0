"""The figures of a campaign report, each returned with its caption (what it shows, N, the
statistic, the units, what to look at). Headless (Agg).

    terminal_figures(rows, reached, ...)   error histograms, footprint, peak histograms
    trajectory_figures(traj, ...)          envelopes against energy, path quantities, drag
                                           profiles, ground tracks, bank histories
"""
from __future__ import annotations

import math

import numpy as np
from scipy import stats

from drake_entry.campaign.statistics import fill_tolerance, normal_ellipse_fill, principal_axis_modes
from drake_entry.figures import plt, save_figure  # sets the Agg backend before pyplot is imported
from drake_entry.models.verdict import ROUNDING

__all__ = ["ELLIPSE_99_K", "ZOOM_DEG", "ENVELOPE", "ENERGY_AXIS", "ENERGY_DEFINITION", "fd_bins", "plain_axis",
           "error_histograms",
           "footprint", "footprint_core_inset", "INSET_SIZE", "INSET_RATIO", "peak_histograms", "margin_histograms", "envelopes", "OFF_SCALE", "path_quantities", "drag_profiles",
           "ground_tracks", "bank_histories", "energy_range", "normalised_energy", "convergence"]

#: k of the 99 % probability ellipse of a 2-D normal: sqrt(chi2.ppf(0.99, 2)) = 3.035
ELLIPSE_99_K = math.sqrt(stats.chi2.ppf(0.99, 2))
#: the half-width of the ground tracks' zoom about the target [deg of latitude]
ZOOM_DEG = 0.5
#: envelope percentiles across samples [%]
ENVELOPE = (1.0, 50.0, 99.0)
#: the normalised energy on the x axes, defined once for every caption
ENERGY_AXIS = "normalised energy e = (E0 - E) / (E0 - Ef)"
ENERGY_DEFINITION = ("e = (E0 - E) / (E0 - Ef) is the normalised energy (E = V^2/2 - mu/r, E0 the highest and Ef the "
                     "lowest energy flown in the campaign): 0 at entry, 1 at the terminal interface")


def fd_bins(values) -> np.ndarray | int:
    """Freedman-Diaconis bin edges (numpy's 'fd'; 10 bins where the interquartile range is 0)."""
    v = np.asarray(values, float)
    v = v[np.isfinite(v)]
    if v.size < 4 or np.subtract(*np.percentile(v, [75, 25])) == 0.0:
        return 10
    return np.histogram_bin_edges(v, bins="fd")


def _save(fig, out_dir: str, name: str, title: str) -> str:
    paths = []
    save_figure(fig, out_dir, name, paths, title)
    return paths[0]


def plain_axis(ax, which: str = "x") -> None:
    """Tick labels in the axis' own units: no offset and no 'x 1e6' multiplier beside the axis."""
    formatter = (ax.xaxis if which == "x" else ax.yaxis).get_major_formatter()
    if hasattr(formatter, "set_useOffset"):
        formatter.set_useOffset(False)
        formatter.set_scientific(False)


def error_histograms(errors: dict, out_dir: str, title: str, *, nonnegative: tuple = ()) -> tuple[str, str]:
    """``errors``: {label [unit]: values} of the reached samples; the labels in ``nonnegative``
    (a distance) get their mean and largest value instead of mean +- 3 sigma, from 0."""
    n_panels = len(errors)
    cols = 4
    rows = math.ceil(n_panels / cols)
    fig, axes = plt.subplots(rows, cols, figsize=(14, 3.3 * rows), squeeze=False)
    n = 0
    for ax, (label, v) in zip(axes.ravel(), errors.items()):
        v = np.asarray(v, float)
        v = v[np.isfinite(v)]
        n = max(n, v.size)
        ax.hist(v, bins=fd_bins(v), color="C0", alpha=0.8)
        if label in nonnegative and v.size:
            ax.axvline(v.mean(), color="k", lw=1.2, label="mean")
            ax.axvline(v.max(), color="C3", ls=":", lw=1.2, label="largest")
            ax.set_xlim(left=0.0)
            ax.legend(fontsize=7)
        elif v.size > 1:
            m, s = v.mean(), v.std(ddof=1)
            ax.axvline(m, color="k", lw=1.2, label="mean")
            for k in (-3, 3):
                ax.axvline(m + k * s, color="k", ls="--", lw=0.9, label="mean ± 3σ" if k > 0 else None)
        plain_axis(ax)
        ax.set_xlabel(label)
        ax.locator_params(axis="x", nbins=5)
        ax.tick_params(axis="x", labelrotation=30)  # long labels (-0.0025 deg) do not run into each other
        ax.grid(True, alpha=0.4)
    for ax in axes.ravel()[n_panels:]:
        ax.set_visible(False)
    axes[0, 0].set_ylabel("samples")
    if axes[0, 0].get_legend_handles_labels()[0]:
        axes[0, 0].legend(fontsize=7)
    path = _save(fig, out_dir, "error_histograms.png", title)
    return path, (f"Terminal errors of the {n} samples that reached the terminal interface (final minus target "
                  "values). Bins by the Freedman-Diaconis rule; solid line the mean, dashed lines mean ± 3σ (99.73 % "
                  "of a normal distribution)"
                  + (f"; {', '.join(nonnegative)}, never negative, with its largest value dotted instead"
                     if nonnegative else "") + ". Look for skew and outliers beyond the dashed lines.")


def footprint(cross_km, range_km, out_dir: str, title: str, *, radius_km: float | None,
              failed=None) -> tuple[str, str]:
    """Cross-range against range to go [km] of the reached samples, centred on the target; the
    samples ``failed`` marks (not successful: outside the box or past a limit) in red on top."""
    x, y = np.asarray(cross_km, float), np.asarray(range_km, float)
    bad = np.zeros(x.size, bool) if failed is None else np.asarray(failed, bool)
    ok = np.isfinite(x) & np.isfinite(y)
    x, y, bad = x[ok], y[ok], bad[ok]
    fig, ax = plt.subplots(figsize=(6.4, 7.2))
    ax.plot(x[~bad], y[~bad], ".", ms=4, color="C0", label=f"successful ({int((~bad).sum())})")
    if bad.any():
        ax.plot(x[bad], y[bad], "x", ms=7, mew=1.5, color="r", zorder=5,
                label=f"not successful ({int(bad.sum())}: outside the box or past a limit)")
    ax.plot(0.0, 0.0, "r*", ms=14, label="target")
    t = np.linspace(0.0, 2.0 * np.pi, 300)
    circle = np.vstack([np.cos(t), np.sin(t)])
    extent = [np.abs(x).max(initial=0.0), np.abs(y).max(initial=0.0)]
    miss = np.hypot(x, y)
    modes = principal_axis_modes(x, y)
    f50, f99, fits = normal_ellipse_fill(x, y)
    if x.size > 2:
        if modes == 1 and fits:
            vals, vecs = np.linalg.eigh(np.cov(np.vstack([x, y])))
            ell = vecs @ (ELLIPSE_99_K * np.sqrt(np.maximum(vals, 0.0))[:, None] * circle)
            ax.plot(x.mean() + ell[0], y.mean() + ell[1], "C1-", lw=1.5,
                    label=f"99 % ellipse (k = {ELLIPSE_99_K:.3f}σ, normal)")
            extent += [np.abs(x.mean() + ell[0]).max(), np.abs(y.mean() + ell[1]).max()]
        p99 = float(np.percentile(miss, 99))
        ax.plot(p99 * circle[0], p99 * circle[1], "C2:", lw=1.5, label=f"P99 miss radius {p99:.3g} km")
        extent.append(p99)
    in_view = radius_km is not None and radius_km <= 4.0 * max(extent)  # else the samples would be a dot
    if radius_km is not None:
        ax.plot(radius_km * circle[0], radius_km * circle[1], "r--", lw=1.2,
                label=f"acceptance region ({radius_km:g} km)")
        if in_view:
            extent.append(radius_km)
    half = 1.1 * max(max(extent), 1e-3)
    ax.set_xlim(-half, half)
    ax.set_ylim(-half, half)
    ax.set_aspect("equal")
    ax.set_xlabel("cross-range [km] (+ right of the final heading)")
    ax.set_ylabel("range to go [km] (+ short of the target)")
    ax.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.11), ncol=2)  # below: it hides no sample
    ax.grid(True, alpha=0.4)
    core = footprint_core_inset(ax, x, y, bad, half)
    path = _save(fig, out_dir, "footprint.png", title)
    caption = (f"Terminal footprint of the {x.size} samples that reached the terminal interface, centred on the "
               "target, equal axes" + (f"; the {int(bad.sum())} not successful drawn as red crosses on top (a cross "
                                       "inside the acceptance region breached a path limit)" if bad.any() else "")
               + ". "
               + ("The ellipse holds 99 % of a normal distribution with the sample's mean and covariance (k = 3.035σ "
                  "in 2-D)" + (f"; {100 * f50:.0f} % and {100 * f99:.1f} % of the samples lie inside its 50 % and 99 % "
                               "contours, as a normal sample would" if np.isfinite(f50) else "")
                  if modes == 1 and fits else
                  f"No normal ellipse: the cloud is not one cluster ({modes} modes of its kernel density along a "
                  "principal axis), and an ellipse would cover ground no sample reached" if modes > 1 else
                  f"No normal ellipse: the samples do not fill a normal's contours ({100 * f50:.0f} % inside its 50 % "
                  f"contour, {100 * f99:.1f} % inside its 99 %, where a normal sample of {x.size} gives 50 ± "
                  f"{100 * fill_tolerance(0.5, x.size):.0f} % and 99 ± {100 * fill_tolerance(0.99, x.size):.1f} %): arms "
                  "from one centre, a ring or outliers far from the core, which an ellipse would misstate")
               + "; the dotted circle is the 99th percentile of the miss distance")
    caption += (f"; the dashed circle is the acceptance region ({radius_km:g} km)" if radius_km is not None else "")
    if radius_km is not None and not in_view:
        caption += " (drawn only when near the samples: here far outside the axes)"
    if core is not None:
        caption += (f"; the inset zooms on the successful samples (+-{core:.3g} km: 1.3 x their 99th-percentile "
                    f"offset), which the axes' scale would show as one dot")
    return path, caption + "."


#: the inset's side [axes fraction], and how much smaller than the axes the successful core must
#: be for one (a core 1/15 of the half-width is a few points across: a dot)
INSET_SIZE, INSET_RATIO = 0.36, 15.0


def footprint_core_inset(ax, x, y, failed, half: float) -> float | None:
    """An inset of ``ax`` zoomed on the successful samples (not ``failed``) when their core (1.3 x
    the 99th percentile of max(|x|, |y|) [km]) is under 1/INSET_RATIO of the axes' half-width
    ``half`` [km], in the corner with the fewest samples; returns the core's half-width [km], or
    None when no inset is drawn (fewer than 3 successful samples, or the core already visible)."""
    good = ~np.asarray(failed, bool)
    if good.sum() < 3:
        return None
    core = 1.3 * float(np.percentile(np.maximum(np.abs(x[good]), np.abs(y[good])), 99))
    if not 0.0 < core < half / INSET_RATIO:
        return None
    corners = [(0.62, 0.62, 1, 1), (0.02, 0.62, -1, 1), (0.62, 0.02, 1, -1), (0.02, 0.02, -1, -1)]
    edge = 0.25 * half  # samples beyond a quarter of the half-width in a corner's direction would be hidden

    def hidden(corner):
        return int(np.sum((corner[2] * x > edge) & (corner[3] * y > edge)))

    cx, cy, _, _ = min(corners, key=hidden)
    inset = ax.inset_axes([cx, cy, INSET_SIZE, INSET_SIZE])
    inset.plot(x[good], y[good], ".", ms=3, color="C0")
    inset.plot(0.0, 0.0, "r*", ms=9)
    inset.set_xlim(-core, core)
    inset.set_ylim(-core, core)
    inset.set_aspect("equal")
    inset.set_title("successful samples [km]", fontsize=7)
    inset.tick_params(labelsize=6)
    inset.grid(True, alpha=0.3)
    ax.indicate_inset_zoom(inset, edgecolor="0.4")
    return core


def peak_histograms(peaks: dict, out_dir: str, title: str) -> tuple[str, str] | None:
    """``peaks``: {label [unit]: (values, limit or None)} over every sample that flew."""
    panels = [(k, np.asarray(v, float), lim) for k, (v, lim) in peaks.items()
              if np.isfinite(np.asarray(v, float)).any()]
    if not panels:
        return None
    fig, axes = plt.subplots(1, len(panels), figsize=(4.2 * len(panels), 3.6), squeeze=False)
    n = 0
    for ax, (label, v, lim) in zip(axes[0], panels):
        v = v[np.isfinite(v)]
        n = max(n, v.size)
        ax.hist(v, bins=fd_bins(v), color="C0", alpha=0.8)
        if lim is not None and np.isfinite(lim):
            ax.axvline(lim, color="r", ls="--", lw=1.4, label=f"limit {lim:g}")
            ax.legend(fontsize=8)
        plain_axis(ax)
        ax.set_xlabel(label)
        ax.grid(True, alpha=0.4)
    axes[0, 0].set_ylabel("samples")
    path = _save(fig, out_dir, "peak_histograms.png", title)
    return path, (f"Peak path quantities of the {n} samples that flew (the largest value over every log sample and "
                  "integrator step of each flight), Freedman-Diaconis bins, the vehicle's limits dashed. The gap "
                  "between the rightmost bar and the limit line is the campaign's worst margin.")


def margin_histograms(margins: dict, out_dir: str, title: str, *, samples=None,
                      tolerance: float = 0.0) -> tuple[str, str] | None:
    """``margins``: {limit name: (worst relative margin of each sample, nan where it did not
    fly; not-successful mask; the limit's bound text)}: each flight's worst distance to each path
    limit, upper and lower bounds alike (models.verdict.check_limits: negative past the bound),
    in % of the limit, the successful and not-successful samples stacked, the limit at 0 and the
    breach threshold (``tolerance``, relative) drawn, the worst sample named by its index in
    ``samples`` (the rows' sample indices; the position without). A limit no flight came within
    1 - 1/OFF_SCALE of is named in the caption, not drawn (a vehicle file's 'no limit')."""
    panels, far = [], []
    for name, (v, bad, text) in margins.items():
        ids = np.arange(len(v)) if samples is None else np.asarray(samples)
        v, bad = np.asarray(v, float), np.asarray(bad, bool)
        ok = np.isfinite(v)
        if not ok.any():
            continue
        if v[ok].min() > 1.0 - 1.0 / OFF_SCALE:
            far.append(f"{name.replace('_', ' ')} {text}".rstrip())
        else:  # a margin within rounding of 0 (a bank clamped at its limit: -1e-16) is on the limit
            held = np.where((v[ok] < 0.0) & (v[ok] >= -ROUNDING), 0.0, v[ok])
            panels.append((name, 100 * held, bad[ok], text, ids[ok]))
    if not panels:
        return None
    cols = min(len(panels), 3)
    rows = -(-len(panels) // cols)
    fig, axes = plt.subplots(rows, cols, figsize=(4.6 * cols, 3.7 * rows), squeeze=False)
    for ax in axes.flat[len(panels):]:
        ax.set_visible(False)
    n = 0
    for ax, (name, v, bad, text, index) in zip(axes.flat, panels):
        n = max(n, v.size)
        edges = fd_bins(v)  # their width, moved to put an edge at the limit (0)
        w = (float(edges[1] - edges[0]) if not isinstance(edges, int)
             else max(float(np.ptp(v)), 1e-9 + abs(float(v[0]))) / edges)
        edges = w * np.arange(math.floor(v.min() / w), math.floor(v.max() / w) + 2)
        ax.hist([v[~bad], v[bad]], bins=edges, stacked=True, color=["C0", "C3"],
                label=[f"successful ({int((~bad).sum())})", f"not successful ({int(bad.sum())})"])
        ax.axvline(0.0, color="r", ls="-", lw=1.4, label=f"limit {text}".rstrip())
        if tolerance > 0:
            ax.axvline(-100 * tolerance, color="r", ls=":", lw=1.2, label=f"breach past {100 * tolerance:g} %")
        k = int(np.argmin(v))
        ax.plot([], [], " ", label=f"worst {v[k]:+.2f} % (sample {int(index[k])})")
        lo, hi = ax.get_xlim()
        span = hi - lo
        ax.set_xlim(min(lo, -100 * tolerance - 0.05 * span), max(hi, 0.05 * span))
        plain_axis(ax)
        ax.set_title(name.replace("_", " "), fontsize=10)
        ax.set_xlabel("worst margin to the limit [% of the limit]")
        ax.legend(fontsize=7)
        ax.grid(True, alpha=0.4)
    for r in range(rows):
        axes[r, 0].set_ylabel("samples")
    path = _save(fig, out_dir, "margin_histograms.png", title)
    return path, (f"Each flight's worst margin to each path limit, the vehicle's and the mission's, upper and lower "
                  f"bounds alike, over every log sample and integrator step of the {n} samples that flew, in % of the "
                  "limit (negative: past the bound), not-successful samples stacked in red, Freedman-Diaconis bins with an edge at the limit. "
                  "The limit is the solid line at 0" + (f", a breach is counted past the dotted line "
                                                       f"({100 * tolerance:g} % of the limit)" if tolerance > 0 else "")
                  + "; the legend names the worst sample. A lower bound (a dynamic-pressure floor) shows here where "
                  "the path-quantity panels' scale hides it"
                  + (f". Not drawn, every flight more than {100 * (1 - 1 / OFF_SCALE):.0f} % from it: "
                     + ", ".join(far) if far else "") + ".")


def _on_energy_grid(e, v, groups, grid):
    """Each sample's values interpolated on ``grid`` of normalised energy (nan outside its range)."""
    out = np.full((len(groups), grid.size), np.nan)
    for i, g in enumerate(groups):
        order = np.argsort(e[g])
        eg, vg = e[g][order], v[g][order]
        inside = (grid >= eg[0]) & (grid <= eg[-1])
        out[i, inside] = np.interp(grid[inside], eg, vg)
    return out


def envelopes(traj: dict, out_dir: str, title: str, *, nominal: dict | None = None) -> tuple[str, str]:
    """Altitude, speed, flight-path angle and bank against normalised energy as P1/P50/P99
    envelopes, with the nominal (undispersed) flight overlaid when given."""
    sample = np.asarray(traj["sample"])
    e = normalised_energy(traj)
    E0, Ef = energy_range(traj)
    e_nominal = None
    if nominal is not None:
        En = np.asarray(nominal["energy_J_kg"], float)
        e_nominal = (E0 - En) / (E0 - Ef) if E0 > Ef else np.zeros_like(En)
    groups = [np.flatnonzero(sample == s) for s in np.unique(sample)]
    grid = np.linspace(0.0, 1.0, 201)
    fig, axes = plt.subplots(2, 2, figsize=(12, 7.5), sharex=True)
    for ax, (col, scale, label) in zip(axes.ravel(), (("altitude_m", 1e-3, "altitude [km]"),
                                                       ("velocity_m_s", 1e-3, "speed [km/s]"),
                                                       ("flight_path_deg", 1.0, "flight-path angle [deg]"),
                                                       ("bank_deg", 1.0, "bank [deg]"))):
        values = _on_energy_grid(e, np.asarray(traj[col], float) * scale, groups, grid)
        with np.errstate(all="ignore"):
            count = np.isfinite(values).sum(axis=0)
            lo, mid, hi = (np.nanpercentile(values, p, axis=0) if values.size else grid * np.nan for p in ENVELOPE)
        keep = count >= max(3, len(groups) // 2)
        for m in (lo, mid, hi):
            m[~keep] = np.nan
        ax.fill_between(grid, lo, hi, color="C0", alpha=0.25, label="P1 - P99 across samples")
        ax.plot(grid, mid, "C0-", lw=1.5, label="P50 (median)")
        if e_nominal is not None:
            ax.plot(e_nominal, np.asarray(nominal[col], float) * scale, "k--", lw=1.0, label="nominal (no dispersion)")
        ax.set_ylabel(label)
        ax.grid(True, alpha=0.4)
    for ax in axes[1]:
        ax.set_xlabel(ENERGY_AXIS)
    axes[0, 0].legend(fontsize=8)
    path = _save(fig, out_dir, "state_envelopes.png", title)
    return path, (f"State envelopes of the {len(groups)} stored trajectories against normalised energy: the band holds "
                  f"the 1st to 99th percentile across samples at each energy, the solid line their median"
                  + (", the dashed line the nominal flight (the scenario without dispersions)" if nominal is not None
                     else "") + f". {ENERGY_DEFINITION}. "
                  "The bank panel shows magnitudes and signs mixed: see the bank histories for single flights.")


#: a limit further than this factor above the largest flown value is named, not drawn (the
#: axis stays on the data: e.g. a vehicle file's "no limit" 1e6 kPa)
OFF_SCALE = 3.0


#: a mission path limit's state column -> (the stored trajectory's column, its factor to the
#: limit's display unit): such a limit gets a panel of its own in path_quantities
STATE_COLUMNS = {"gamma": ("flight_path_deg", 1.0)}


def _split_by_success(traj: dict, failed) -> tuple[list, list]:
    """The stored trajectory's row indices per sample: (those of the successful samples, those
    of the ``failed`` ones (sample indices; only those stored count), in sample order)."""
    sample = np.asarray(traj["sample"])
    ids = np.unique(sample)
    failed = {int(i) for i in failed} & {int(i) for i in ids}
    return ([np.flatnonzero(sample == s) for s in ids if int(s) not in failed],
            [np.flatnonzero(sample == s) for s in sorted(failed)])


def path_quantities(traj: dict, out_dir: str, title: str, limits, mission_limits=(),
                    failed=()) -> tuple[str, str]:
    """Dynamic pressure, heat flux and normal load (and the total load where the vehicle limits
    it) against normalised energy, every sample, the ``failed`` samples (indices) drawn on top in
    red; the vehicle's limits (``limits``) dashed and the mission's (``mission_limits``:
    PathLimits on the same quantities, e.g. a lower bound on q, or on a state of STATE_COLUMNS,
    e.g. paper 001's flight-path bounds, in a panel of its own) dotted, each labelled."""
    e = normalised_energy(traj)
    groups, bad = _split_by_success(traj, failed)
    panels = [("dynamic_pressure_Pa", "dynamic_pressure", 1e-3, "dynamic pressure [kPa]", "dynamic_pressure_max", "kPa"),
              ("heat_flux_W_m2", "heat_flux", 1e-3, "heat flux [kW/m^2]", "heat_flux_max", "kW/m^2"),
              ("normal_load_g", "normal_load", 1.0, "normal load [g]", "normal_load_max", "g")]
    if limits is not None and np.isfinite(getattr(limits, "total_load_max", np.inf)) and "total_load_g" in traj:
        panels.append(("total_load_g", "total_load", 1.0, "total load [g]", "total_load_max", "g"))
    for m in mission_limits:  # a mission's limit on a state (paper 001's flight-path bounds): its own panel
        col = STATE_COLUMNS.get(m.column)
        if col is not None and col[0] in traj and all(p[1] != m.column for p in panels):
            panels.append((col[0], m.column, col[1], f"{m.name.replace('_', ' ')} [{m.unit}]", None, m.unit))
    fig, axes = plt.subplots(1, len(panels), figsize=(4.7 * len(panels), 4.0))
    for ax, (col, quantity, scale, label, lim, unit) in zip(axes, panels):
        v = np.asarray(traj[col], float) * scale
        for k, g in enumerate(groups):
            ax.plot(e[g], v[g], lw=0.4, alpha=0.4, color="C0", label=f"successful ({len(groups)})" if k == 0 else None)
        for k, g in enumerate(bad):
            ax.plot(e[g], v[g], lw=0.9, alpha=0.9, color="C3", label=f"not successful ({len(bad)})" if k == 0 else None)
        top = float(np.nanmax(v)) if v.size else 0.0
        value = getattr(limits, lim, None) if limits is not None and lim is not None else None
        lines = [] if value is None or not np.isfinite(value) else [(value * scale, f"vehicle limit {value * scale:g} {unit}",
                                                                       "--")]
        for m in mission_limits:
            if m.column == quantity:
                for bound in (m.lower, m.upper):  # SI; a state's panel shows the display unit (m.scale)
                    if np.isfinite(bound):
                        y = bound * (m.scale if quantity in STATE_COLUMNS else scale)
                        lines.append((y, f"{m.name} {m.bound_text()}", ":"))
        named = set()
        for y, text, style in lines:
            if quantity not in STATE_COLUMNS and top > 0 and y > OFF_SCALE * top:
                ax.plot([], [], " ", label=f"{text} (off scale)")
            else:
                ax.axhline(y, color="r", ls=style, lw=1.2, label=None if text in named else text)
            named.add(text)
        if lines or bad:
            ax.legend(fontsize=8)
        ax.set_xlabel(ENERGY_AXIS)
        ax.set_ylabel(label)
        ax.grid(True, alpha=0.4)
    path = _save(fig, out_dir, "path_quantities.png", title)
    return path, (f"Path quantities of the {len(groups) + len(bad)} stored trajectories against normalised energy (one "
                  "line per sample, at the storage step and at each flight's peaks of these quantities and extremes of "
                  "the flight-path angle, taken at the log period: a line's top is its flight's peak; the peaks "
                  "between log samples, at the integrator's steps, are in the peak histograms, and each flight's worst "
                  "margin to every limit, a lower bound's too, in the margin histograms"
                  + (f"; not successful in red, on top: {len(bad)}" if bad else "") + "), the "
                  "vehicle's limits dashed and the mission's dotted (a mission's limit on a state, such as the "
                  "flight-path bounds, in a panel of its own; a limit more than "
                  f"{OFF_SCALE:g} times the largest flown value is named in the legend, not drawn). {ENERGY_DEFINITION}.")


def drag_profiles(traj: dict, out_dir: str, title: str, failed=()) -> tuple[str, str] | None:
    """Flown drag (light) under the guidance's references (dark) against normalised energy (left)
    and the tracking error, flown minus reference drag relative to the reference [%] (right),
    the ``failed`` samples (indices) in red on top."""
    if "reference_drag_m_s2" not in traj:
        return None
    e = normalised_energy(traj)
    good, bad = _split_by_success(traj, failed)
    ref = np.asarray(traj["reference_drag_m_s2"], float)
    D = np.asarray(traj["drag_m_s2"], float)
    fig, (ax, ax_err) = plt.subplots(1, 2, figsize=(13.0, 4.8))
    for i, g in enumerate(good + bad):
        ax.plot(e[g], D[g], lw=2.0, alpha=0.25, color="C1", label="flown drag" if i == 0 else None)
    for i, g in enumerate(good + bad):
        m = ref[g] > 0
        ax.plot(e[g][m], ref[g][m], lw=0.6, color="k", alpha=0.6, label="reference (re-planned)" if i == 0 else None)
    engaged = np.flatnonzero(ref > 0)
    error = np.full(D.shape, np.nan)
    error[engaged] = 100.0 * (D[engaged] / ref[engaged] - 1.0)
    for k, g in enumerate(good):
        g = g[ref[g] > 0]
        ax_err.plot(e[g], error[g], lw=0.4, alpha=0.4, color="C0", label=f"successful ({len(good)})" if k == 0 else None)
    for k, g in enumerate(bad):  # the failed ones last: on top
        g = g[ref[g] > 0]
        ax_err.plot(e[g], error[g], lw=0.9, alpha=0.9, color="C3", label=f"not successful ({len(bad)})" if k == 0 else None)
    ax_err.axhline(0.0, color="k", lw=0.8)
    for a, label in ((ax, "drag acceleration [m/s^2]"), (ax_err, "tracking error: flown / reference - 1 [%]")):
        a.set_xlabel(ENERGY_AXIS)
        a.set_ylabel(label)
        a.grid(True, alpha=0.4)
    ax.legend(fontsize=8)
    if bad:
        ax_err.legend(fontsize=8)
    path = _save(fig, out_dir, "drag_profiles.png", title)
    return path, (f"Drag tracking of the {len(good) + len(bad)} stored trajectories: left, the flown drag (wide "
                  "light lines) under the drag reference the guidance was tracking at each stored point (thin dark lines; it "
                  "changes at every re-plan); right, the tracking error, flown drag relative to that reference, "
                  "where the guidance engages (reference > 0)" + (f", the {len(bad)} not successful in red on top"
                                                                  if bad else "")
                  + f". {ENERGY_DEFINITION}.")


def ground_tracks(traj: dict, out_dir: str, title: str, *, target=None) -> tuple[str, str]:
    """Every stored ground track with the entry points and the target (left), and the last
    ZOOM_DEG around the target, where the dispersed tracks part (right); true-length axes."""
    sample = np.asarray(traj["sample"])
    lon, lat = np.asarray(traj["longitude_deg"], float), np.asarray(traj["latitude_deg"], float)
    groups = [np.flatnonzero(sample == s) for s in np.unique(sample)]
    ends = np.array([[lon[g][-1], lat[g][-1]] for g in groups])
    centre = np.asarray(target, float) if target is not None else ends.mean(axis=0)
    fig, axes = plt.subplots(1, 2, figsize=(13, 5.5))
    aspect = 1.0 / max(math.cos(math.radians(float(np.nanmean(lat)))), 0.1)
    for ax, zoom in zip(axes, (False, True)):
        for g in groups:
            ax.plot(lon[g], lat[g], lw=0.6 if zoom else 0.5, alpha=0.5, color="C0")
        if not zoom:
            starts = np.array([[lon[g][0], lat[g][0]] for g in groups])
            ax.plot(starts[:, 0], starts[:, 1], "g^", ms=5, label="entry interface")
        else:
            ax.plot(ends[:, 0], ends[:, 1], "k.", ms=4, label="terminal points")
            half = max(ZOOM_DEG, 1.2 * float(np.abs(ends - centre).max()))
            ax.set_xlim(centre[0] - half * aspect, centre[0] + half * aspect)
            ax.set_ylim(centre[1] - half, centre[1] + half)
        if target is not None:
            ax.plot(*target, "r*", ms=14, label="target")
        ax.set_aspect(aspect)
        ax.set_xlabel("longitude [deg]")
        ax.set_ylabel("latitude [deg]")
        ax.legend(fontsize=8)
        ax.grid(True, alpha=0.4)
    axes[1].set_title("near the target", fontsize=9)
    path = _save(fig, out_dir, "groundtracks.png", title)
    return path, (f"Ground tracks of the {len(groups)} stored trajectories from their (dispersed) entry interfaces"
                  + (" to the target" if target is not None else "") + " (left) and the end of each near "
                  + ("the target" if target is not None else "the mean terminal point")
                  + " (right), where the dispersed tracks part; both axes scaled so a degree of longitude and of "
                  "latitude have their true lengths at the mean latitude.")


def bank_histories(traj: dict, out_dir: str, title: str, *, detailed: list) -> tuple[str, str] | None:
    """Bank against time of the samples stored at the detailed step."""
    if not detailed:
        return None
    sample = np.asarray(traj["sample"])
    t, bank = np.asarray(traj["time_s"], float), np.asarray(traj["bank_deg"], float)
    fig, ax = plt.subplots(figsize=(9, 4.2))
    for s in detailed:
        g = np.flatnonzero(sample == s)
        ax.plot(t[g], bank[g], lw=1.0, label=f"sample {s}")
    ax.set_xlabel("time [s]")
    ax.set_ylabel("bank [deg] (actuator position)")
    ax.legend(fontsize=8, ncol=min(len(detailed), 5))
    ax.grid(True, alpha=0.4)
    path = _save(fig, out_dir, "bank_histories.png", title)
    return path, (f"Bank angle flown by samples {', '.join(str(s) for s in detailed)} (stored every 1 s or at the "
                  "scenario's log period when longer, not at the campaign's storage step), the bank actuator's "
                  "position: reversals cross wings-level at the bank-rate limit.")


def convergence(est: dict, out_dir: str, title: str, *, miss: str | None = None, tolerance: float | None = None,
                margins: tuple = (), required: float | None = None) -> tuple[str, str] | None:
    """The running estimates (statistics.running_estimates) against the sample count: the
    success fraction with its one-sided bounds (and the ``required`` probability), the P50 and P99
    of the quantity ``miss`` (with the box's ``tolerance`` in its unit), the P1 of each of
    ``margins`` [%] (with the limit at 0)."""
    n = np.asarray(est["n"], float)
    if n.size < 2:
        return None
    q = est["quantities"]
    panels = 1 + (miss is not None) + bool(margins)
    fig, axes = plt.subplots(panels, 1, figsize=(8, 2.6 * panels + 0.6), sharex=True, squeeze=False)
    axes = axes[:, 0]
    level = 100 * float(est.get("level", 0.9))
    ax = axes[0]
    ax.fill_between(n, 100 * np.asarray(est["lower"]), 100 * np.asarray(est["upper"]), color="C0", alpha=0.2,
                    label=f"one-sided {level:g} % bounds")
    ax.plot(n, 100 * np.asarray(est["fraction"]), "C0-", lw=1.2, label="success fraction")
    if required is not None:
        ax.axhline(100 * required, color="r", ls="--", lw=1.0, label=f"required {100 * required:g} %")
    ax.set_ylabel("successful [%]")
    ax.set_ylim(max(0.0, 100 * min(est["lower"]) - 2), 100.5)
    k = 1
    if miss is not None:
        ax = axes[k]
        k += 1
        for key, style, label in (("p50", "C2-", "P50"), ("p99", "C3.-", "P99 (from 100 samples)"),
                                  ("max", "C3:", "largest")):
            v = np.array([np.nan if x is None else x for x in q[miss][key]], float)
            ax.plot(n, v, style, lw=1.0, ms=4, label=label)
        if tolerance is not None:
            ax.axhline(tolerance, color="k", ls="--", lw=1.0, label=f"box {tolerance:g}")
        ax.set_ylabel(miss)
    if margins:
        ax = axes[k]
        for i, name in enumerate(margins):
            for key, style, words in (("p1", ".-", "P1"), ("min", ":", "smallest")):
                v = np.array([np.nan if x is None else 100 * x for x in q[name][key]], float)
                ax.plot(n, v, f"C{i % 10}{style}", lw=1.0, ms=4, label=f"{name.removeprefix('margin_')} {words}")
        ax.axhline(0.0, color="r", ls="--", lw=1.0, label="limit (margin 0)")
        ax.set_ylabel("margin [% of limit]")
    for ax in axes:
        ax.set_xscale("log")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7, loc="best")
    axes[-1].set_xlabel("samples N (in sample order)")
    path = _save(fig, out_dir, "convergence.png", title)
    return path, (f"How the estimates settle as the {int(n[-1])} samples accumulate in sample order: the success "
                  f"fraction with its one-sided {level:g} % Clopper-Pearson bounds"
                  + (f" and the required {100 * required:g} %" if required is not None else "")
                  + (f"; the {miss} P50, P99 (from 100 samples) and largest" if miss is not None else "")
                  + ("; the P1 (from 100 samples) and smallest of each path-limit margin (below 0 a limit is "
                     "passed)" if margins else "")
                  + ". Look at: an estimate still moving at the right end is not converged; the bounds close "
                    "as 1/N.")


def sensitivity_scatter(pairs: list, out_dir: str, title: str) -> tuple[str, str] | None:
    """Each of ``pairs`` [(input words, input values, outcome words, outcome values, PAWN index,
    noise floor, failed mask)] as a panel: the outcome against the input, failed samples red on
    top; None without a pair."""
    if not pairs:
        return None
    fig, axes = plt.subplots(1, len(pairs), figsize=(4.2 * len(pairs), 3.8), squeeze=False)
    for ax, (x_words, x, y_words, y, index, floor, failed) in zip(axes[0], pairs):
        x, y, failed = np.asarray(x, float), np.asarray(y, float), np.asarray(failed, bool)
        ax.plot(x[~failed], y[~failed], "o", color="C0", ms=3, alpha=0.6, label=f"successful ({int((~failed).sum())})")
        if failed.any():
            ax.plot(x[failed], y[failed], "o", color="r", ms=4, label=f"failed ({int(failed.sum())})")
        ax.set_xlabel(x_words)
        ax.set_ylabel(y_words)
        ax.set_title(f"PAWN {index:.2f} (noise floor {floor:.2f})", fontsize=9)
        plain_axis(ax, "x")
        plain_axis(ax, "y")
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=7, loc="best")
    path = _save(fig, out_dir, "sensitivity.png", title)
    return path, ("The outcomes most shaped by one dispersed input, each against that input (PAWN index above the "
                  "largest of the dummy inputs' indices, the noise floor), failed samples in red on top. Look at: "
                  "where the failed samples sit along the input (a tail of it, or spread through it).")


def energy_range(traj: dict) -> tuple[float, float]:
    """(E0, Ef) of ENERGY_DEFINITION: the highest and lowest energy stored [J/kg]."""
    E = np.asarray(traj["energy_J_kg"], float)
    return float(np.nanmax(E)), float(np.nanmin(E))


def normalised_energy(traj: dict) -> np.ndarray:
    """e of ENERGY_DEFINITION for every stored point."""
    E = np.asarray(traj["energy_J_kg"], float)
    E0, Ef = energy_range(traj)
    return (E0 - E) / (E0 - Ef) if E0 > Ef else np.zeros_like(E)
