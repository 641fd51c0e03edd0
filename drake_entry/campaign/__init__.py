"""Campaign outputs shared by every method: the durable campaign directory (``store``), the
report (``report``), the standard figures (``plots``) and result tables (``tables``)."""

__all__ = ["backends", "engine", "montecarlo", "report", "report_figures", "sample", "statistics", "store"]
