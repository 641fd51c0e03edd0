"""The schema of a campaign row: what a line of samples.jsonl must hold to be one sample.

Every Monte-Carlo sample writes one row (campaign.sample.run_sample; a sample whose worker
failed, campaign.backends.failed_row): its index, seed, verdict and message, always. A row
that says ``success: true`` carries the verdict behind it: reached the terminal interface,
inside the acceptance box, within every path limit, and its finite miss distance and flight
time. A report reads only rows that meet this schema, so a bare ``{"index": 0, "success":
true}`` is never counted as a successful flight.
"""
from __future__ import annotations

import math

__all__ = ["ROW_FIELDS", "SUCCESS_FIELDS", "row_problem"]

#: every row: field -> what it must be
ROW_FIELDS = {"index": "an integer >= 0", "seed": "an integer", "success": "true or false", "message": "text"}
#: a successful row also: the verdict's parts and the numbers it was judged on
SUCCESS_FIELDS = {"reached_terminal": "true", "inside_box": "true", "within_limits": "true",
                  "err_distance_m": "a finite number", "flight_time_s": "a finite number"}


def _meets(value, want: str) -> bool:
    if want == "an integer >= 0":
        return isinstance(value, int) and not isinstance(value, bool) and value >= 0
    if want == "an integer":
        return isinstance(value, int) and not isinstance(value, bool)
    if want == "true or false":
        return isinstance(value, bool)
    if want == "true":
        return value is True
    if want == "text":
        return isinstance(value, str)
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


def row_problem(row) -> str:
    """Why ``row`` is not a campaign row ('' when it is one): the fields missing or wrong."""
    if not isinstance(row, dict):
        return "not a block of fields"
    wanted = dict(ROW_FIELDS, **(SUCCESS_FIELDS if row.get("success") is True else {}))
    bad = [f"{k} (missing)" if k not in row else f"{k} = {row[k]!r} (want {want})"
           for k, want in wanted.items() if k not in row or not _meets(row[k], want)]
    return ", ".join(bad)
