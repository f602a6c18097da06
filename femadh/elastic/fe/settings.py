"""Settings of the FE body and the rules that turn them into a mesh: :class:`FESettings`, the
Poisson-ratio limits of the two formulations, the radial grading rule for thin soft layers and
:func:`mesh_spec` (the gmsh/structured mesh of a grid)."""
from dataclasses import dataclass

import numpy as np

from ...materials import IsotropicMaterial
from .layers import Layer
from .mesh import MeshSpec, surface_points_of

#: above this Poisson ratio of any region, formulation "auto" uses the mixed one (plain P2
#: displacement elements lock in confined nearly incompressible layers)
NU_DISPLACEMENT_MAX = 0.45
#: largest Poisson ratio the FE body accepts (mixed formulation; its pressure is eliminated
#: element by element with a finite lambda, so nu = 0.5 itself is excluded)
NU_LIMIT = 0.49999


@dataclass
class FESettings:
    """Mesh parameters of the FE operator (dimensionless, relative to the grid).

    Attributes
    ----------
    outer_factor : float
        L / max(a, D): far-boundary radius over the larger of the analysis radius a and the
        layer stack depth D (D = 0 for the homogeneous half-space).
    growth : float
        Element size growth with distance from the loaded segment.
    surface_fraction : float
        Surface element size as a fraction of the node spacing (1/2: one element per
        node-to-edge interval).
    far_field : str
        ``"boussinesq"``: the far boundary carries the (substrate's) point-load field scaled by
        the total load (truncation error O(a^2/L^2) homogeneous); ``"fixed"``: u = 0 there
        (error O(a/L), for studies).
    layer_min_elements : int
        Least number of elements through the thickness of any layer.
    layer_radial_elements : float
        Radial surface elements per thickness of the thinnest layer on the loaded segment: the
        surface size is min(surface_fraction x node spacing, t_min / layer_radial_elements) ...
    max_layer_refinement : float
        ... but at most this many times finer than surface_fraction x node spacing (a layer
        much thinner than the node spacing changes the nodal response only through its
        thickness, not through the narrow boundary layers at the annulus edges).
    formulation : str
        ``"displacement"``: P2 displacement elements; ``"mixed"``: P2 + cubic bubble
        displacements with a discontinuous P1 pressure eliminated per element (locking-free
        for nu -> 0.5); ``"auto"``: mixed when a region has nu > NU_DISPLACEMENT_MAX.
    """

    outer_factor: float = 1e4
    growth: float = 0.25
    surface_fraction: float = 0.5
    far_field: str = "boussinesq"
    layer_min_elements: int = 2
    formulation: str = "auto"
    layer_radial_elements: float = 8.0
    max_layer_refinement: float = 8.0

    def __post_init__(self):
        if not self.outer_factor > 1:
            raise ValueError(f"outer_factor must be > 1, got {self.outer_factor}")
        if not 0 < self.growth <= 2:
            raise ValueError(f"growth must be in (0, 2], got {self.growth}")
        if not 0 < self.surface_fraction <= 1:
            raise ValueError(f"surface_fraction must be in (0, 1], got {self.surface_fraction}")
        if self.far_field not in ("boussinesq", "fixed"):
            raise ValueError(f"far_field must be 'boussinesq' or 'fixed', got {self.far_field!r}")
        if not int(self.layer_min_elements) >= 1:
            raise ValueError(f"layer_min_elements must be >= 1, got {self.layer_min_elements}")
        if not (self.layer_radial_elements > 0 and self.max_layer_refinement >= 1):
            raise ValueError("need layer_radial_elements > 0 and max_layer_refinement >= 1")
        if self.formulation not in ("auto", "displacement", "mixed"):
            raise ValueError(f"formulation must be 'auto', 'displacement' or 'mixed', got "
                             f"{self.formulation!r}")


#: a layer whose E/(1 - nu^2) is below this fraction of the material directly beneath it is
#: "soft": it carries the deformation of a pressure step in a boundary layer ~ its thickness
SOFT_RATIO = 0.25


def layers_needing_radial_resolution(layers, substrate=None):
    """Thicknesses (m) of the layers the radial grading rule applies to: soft layers (plane-
    strain modulus < SOFT_RATIO x that of the material directly below) and nearly
    incompressible ones (nu > NU_DISPLACEMENT_MAX). A thickness given without a material, or
    the last layer when the substrate is not given, counts (the conservative choice).

    Stiff or matched layers transmit a pressure step like the homogeneous body, which the
    grid's own surface size resolves (measured: a 10x or 100x stiffer layer, and one 2x softer,
    0.1-0.4 node spacings thick, stay within 3e-4 of the reference unrefined; 100x softer:
    4.3e-3, 0.45 < nu, 100x softer: 1.9e-2).
    """
    out = []
    for i, ly in enumerate(layers):
        if not isinstance(ly, Layer):
            out.append(float(ly))
            continue
        below = layers[i + 1] if i + 1 < len(layers) else substrate
        if below is None or not isinstance(below, (Layer, IsotropicMaterial)):
            out.append(ly.thickness)
            continue
        e_below = below.youngs_modulus / (1 - below.poisson_ratio**2)
        e_here = ly.youngs_modulus / (1 - ly.poisson_ratio**2)
        if e_here < SOFT_RATIO * e_below or ly.poisson_ratio > NU_DISPLACEMENT_MAX:
            out.append(ly.thickness)
    return out


def layered_surface_size(node_size, thicknesses, settings):
    """Element size (m) on the loaded surface inside the layers: the radial grading rule.

    h = clip(t_min / layer_radial_elements, node_size / max_layer_refinement, node_size),
    node_size = surface_fraction x node spacing, t_min the thinnest of ``thicknesses`` (the
    layers :func:`layers_needing_radial_resolution` selects): that layer gets
    ``layer_radial_elements`` elements per thickness along the loaded surface (the response to
    a pressure step in a soft or nearly incompressible layer changes over ~t), but the grid's
    own surface size is refined by at most ``max_layer_refinement``.
    """
    if not len(thicknesses):
        return node_size
    fine = min(thicknesses) / settings.layer_radial_elements
    return float(np.clip(fine, node_size / settings.max_layer_refinement, node_size))


def mesh_spec(grid, settings, layers=(), substrate=None):
    """The body's mesh for a grid: vertices at its nodes and annulus edges, far boundary at
    outer_factor x max(analysis radius, stack depth), surface elements surface_fraction x the
    node spacing (in the layers finer for thin soft ones, :func:`layered_surface_size`);
    ``layers`` (Layer, top first, on ``substrate``; or bare thicknesses in m) become
    interfaces."""
    thick = tuple(float(getattr(x, "thickness", x)) for x in layers)
    node_size = settings.surface_fraction * float(np.min(np.diff(grid.nodes)))
    fine = layered_surface_size(node_size, layers_needing_radial_resolution(layers, substrate),
                                settings)
    return MeshSpec(surface_points_of(grid),
                    settings.outer_factor * max(grid.radius, sum(thick)),
                    settings.growth, node_size, thick, int(settings.layer_min_elements),
                    fine if thick else None)
