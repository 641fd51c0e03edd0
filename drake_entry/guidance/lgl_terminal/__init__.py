"""Paper 002 as guidance: the Legendre pseudospectral optimal-control solution flown in the
closed loop and re-solved on board with the horizon that remains (shrinking-horizon LGL)."""

__all__ = ["method", "mission", "planner", "spec"]
