"""Several guidance methods on one mission with the same dispersions and seeds: the comparison
file (``spec``: pure data), its runner (``runner``: one campaign per flown method) and its report
(``report``)."""

__all__ = ["report", "runner", "spec"]
