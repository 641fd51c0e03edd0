"""Paper 000 (HORUS-2B): drag-energy guidance by pseudospectral convex optimisation.

``drag_dynamics`` holds the drag-energy equations, ``corridor`` the drag corridor from the
path constraints, ``planner`` the SOCP reference and its re-planning, ``spec`` the
``!DragEnergy`` scenario block, ``method`` the closed-loop wiring, ``plots`` its figures and
``commands`` its plan report.
"""
