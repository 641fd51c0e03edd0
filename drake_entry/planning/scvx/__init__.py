"""Paper 001: successive convexification (SCvx) entry planning on Drake SOCPs. ``engine`` is the
generic SCvx (virtual controls, buffers, adaptive trust region, golden-section line search),
``entry`` the lossless-bank entry problem, ``mission`` the entry/site/DRS data, ``guess`` the
glide initial guess, ``planner`` puts them together and re-checks the answer."""
