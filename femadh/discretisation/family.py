"""A radial grid family that is fine where the surfaces come close and graded beyond.

The spacing function is Delta_h(r) = h * (1 + max(r - r_b, 0) / g): uniform h on the band
[0, r_b] that holds every place the solution varies on a short scale during the sweep (the
contact or cohesive-zone edge, the meniscus edge: they all travel inside it), growing linearly
with the distance beyond it (geometrically per node, by about 1 + h/g) out to the analysis
radius a, where the gaps are large and the pressures smooth. The family parameter is h alone:
at fixed (a, r_b, g) halving h halves Delta everywhere, so the members are refinements of one
mesh density - what a Richardson estimate needs - and a coarser member resolves the edge with
the same topology as the fine one. The far field costs (g/h) ln(1 + (a - r_b)/g) nodes, so a
large analysis radius (a negligible truncation tail) is cheap.
"""
from dataclasses import dataclass
import math

from ..elastic.grid import RadialGrid
# the largest member a family builds: the node limits' one home says why 4000
from ..estimate.refine import BANDED_MAX_NODES as MAX_NODES


@dataclass(frozen=True)
class GridFamily:
    """The family of banded grids of one scene (all lengths in m).

    Attributes
    ----------
    radius : float
        Analysis radius a.
    band : float
        Outer radius r_b of the band of uniform spacing [0, r_b].
    grading : float
        Length g over which the spacing beyond the band grows by h.
    inner : float
        Inner radius of the band (0: the band is the disk [0, band]; > 0: a band around a
        feature, graded towards the centre as well, :class:`MovingBand`).
    """

    radius: float
    band: float
    grading: float
    inner: float = 0.0

    def __post_init__(self):
        if not (self.radius > 0 and 0 < self.band <= self.radius and self.grading > 0
                and self.inner < self.band):
            raise ValueError(f"grid family needs inner ({self.inner:.3g} m) < band "
                             f"({self.band:.3g} m) <= radius ({self.radius:.3g} m) and "
                             f"grading > 0 ({self.grading:.3g} m)")

    def member(self, spacing):
        """The member of band spacing h = ``spacing`` (m) as a :class:`RadialGrid`.

        Raises ValueError beyond :data:`MAX_NODES` nodes."""
        return RadialGrid.banded(self.radius, spacing, (max(0.0, self.inner), self.band),
                                 self.grading, max_nodes=MAX_NODES)

    def count(self, spacing):
        """Node count of the member of band spacing h (m), from the spacing function
        (within a few nodes of :meth:`member`, without building it)."""
        far, lo = max(self.radius - self.band, 0.0), max(0.0, self.inner)
        return int(math.ceil((self.band - lo) / spacing
                             + self.grading / spacing * (math.log1p(far / self.grading)
                                                         + math.log1p(lo / self.grading))))

    def as_dict(self, spacing):
        """The [solver.grid] table of a member (SI, for scenes and summary.json)."""
        return {"spacing": spacing, "band": self.band, "grading": self.grading}
