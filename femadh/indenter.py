"""The rigid sphere's surface contour b(r; d), paper 1 eq (4)."""
from dataclasses import dataclass

import numpy as np

PROFILES = ("paraboloid", "sphere")


@dataclass(frozen=True)
class Sphere:
    """Rigid sphere of radius R whose tip sits at height d above the undeformed mean plane.

    Attributes
    ----------
    radius : float
        R (m).
    profile : str
        ``"paraboloid"``: b = d + r^2/(2R) (eq 4); ``"sphere"``: exact cap d + R - sqrt(R^2 - r^2).
    """

    radius: float
    profile: str = "paraboloid"

    def __post_init__(self):
        if not self.radius > 0:
            raise ValueError(f"radius must be > 0 m, got {self.radius}")
        if self.profile not in PROFILES:
            raise ValueError(f"profile must be one of {PROFILES}, got {self.profile!r}")

    def shape(self, r):
        """b(r; 0) (m): height of the contour above its tip."""
        r = np.asarray(r, float)
        if self.profile == "paraboloid":
            return r * r / (2.0 * self.radius)
        R = self.radius
        return r * r / (R + np.sqrt(R * R - r * r))  # = R - sqrt(R^2 - r^2), no cancellation

    def slope(self, r):
        """db/dr."""
        r = np.asarray(r, float)
        if self.profile == "paraboloid":
            return r / self.radius
        return r / np.sqrt(self.radius**2 - r * r)

    def contour(self, r, d):
        """b(r; d) = d + shape(r) (m), eq (4)."""
        return d + self.shape(r)
