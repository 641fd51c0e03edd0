"""Paper 004 guidance: |sigma| linear in energy from a sigma_0 chosen by pigeon-inspired
optimisation (or PSO, or a scipy baseline) with the quasi-equilibrium-glide compensation, alpha
from the path constraints, and the shared bank reversals; sigma_0 optionally re-solved on board."""
