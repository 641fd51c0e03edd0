"""Example 8: paper 001's abort reachability (Sec. VI) with SCvx on SPHYNX, through the campaign
engine (local processes; resumable: run it again and only missing cases run):

1. Orbital aborts: a 9 x 9 grid of entry interface points 5 deg apart around Table 1's, each
   planned for minimum heat load to the Azores site (direct bank and alpha) and flown by the
   Drake Simulator; feasible at 10 km and 40 km; the reachability map and the Tables 4-7 form.
2. Descent aborts: the nominal plan flown, and every 50 s a new plan from the flown state and
   attitude to Ben Guerir (minimum miss, as the paper), each flown.

The EIP states of the grid and the alternative site's coordinates are labelled substitutes
(drake_entry.guidance.scvx.aborts.cases); SPHYNX's aerodynamics are the representative model.

    python examples/08_abort_maps.py [--quick] [--out out/examples/08]

The full run takes about 10 minutes on 2 cores; --quick plans a 1 x 3 row of EIPs and two
descent aborts.
"""
import os

from drake_entry.campaign.store import read_rows
from drake_entry.claims import Claims, run_example
from drake_entry.guidance.scvx.aborts.cases import FEASIBLE_RADII_M, feasible
from drake_entry.guidance.scvx.aborts.report import write_abort_report
from drake_entry.guidance.scvx.aborts.study import run_descent_aborts, run_orbital_aborts


def main(quick: bool = False, out_dir: str = "out/examples/08") -> dict:
    out = {}
    for kind, run, kwargs in (
            ("orbital", run_orbital_aborts, {"shape": (1, 3) if quick else (9, 9)}),
            ("descent", run_descent_aborts, {"spacing_s": 300.0, "last_abort_s": 600.0} if quick else {})):
        directory = os.path.join(out_dir, kind)
        run(directory, progress=not quick, **kwargs)
        rows = list(read_rows(directory)[0].values())
        report = write_abort_report(directory)
        counts = {f"{r / 1e3:g} km": sum(feasible(row, r) for row in rows) for r in FEASIBLE_RADII_M}
        print(f"{kind} aborts: {len(rows)} cases, feasible {counts}; report {report}")
        out[kind] = {"rows": rows, "report": report, "directory": directory}
    return out


def check(r: dict, quick: bool = False) -> Claims:
    """What this example shows, checked (an abort that cannot reach its site is a finding of the
    map, not a failure of the example; a case that raised is)."""
    c = Claims("example 08: paper 001's abort maps")
    orbital, descent = r["orbital"], r["descent"]
    for kind, x in (("orbital", orbital), ("descent", descent)):
        raised = [row for row in x["rows"] if "traceback" in row or "iterations" not in row]
        c.check(f"every {kind} case was planned and flown (none raised)", not raised,
                "; ".join(f"case {row['index']}: {row.get('message', '')[:100]}" for row in raised[:3]))
        c.check(f"the {kind} report is written", os.path.exists(x["report"]), x["report"])
    centre = [row for row in orbital["rows"] if abs(row["entry_longitude_deg"] + 115.0) < 1e-9
              and abs(row["entry_latitude_deg"] - 30.0) < 1e-9]
    c.check("the nominal EIP's abort is feasible at 10 km", bool(centre) and feasible(centre[0], FEASIBLE_RADII_M[0]),
            centre[0]["message"][:160] if centre else "missing")
    c.check("no descent case is called feasible with a planned miss beyond 10 km",
            all(not feasible(row, FEASIBLE_RADII_M[-1]) for row in descent["rows"]
                if row.get("planned_miss_km", 0.0) > 10.0 + 1e-9))
    return c


if __name__ == "__main__":
    raise SystemExit(run_example(__doc__, main, check, out="out/examples/08"))
