"""Paper 003's guidance: a reference from the trajectory database at the entry interface
(AMPI synthesis or the nearest entry, NTT) tracked by a time-varying LQR."""
