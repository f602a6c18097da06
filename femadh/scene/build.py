"""From a validated scene to the objects the solvers take: the surface operator (Green
function or condensed FE) on the scene's grid, and the contact problem with only the laws the
scene names.

The operator is built from two of the scene's parts alone, its body and its discretisation
(:func:`operator_from_parts` takes nothing else), and :func:`operator_key`, the content hash
of that pair, is what a study's worker keeps it under: a field added to either part is in the
key by construction.
"""
from .parts import content_hash


def discretisation_grid(disc):
    """The radial nodes of a :class:`~femadh.scene.parts.Discretisation`: its banded grid's
    member, else N uniform nodes on [0, a]."""
    from ..elastic import RadialGrid

    if disc.grid is not None:
        from ..discretisation import GridFamily

        g = disc.grid
        if g.get("follow"):
            # a band that follows the contact edge: its first member is centred on r = 0
            # (the runner exchanges it as the edge moves, femadh.discretisation.moving)
            from ..discretisation.moving import follow_family

            return follow_family(disc.analysis_radius, g["follow"], g["grading"],
                                 0.0).member(g["spacing"])
        return GridFamily(disc.analysis_radius, g["band"], g["grading"]).member(g["spacing"])
    return RadialGrid.uniform(disc.analysis_radius, disc.nodes)


def operator_key(body, discretisation):
    """The key of the operator :func:`operator_from_parts` builds from this pair: the content
    hash of every field of both (40 hex digits). Equal keys, equal operators."""
    return content_hash(body, discretisation)


def build_operator(scene, progress=None, *, grid=None, settings=None):
    """The scene's SurfaceOperator: Green function or condensed FE, on the scene's grid,
    from ``scene.body`` and ``scene.discretisation`` alone (:func:`operator_from_parts`).

    ``grid`` and ``settings`` (FESettings) replace the scene's (convergence studies)."""
    return operator_from_parts(scene.body, scene.discretisation, progress, grid=grid,
                               settings=settings)


def operator_from_parts(body, disc, progress=None, *, grid=None, settings=None):
    """The SurfaceOperator of a body on a discretisation.

    A layered body gets the FE body of its layer stack on the disk material, with the
    sphere's own compliance added (rigid without a slider material). ``grid`` and
    ``settings`` (FESettings) replace the discretisation's (convergence studies).
    """
    from ..elastic import GreenOperator

    grid = grid or discretisation_grid(disc)
    if disc.method == "fe":
        from ..elastic.fe import FEOperator

        settings = settings or disc.fe_settings
        # the condensed body from the on-disk operator cache when it was built before (by
        # content: mesh, grid, materials, settings); its factorised body only on demand
        if body.layers:
            return FEOperator.layered(grid, body.disk, body.layers, body.slider, settings,
                                      progress=progress, cache=True)
        return FEOperator.homogeneous(grid, body.e_star, disc.fe_poisson_ratio, settings,
                                      progress=progress, cache=True)
    return GreenOperator(grid, body.e_star)


def build_problem(scene, operator=None, progress=None):
    """The :class:`ContactProblem` of a scene; only the effects it names are built.

    Pass ``operator`` to reuse an already built (e.g. factorised FE) operator.
    """
    from ..contact import ContactProblem

    operator = operator or build_operator(scene, progress)
    # sub-grid step laws (a tridiagonal law Jacobian) on the stepping solvers; the arclength
    # tracers take a diagonal one and keep the laws collocated
    return ContactProblem(operator, scene.sphere, dict(scene.effects), scene.gap,
                          subgrid=getattr(scene, "continuation", "steps") != "arclength")
