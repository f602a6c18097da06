"""The meniscus solvers a scene can ask for: ``fe`` (1D finite elements of the exact
Young-Laplace meridian), ``shooting`` (its ODE solution, the cross-check), ``circular`` (the
toroidal approximation) and ``no-film`` (the exact meniscus on bare solids)."""
METHODS = ("fe", "shooting", "circular", "no-film")
