"""Layered FE body: the layer description and the rule that meshes each layer through its
thickness.

A layer is a bonded isotropic slab of the body z <= 0, listed top first; below the last one
the substrate fills the rest of the half-space. In the mesh every interface is a mesh line and
every layer is a structured band of the surface-line columns (gmsh extrusion), so each layer's
vertical element size is set here, independently of its radial one.
"""
from dataclasses import dataclass
import math

import numpy as np


@dataclass(frozen=True)
class Layer:
    """One bonded elastic layer.

    Attributes
    ----------
    thickness : float
        t (m), > 0.
    youngs_modulus : float
        E (Pa), > 0.
    poisson_ratio : float
        nu, -1 < nu < 0.5 (see :data:`NU_LIMIT` for what the FE body accepts).
    """

    thickness: float
    youngs_modulus: float
    poisson_ratio: float

    def __post_init__(self):
        if not self.thickness > 0:
            raise ValueError(f"layer thickness must be > 0 m, got {self.thickness}")
        if not self.youngs_modulus > 0:
            raise ValueError(f"layer Young's modulus must be > 0 Pa, got {self.youngs_modulus}")
        if not -1.0 < self.poisson_ratio <= 0.5:
            raise ValueError(f"layer Poisson ratio must be in (-1, 0.5], got "
                             f"{self.poisson_ratio}")


def as_layer(x):
    """A :class:`Layer` from a Layer or a (thickness, E, nu) tuple."""
    return x if isinstance(x, Layer) else Layer(*(float(v) for v in x))


def layer_depths(thicknesses, surface_size, growth, min_elements):
    """Vertical element boundaries of every layer: the through-thickness grading rule.

    Rule: in a layer between depths z_top and z_bot the element height follows the substrate's
    own size law h(z) = h_s + growth * z (distance below the loaded surface), i.e. element
    boundaries are equally spaced in log(h_s + growth z); a layer gets
    n = max(min_elements, ceil(log((h_s + g z_bot)/(h_s + g z_top)) / g)) elements, so a layer
    thinner than the local size law still has ``min_elements`` P2 elements through it (height
    t / min_elements, whatever its radial size).

    Parameters
    ----------
    thicknesses : sequence of float
        Layer thicknesses, top first (any consistent length unit).
    surface_size : float
        h_s, the element size at the loaded surface (same unit).
    growth : float
        Size growth per unit depth (dimensionless).
    min_elements : int
        Least number of elements through any layer.

    Returns
    -------
    list of ndarray
        Per layer, the cumulative fractions (0, 1] of its thickness at each element bottom
        (what gmsh's extrusion ``heights`` takes).
    """
    out = []
    top = 0.0
    for t in thicknesses:
        lo, hi = surface_size + growth * top, surface_size + growth * (top + t)
        n = max(int(min_elements), math.ceil(math.log(hi / lo) / growth - 1e-9))
        # boundaries equally spaced in log(h_s + g z): heights grow like the size law
        z = (lo * (hi / lo) ** (np.arange(1, n + 1) / n) - lo) / growth
        frac = z / t
        frac[-1] = 1.0
        out.append(frac)
        top += t
    return out
