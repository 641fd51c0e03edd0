"""The physics: planet, geodesy, atmosphere, aerodynamics, vehicles, equations of motion,
path constraints, command schedules, dispersions, the actuator and bank-reversal laws, the
``Trajectory`` record and the verdict of a flight. Imports only ``drake_entry.errors``,
numpy, scipy and pydrake's maths; every other layer builds on it."""

__all__ = ["acceleration_ratios", "actuator", "aerodynamics", "atmosphere", "bank_reversal", "constraints",
           "data_tables", "dispersions", "dynamics", "environment", "expression_tape", "geodesy", "planet", "scalar",
           "schedules", "symbolic_system", "trajectory", "vehicles", "verdict"]
