"""From a validated scene to the objects the solvers take: the surface operator (Green
function or condensed FE) on the scene's grid, and the contact problem with only the laws the
scene names."""


def build_operator(scene, progress=None):
    """The scene's SurfaceOperator: Green function or condensed FE, on the scene's grid."""
    from ..elastic import GreenOperator, RadialGrid

    grid = RadialGrid.uniform(scene.analysis_radius, scene.nodes)
    if scene.method == "fe":
        from ..elastic.fe import FEOperator

        return FEOperator(grid, scene.e_star, scene.fe_poisson_ratio, scene.fe_settings,
                          progress=progress)
    return GreenOperator(grid, scene.e_star)


def build_problem(scene, operator=None, progress=None):
    """The :class:`ContactProblem` of a scene; only the effects it names are built.

    Pass ``operator`` to reuse an already built (e.g. factorised FE) operator.
    """
    from ..contact import ContactProblem

    operator = operator or build_operator(scene, progress)
    return ContactProblem(operator, scene.sphere, dict(scene.effects), scene.gap)
