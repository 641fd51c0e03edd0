"""Bank-profile guidance: |sigma| linear in normalised energy with the shared reversal logic.
The worked example of adding a method (docs/architecture.md)."""

__all__ = ["method", "spec"]
