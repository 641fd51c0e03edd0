"""Reference-trajectory planners, one module per method."""
