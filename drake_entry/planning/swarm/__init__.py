"""Paper 004: entry trajectory design by pigeon-inspired optimisation (and PSO) over the
bank profile, with the angle of attack derived from the path constraints and the
quasi-equilibrium-glide bank compensation (CAV-H). ``guidance_law`` holds the per-step law
(eqs. 17, 21, 31, 46-48)."""
