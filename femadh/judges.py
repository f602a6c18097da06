"""The judges in the form the contact solvers take: surface operators built on
:mod:`femadh.reference`.

The layered half-space's surface operator from the Hankel-transform solution
(:class:`femadh.reference.layered.LayeredHalfSpace`): C = C_stack + C_sphere on a radial grid.
It lives here, not in :mod:`femadh.elastic`, so that no solver package imports a judge
(``tests/test_layout.py`` guards the floors): this module may import both.

It is the independent judge of the layered FE body, in the form the contact solvers take: the
same scene solved on both operators differs only by the FE discretisation (used by
``femadh study convergence`` on layered scenes and by the tests). It is not a scene method:
its cost grows steeply for layers much thinner than the analysis radius (t/a = 1e-3: ~7 s at
N = 200, against ~0.05 s for t ~ a), where the FE body is the faster route.
"""
from .elastic.green import GreenOperator
from .elastic.operator import SurfaceOperator
from .reference.layered import LayeredHalfSpace


class HankelLayeredOperator(SurfaceOperator):
    """Surface compliance of a layer stack on a half-space, by Hankel transform.

    Parameters
    ----------
    grid : RadialGrid
    layers : sequence of (thickness m, E Pa, nu) or objects with those attributes
        Top layer first.
    substrate : IsotropicMaterial or (E Pa, nu)
        The half-space below the layers.
    sphere : IsotropicMaterial or None
        Elastic sphere (its half-space Green compliance is added) or None (rigid).
    """

    name = "layered-hankel"

    def __init__(self, grid, layers, substrate, sphere=None):
        self.grid = grid
        stack = [_triple(ly) for ly in layers]
        sub = (substrate if isinstance(substrate, tuple)
               else (substrate.youngs_modulus, substrate.poisson_ratio))
        self.compliance = LayeredHalfSpace(stack, sub).annulus_compliance(grid.nodes,
                                                                           grid.edges)
        if sphere is not None:
            self.compliance = (self.compliance
                               + GreenOperator(grid, sphere.plane_strain_modulus).compliance)


def _triple(layer):
    """(thickness, E, nu) of a Layer-like object or a tuple."""
    if isinstance(layer, tuple):
        return tuple(float(x) for x in layer)
    return (float(layer.thickness), float(layer.youngs_modulus), float(layer.poisson_ratio))
