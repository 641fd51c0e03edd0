"""Paper 001 guidance: a successive-convexification plan (planning/scvx) from the entry state to
the target's DRS box, its bank and alpha flown in time, re-planned on board from the navigation
estimate."""
