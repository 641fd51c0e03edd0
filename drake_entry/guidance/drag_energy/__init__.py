"""Paper 000 (HORUS-2B): drag-energy guidance by pseudospectral convex optimisation.

``drag_dynamics`` holds the drag-energy equations, ``corridor`` the drag corridor from the
path constraints, ``planner`` the SOCP reference and its re-planning, ``spec`` the
``!DragEnergy`` scenario block, ``method`` the closed-loop wiring and ``plots`` its figures
(its plan report and ``fit-horus`` are ``drake_entry.cli.methods.drag_energy``).
"""

__all__ = ["corridor", "drag_dynamics", "method", "planner", "plots", "spec"]
