"""The campaign's interactive view, interactive.html: linked Plotly views in one self-contained
file (plotly.js inline: no network when it is opened).

- The footprint (cross-range and range to go at the interface [km], the box's radius drawn) and
  the margins scatter (the two path-limit margins that come closest to their limits [%], the
  limits at 0), every sample a point, failed ones red, hovering names the sample and why.
- Selecting samples in either (box or lasso) marks them in both, draws their trajectories over
  the grey others (altitude against speed; bank against time) and lists their dispersed inputs and
  verdicts in a table; a double click clears the selection.

``write_interactive(out_dir, rows, traj, scenario, title, labels)`` writes it from the report's own
columns; a campaign without stored trajectories gets the scatters and the table only.
"""
from __future__ import annotations

import html
import json
import math
import os

import numpy as np

from drake_entry.campaign.drivers import dispersed_inputs
from drake_entry.campaign.statistics import finite_column

__all__ = ["INTERACTIVE", "MAX_POINTS", "write_interactive", "closest_margins"]

#: the file name beside report.html
INTERACTIVE = "interactive.html"
#: stored points per trajectory kept in the view (evenly spaced, the last one kept)
MAX_POINTS = 150


def closest_margins(rows: dict, n: int, count: int = 2) -> list[str]:
    """The ``count`` margin columns whose smallest flown value is lowest (the limits flown
    closest), in that order."""
    worst = []
    for col in sorted(c for c in rows if c.startswith("margin_")):
        m = finite_column(rows, col, n)
        if np.isfinite(m).any():
            worst.append((float(np.nanmin(m)), col))
    return [col for _, col in sorted(worst)[:count]]


def _thin(values, keep) -> list:
    return [None if not math.isfinite(v) else round(float(v), 4) for v in np.asarray(values, float)[keep]]


def _trajectories(traj: dict | None) -> dict:
    """{sample: {v, h, t, bank}} in km/s, km, s and deg, at most MAX_POINTS points each."""
    if not traj:
        return {}
    sample = np.asarray(traj["sample"])
    out = {}
    for s in np.unique(sample):
        idx = np.flatnonzero(sample == s)
        keep = idx[np.unique(np.linspace(0, idx.size - 1, min(idx.size, MAX_POINTS)).round().astype(int))]
        out[str(int(s))] = {"v": _thin(np.asarray(traj["velocity_m_s"], float) / 1e3, keep),
                            "h": _thin(np.asarray(traj["altitude_m"], float) / 1e3, keep),
                            "t": _thin(traj["time_s"], keep),
                            "bank": _thin(traj.get("bank_deg", [math.nan] * sample.size), keep)}
    return out


def _data(rows: dict, traj: dict | None, scenario, labels: dict) -> dict:
    n = len(rows["index"])
    ok = [bool(v) for v in rows["success"]]
    messages = [str(m or "")[:160] for m in rows.get("message", [""] * n)]
    margins = closest_margins(rows, n)
    inputs = dispersed_inputs(rows, n)
    radius = getattr(getattr(scenario, "terminal", None), "distance_tolerance_km", None)
    return {
        "index": [int(i) for i in rows["index"]], "success": ok, "message": messages,
        "cross_km": _thin(finite_column(rows, "err_crossrange_m", n) / 1e3, slice(None)),
        "range_km": _thin(finite_column(rows, "err_range_m", n) / 1e3, slice(None)),
        "margins": [{"name": col.removeprefix("margin_").replace("_", " "),
                     "values": _thin(100 * finite_column(rows, col, n), slice(None))} for col in margins],
        "inputs": [{"name": labels.get(col, col.removeprefix("disp_")), "values": _thin(x, slice(None))}
                   for col, x in inputs],
        "radius_km": radius, "trajectories": _trajectories(traj),
    }


def write_interactive(out_dir: str, rows: dict, traj: dict | None, scenario, title: str,
                      labels: dict | None = None) -> str:
    """interactive.html in ``out_dir`` (module doc; ``labels``: the table's words for the
    ``disp_*`` columns); returns its path."""
    from plotly.offline import get_plotlyjs  # the one library this view needs, inline

    data = json.dumps(_data(rows, traj, scenario, labels or {}), separators=(",", ":"), allow_nan=False)
    page = PAGE.replace("%TITLE%", html.escape(title)).replace("%PLOTLY%", get_plotlyjs()).replace("%DATA%", data)
    path = os.path.join(out_dir, INTERACTIVE)
    with open(path, "w") as f:
        f.write(page)
    return path


PAGE = """<!DOCTYPE html>
<html><head><meta charset="utf-8"><title>%TITLE% - interactive view</title>
<style>body{font-family:sans-serif;margin:1em 2em}#top{display:flex;flex-wrap:wrap}
#top>div{width:48%;min-width:420px;height:430px}#traj{height:430px}
table{border-collapse:collapse;font-size:0.85em}td,th{border:1px solid #bbb;padding:2px 6px}th{background:#eee}
.failed{color:#c00}</style>
<script>%PLOTLY%</script></head><body>
<h2>%TITLE%: interactive view</h2>
<p>Select samples with the box or lasso tool in either scatter: they are marked in both, their
trajectories are drawn over the others (grey) and their dispersed inputs listed below. A double
click clears the selection. Failed samples are red.</p>
<div id="top"><div id="footprint"></div><div id="margins"></div></div>
<div id="traj"></div>
<p id="count">No samples selected.</p>
<div id="table"></div>
<script>
const D = %DATA%;
const N = D.index.length;
const colour = D.success.map(ok => ok ? "#1f77b4" : "#d62728");
const hover = D.index.map((s, i) => "sample " + s + "<br>" + D.message[i]);
const layoutBase = {margin: {t: 50, r: 20, b: 50, l: 60}, dragmode: "lasso", showlegend: false};
function scatter(x, y) {
  return [{x: x, y: y, mode: "markers", type: "scatter", customdata: D.index, text: hover,
           hoverinfo: "text", marker: {color: colour, size: 6}, selected: {marker: {size: 10}},
           unselected: {marker: {opacity: 0.25}}}];
}
const shapes = [];
if (D.radius_km) {
  shapes.push({type: "circle", x0: -D.radius_km, x1: D.radius_km, y0: -D.radius_km, y1: D.radius_km,
               line: {color: "black", dash: "dash"}});
}
Plotly.newPlot("footprint", scatter(D.cross_km, D.range_km), Object.assign({}, layoutBase, {
  title: {text: "Footprint at the interface" + (D.radius_km ? " (dashed: the box's " + D.radius_km + " km)" : "")},
  xaxis: {title: {text: "cross-range [km]"}}, yaxis: {title: {text: "range to go [km]"}, scaleanchor: "x"},
  shapes: shapes}));
const M = D.margins;
const mx = M.length > 0 ? M[0].values : D.index.map(() => 0);
const my = M.length > 1 ? M[1].values : D.index.map(() => 0);
Plotly.newPlot("margins", scatter(mx, my), Object.assign({}, layoutBase, {
  title: {text: "Margins of the two limits flown closest (limit at 0)"},
  xaxis: {title: {text: (M.length > 0 ? M[0].name : "-") + " margin [% of limit]"}, zeroline: true,
          zerolinecolor: "#d62728"},
  yaxis: {title: {text: (M.length > 1 ? M[1].name : "-") + " margin [% of limit]"}, zeroline: true,
          zerolinecolor: "#d62728"}}));
function lines(samples, key_x, key_y) {
  const x = [], y = [];
  for (const s of samples) {
    const t = D.trajectories[String(s)];
    if (!t) continue;
    x.push(...t[key_x], null); y.push(...t[key_y], null);
  }
  return {x: x, y: y};
}
const all = lines(D.index, "v", "h"), allBank = lines(D.index, "t", "bank");
Plotly.newPlot("traj", [
  {x: all.x, y: all.y, mode: "lines", line: {color: "#ccc", width: 1}, name: "every sample", hoverinfo: "skip"},
  {x: [], y: [], mode: "lines", line: {color: "#ff7f0e", width: 2}, name: "selected", hoverinfo: "skip"},
  {x: allBank.x, y: allBank.y, mode: "lines", line: {color: "#ccc", width: 1}, xaxis: "x2", yaxis: "y2",
   hoverinfo: "skip", showlegend: false},
  {x: [], y: [], mode: "lines", line: {color: "#ff7f0e", width: 2}, xaxis: "x2", yaxis: "y2", hoverinfo: "skip",
   showlegend: false}],
  {title: {text: Object.keys(D.trajectories).length ? "Trajectories (selected in orange)" :
                 "Trajectories were not stored for this campaign"},
   grid: {rows: 1, columns: 2, pattern: "independent"}, margin: {t: 50, r: 20, b: 50, l: 60},
   xaxis: {title: {text: "speed [km/s]"}}, yaxis: {title: {text: "altitude [km]"}},
   xaxis2: {title: {text: "time [s]"}}, yaxis2: {title: {text: "bank [deg]"}}});
function show(selected) {
  const set = new Set(selected);
  const points = D.index.map((s, i) => set.has(s) ? i : -1).filter(i => i >= 0);
  for (const id of ["footprint", "margins"]) {
    Plotly.restyle(id, {selectedpoints: [selected.length ? points : null]});
  }
  const a = lines(selected, "v", "h"), b = lines(selected, "t", "bank");
  Plotly.restyle("traj", {x: [a.x, b.x], y: [a.y, b.y]}, [1, 3]);
  document.getElementById("count").textContent = selected.length ?
      selected.length + " sample(s) selected." : "No samples selected.";
  let t = "";
  if (selected.length) {
    t = "<table><tr><th>sample</th><th>verdict</th>" + D.inputs.map(c => "<th>" + c.name + "</th>").join("") + "</tr>";
    for (const i of points.slice(0, 200)) {
      t += "<tr class='" + (D.success[i] ? "" : "failed") + "'><td>" + D.index[i] + "</td><td>" +
           (D.success[i] ? "successful" : D.message[i].replace(/</g, "&lt;")) + "</td>" +
           D.inputs.map(c => "<td>" + (c.values[i] === null ? "-" : c.values[i]) + "</td>").join("") + "</tr>";
    }
    t += "</table>";
  }
  document.getElementById("table").innerHTML = t;
}
for (const id of ["footprint", "margins"]) {
  const el = document.getElementById(id);
  el.on("plotly_selected", ev => show(ev && ev.points ? ev.points.map(p => p.customdata) : []));
  el.on("plotly_deselect", () => show([]));
}
window.showSamples = show;  // the browser test selects through it as a lasso would
</script></body></html>
"""
