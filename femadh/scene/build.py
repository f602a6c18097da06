"""From a validated scene to the objects the solvers take: the surface operator (Green
function or condensed FE) on the scene's grid, and the contact problem with only the laws the
scene names."""


def scene_grid(scene):
    """The scene's radial nodes: its [solver.grid] member, else N uniform nodes."""
    from ..elastic import RadialGrid

    if scene.grid is not None:
        from ..discretisation import GridFamily

        g = scene.grid
        if g.get("follow"):
            # a band that follows the contact edge: its first member is centred on r = 0
            # (the runner exchanges it as the edge moves, femadh.discretisation.moving)
            from ..discretisation.moving import follow_family

            return follow_family(scene.analysis_radius, g["follow"], g["grading"],
                                 0.0).member(g["spacing"])
        return GridFamily(scene.analysis_radius, g["band"], g["grading"]).member(g["spacing"])
    return RadialGrid.uniform(scene.analysis_radius, scene.nodes)


def build_operator(scene, progress=None, *, grid=None, settings=None):
    """The scene's SurfaceOperator: Green function or condensed FE, on the scene's grid.

    A layered scene gets the FE body of its layer stack on the disk material, with the
    sphere's own compliance added (rigid without a slider material). ``grid`` and
    ``settings`` (FESettings) replace the scene's (convergence studies).
    """
    from ..elastic import GreenOperator

    grid = grid or scene_grid(scene)
    if scene.method == "fe":
        from ..elastic.fe.cache import cached_operator

        settings = settings or scene.fe_settings
        # the condensed body from the on-disk operator cache when it was built before (by
        # content: mesh, grid, materials, settings); its factorised body only on demand
        if scene.layers:
            return cached_operator(grid, settings=settings, progress=progress,
                                   substrate=scene.disk, layers=scene.layers,
                                   sphere=scene.slider)
        return cached_operator(grid, scene.e_star, scene.fe_poisson_ratio, settings,
                               progress=progress)
    return GreenOperator(grid, scene.e_star)


def build_problem(scene, operator=None, progress=None):
    """The :class:`ContactProblem` of a scene; only the effects it names are built.

    Pass ``operator`` to reuse an already built (e.g. factorised FE) operator.
    """
    from ..contact import ContactProblem

    operator = operator or build_operator(scene, progress)
    return ContactProblem(operator, scene.sphere, dict(scene.effects), scene.gap)
