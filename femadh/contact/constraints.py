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
        Hertz-shaped contact pressure of eq (9) with the contact radius set by h(r_c) = sigma;
        eq (8) is then not enforced inside the contact and its violation is reported.
    """

    sigma: float
    contact_model: str = "complementarity"

    def __post_init__(self):
        if not self.sigma > 0:
            raise ValueError(f"sigma must be > 0 m, got {self.sigma}")
        if self.contact_model not in CONTACT_MODELS:
            raise ValueError(f"contact_model must be one of {CONTACT_MODELS}, got {self.contact_model!r}")
