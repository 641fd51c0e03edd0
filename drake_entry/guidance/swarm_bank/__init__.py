"""Paper 004 (CAV-H): the bank profile by pigeon-inspired optimisation (and PSO).

|sigma| linear in energy from a sigma_0 chosen by PIO (or PSO, or a scipy baseline) with the
quasi-equilibrium-glide compensation, alpha from the path constraints and the shared bank
reversals; sigma_0 optionally re-solved on board. ``guidance_law`` holds the per-step law
(eqs. 17, 21, 31, 46-48), ``evaluator`` the closed-loop replica that scores a candidate,
``optimizers`` PIO/PSO, ``search`` the searches, ``study`` the paper's study, ``plots`` its
figures; ``spec`` and ``method`` plug it into scenarios and the closed loop (its plan report:
``drake_entry.cli.methods.swarm_bank``).
"""

__all__ = ["evaluator", "guidance_law", "method", "optimizers", "plots", "search", "spec", "study"]
