"""Paper 001 (SPHYNX): successive convexification (SCvx) entry planning on Drake SOCPs, flown.

``engine`` is the generic SCvx (virtual controls, buffers, adaptive trust region,
golden-section line search), ``entry`` the lossless-bank entry problem, ``mission`` the
entry/site/DRS data, ``guess`` the glide initial guess, ``planner`` puts them together and
checks the answer by flight, ``as_ocp`` states the problem for the shared NLP cross-check,
``aborts`` the abort reachability maps (cases, study, report); ``spec`` is the ``!Scvx`` scenario
block and ``method`` its closed-loop wiring (the plan re-planned on board from the estimate).
"""

__all__ = ["aborts", "as_ocp", "engine", "entry", "guess", "method", "mission", "planner", "plots", "settings",
           "spec"]
