"""Diagram builders: open loop, closed loop, Monte-Carlo campaigns."""
