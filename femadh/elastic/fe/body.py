"""What the FE operator condenses: the elastic body (a homogeneous half-space, or a layer stack
on a substrate half-space), the sphere whose own compliance is added, and the formulation the
regions' Poisson ratios call for."""
from dataclasses import dataclass

from ...materials import IsotropicMaterial
from .layers import as_layer
from .settings import NU_DISPLACEMENT_MAX, NU_LIMIT


@dataclass(frozen=True)
class FEBody:
    """The body of an :class:`~femadh.elastic.fe.operator.FEOperator`.

    Build it with :meth:`homogeneous` or :meth:`layered`.

    Attributes
    ----------
    substrate : IsotropicMaterial
        The half-space below the layers (the whole body when there are none).
    layers : tuple of Layer
        Top first.
    sphere : IsotropicMaterial or None
        Elastic sphere (its half-space Green compliance is added to the body's) or None
        (rigid, or already inside a composite modulus).
    e_star : float or None
        Composite modulus E* (Pa) of the homogeneous body (paper 1 eq 2), else None.
    """

    substrate: IsotropicMaterial
    layers: tuple = ()
    sphere: IsotropicMaterial = None
    e_star: float = None

    def __post_init__(self):
        for i, (_, nu_i) in enumerate(self.materials):
            _check_nu(nu_i, "substrate" if i == len(self.layers) else f"layer {i}")

    @classmethod
    def homogeneous(cls, e_star, nu=0.3):
        """The half-space of the pair's composite modulus E* (Pa): Young's modulus
        E* (1 - nu^2), Poisson ratio nu (the surface normal compliance of a half-space depends
        on E/(1 - nu^2) only; nu shapes the interior field)."""
        e_star, nu = float(e_star), float(nu)
        return cls(IsotropicMaterial(e_star * (1 - nu**2), nu), (), None, e_star)

    @classmethod
    def layered(cls, substrate, layers=(), sphere=None):
        """A layer stack (Layer or (thickness m, E Pa, nu), top first) bonded on the
        ``substrate`` half-space (IsotropicMaterial or (E, nu)); ``sphere`` (material or None
        for rigid) adds its own Green compliance. ``layers=()``: the bare substrate."""
        if not isinstance(substrate, IsotropicMaterial):
            substrate = IsotropicMaterial(*substrate)
        if sphere is not None and not isinstance(sphere, IsotropicMaterial):
            sphere = IsotropicMaterial(*sphere)
        return cls(substrate, tuple(as_layer(x) for x in layers), sphere, None)

    @property
    def materials(self):
        """(E Pa, nu) per region: the layers top first, then the substrate (region id =
        index)."""
        return ([(ly.youngs_modulus, ly.poisson_ratio) for ly in self.layers]
                + [(self.substrate.youngs_modulus, self.substrate.poisson_ratio)])

    def formulation(self, choice="auto"):
        """The formulation used for ``choice`` (FESettings.formulation): "auto" takes the
        mixed one when a region has nu > NU_DISPLACEMENT_MAX (plain P2 locks in confined
        nearly incompressible layers)."""
        if choice != "auto":
            return choice
        nu_max = max(nu_i for _, nu_i in self.materials)
        return "mixed" if nu_max > NU_DISPLACEMENT_MAX else "displacement"


def _check_nu(nu, what):
    if not nu <= NU_LIMIT:
        raise ValueError(
            f"{what}: Poisson ratio {nu} is above the FE body's limit {NU_LIMIT}: the mixed "
            f"formulation eliminates the pressure with a finite lambda = E nu/((1+nu)(1-2nu)); "
            f"use nu <= {NU_LIMIT} (the incompressible limit is reached to ~(0.5 - nu))")
