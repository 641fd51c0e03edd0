"""Diagram builders: open loop, closed loop, Monte-Carlo campaigns."""

__all__ = ["closed_loop", "common", "open_loop", "verification"]
