"""Planning machinery shared by several methods: the plan result type, the optimal-control problem description (and its YAML form), the LGL operators, the NLP transcriptions and solver, and time-varying LQR tracking."""

__all__ = ["neighbouring_optimal", "nlp", "ocp", "ocp_system", "ocp_yaml", "progress", "pseudospectral", "result",
           "tracking", "verification"]
