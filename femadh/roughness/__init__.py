"""Roughness statistics of measured surfaces: spectral moments, McCool's summit statistics
(:mod:`.moments`), the composite of two surfaces (:mod:`.composite`), the check of a
spectrum's short-wavelength end (:mod:`.spectrum`) and the report of one or two topography
files (:mod:`.report`, used by ``femadh topography`` and by scenes naming ``topography``)."""
from .composite import composite, table2_rule
from .moments import SpectralMoments, mccool, profile_moments

__all__ = ["SpectralMoments", "profile_moments", "mccool", "composite", "table2_rule"]
