"""The minimum gap set by compressed asperities, paper 1 eq (8): h(r) >= sigma."""
from dataclasses import dataclass

CONTACT_MODELS = ("complementarity", "hertz-closure")


@dataclass(frozen=True)
class AsperityGap:
    """Constraint h >= sigma between the sphere and the disk's mean plane.

    Attributes
    ----------
    sigma : float
        Spacing of the mean height planes in contact (m), > 0.
    contact_model : str
        ``"complementarity"``: h >= sigma, contact pressure >= 0, their product 0 (eq 8),
        solved exactly by a semismooth Newton method. ``"hertz-closure"``: the paper's
        Hertz-shaped contact pressure of eq (9), contact radius with h(r_c) = sigma; eq (8)
        clamped inside, eq (10) not, its violation reported.
    adhesion : float
        P_LJa (Pa) of paper 1 eq (20) acting on the contact set only (range-less): with the
        complementarity model a contact node holds a net tension up to P_LJa before it
        releases (h >= sigma, lambda >= 0, lambda (h - sigma) = 0 for the asperities'
        elastic pressure lambda, with P_LJa added where h = sigma); the closure applies it over
        r < r_c. 0: no asperity adhesion.
    """

    sigma: float
    contact_model: str = "complementarity"
    adhesion: float = 0.0

    def __post_init__(self):
        if not self.sigma > 0:
            raise ValueError(f"sigma must be > 0 m, got {self.sigma}")
        if self.contact_model not in CONTACT_MODELS:
            raise ValueError(f"contact_model must be one of {CONTACT_MODELS}, "
                             f"got {self.contact_model!r}")
        if not self.adhesion >= 0:
            raise ValueError(f"adhesion must be >= 0 Pa, got {self.adhesion}")
