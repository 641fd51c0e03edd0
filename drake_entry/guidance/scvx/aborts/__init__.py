"""Paper 001 Sec. VI abort maps: the cases and the Tables 4-7 statistics (``cases``, pure), the
campaigns that plan and fly them (``study``) and their report and figures (``report``)."""

__all__ = ["cases", "report", "study"]
