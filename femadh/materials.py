"""Elastic materials and the composite modulus of paper 1, eq (2)."""
from dataclasses import dataclass


@dataclass(frozen=True)
class IsotropicMaterial:
    """Linear isotropic elastic solid.

    Attributes
    ----------
    youngs_modulus : float
        E (Pa), > 0.
    poisson_ratio : float
        nu, -1 < nu < 0.5.
    """

    youngs_modulus: float
    poisson_ratio: float

    def __post_init__(self):
        if not self.youngs_modulus > 0:
            raise ValueError(f"youngs_modulus must be > 0 Pa, got {self.youngs_modulus}")
        if not -1.0 < self.poisson_ratio < 0.5:
            raise ValueError(f"poisson_ratio must be in (-1, 0.5), got {self.poisson_ratio}")

    @property
    def plane_strain_modulus(self):
        """E / (1 - nu^2) (Pa): the half-space's surface stiffness measure."""
        return self.youngs_modulus / (1.0 - self.poisson_ratio**2)


def composite_modulus(m1, m2=None):
    """Composite Young's modulus E* (Pa), paper 1 eq (2).

    1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2. With one material the other body is rigid.
    """
    inv = 1.0 / m1.plane_strain_modulus
    if m2 is not None:
        inv += 1.0 / m2.plane_strain_modulus
    return 1.0 / inv
