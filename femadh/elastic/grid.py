"""Radial node sets with their annuli (piecewise-constant pressure cells)."""
from dataclasses import dataclass
import math

import numpy as np


class NodeBudgetError(ValueError):
    """A grid refused for needing more nodes than its budget (``max_nodes``): the one refusal
    a caller may answer by a coarser request; any other ValueError of a grid is an error."""


@dataclass(frozen=True, eq=False)
class RadialGrid:
    """Collocation nodes r_k and the annuli [e_k, e_{k+1}] that carry their pressure.

    Attributes
    ----------
    nodes : ndarray, shape (N,)
        Node radii (m), increasing, nodes[0] == 0 (the central disk is collocated at its centre).
    edges : ndarray, shape (N+1,)
        Annulus edges (m), edges[0] == 0, edges[-1] == the analysis radius a.
    fine_radius : float or None
        Outer radius (m) of the band of finest nodes, where the surfaces come close (a graded
        grid coarsens beyond it, where the gaps stay large); None: the whole disk.
    """

    nodes: np.ndarray
    edges: np.ndarray
    fine_radius: float | None = None

    def __post_init__(self):
        r, e = np.asarray(self.nodes, float), np.asarray(self.edges, float)
        if r.ndim != 1 or e.shape != (r.size + 1,):
            raise ValueError("edges must have one more entry than nodes")
        if e[0] != 0.0 or np.any(np.diff(e) <= 0):
            raise ValueError("edges must start at 0 and increase strictly")
        if np.any(r < e[:-1]) or np.any(r >= e[1:]):
            raise ValueError("every node must lie inside its annulus [e_k, e_k+1)")

    @classmethod
    def uniform(cls, radius, n):
        """N nodes r_k = k*dr with dr = a/(N - 1/2); annuli edges half-way between nodes.

        Parameters
        ----------
        radius : float
            Analysis radius a (m), the outer edge of the last annulus.
        n : int
            Number of nodes N >= 2.
        """
        if n < 2:
            raise ValueError(f"need at least 2 nodes, got {n}")
        dr = radius / (n - 0.5)
        nodes = dr * np.arange(n)
        edges = np.concatenate([[0.0], dr * (np.arange(n) + 0.5)])
        edges[-1] = radius
        return cls(nodes, edges)

    @classmethod
    def graded(cls, radius, spacing, fine_radius, growth=1.08):
        """Uniform nodes of the given spacing up to fine_radius, then geometrically coarser.

        Parameters
        ----------
        radius : float
            Analysis radius a (m).
        spacing : float
            Node spacing (m) on [0, fine_radius].
        fine_radius : float
            Radius (m) up to which the spacing is uniform (where the contact edge can move).
        growth : float
            Ratio of successive spacings beyond fine_radius (> 1).
        """
        if not (spacing > 0 and growth > 1 and 0 < fine_radius):
            raise ValueError("need spacing > 0, fine_radius > 0 and growth > 1")
        m = int(math.floor(min(fine_radius, radius) / spacing))
        nodes = list(spacing * np.arange(m + 1))
        step = spacing
        while True:
            step *= growth
            # stop when the last annulus (half-way edge to a) would be narrower than the step
            if nodes[-1] + step + 0.5 * step * growth > radius:
                break
            nodes.append(nodes[-1] + step)
        if nodes[-1] >= radius:
            raise ValueError("the fine spacing does not fit inside the analysis radius")
        return cls.from_nodes(np.array(nodes), radius)

    @classmethod
    def banded(cls, radius, spacing, band, grading, max_nodes=20000):
        """A grid family fine in a band and coarsening linearly with the distance from it.

        The node spacing is Delta(r) = spacing * (1 + dist(r, band) / grading): uniform in
        the band [lo, hi], growing by about 1 + spacing/grading per node away from it
        (geometrically) on both sides, down to r = 0 and out to the analysis radius. Halving
        ``spacing`` at fixed ``grading`` halves Delta everywhere: the members of the family
        are refinements of one mesh density, as a Richardson estimate needs.

        Parameters
        ----------
        radius : float
            Analysis radius a (m).
        spacing : float
            Node spacing (m) in the band.
        band : (float, float)
            Radii (m) of the band (e.g. around the contact edge); clipped to [0, radius].
        grading : float
            Length (m) over which the spacing grows by ``spacing`` (> 0).
        max_nodes : int
            Budget: a :class:`NodeBudgetError` beyond it (spacing too fine for the domain).
        """
        lo, hi = max(0.0, float(band[0])), min(radius, float(band[1]))
        if not (spacing > 0 and grading > 0 and lo <= hi):
            raise ValueError("need spacing > 0, grading > 0 and band[0] <= band[1]")

        def delta(r):
            return spacing * (1.0 + max(lo - r, r - hi, 0.0) / grading)

        nodes = [0.0]
        while True:
            r = nodes[-1]
            # midpoint rule for the spacing function: symmetric coarsening on both sides
            step = delta(r + 0.5 * delta(r))
            # stop when the last annulus (half-way edge to a) would be narrower than the step
            if r + 1.5 * step > radius:
                break
            nodes.append(r + step)
            if len(nodes) > max_nodes:
                raise NodeBudgetError(f"banded grid needs more than {max_nodes} nodes "
                                      f"(spacing {spacing:.3g} m on a radius of {radius:.3g} m)")
        if len(nodes) < 2:
            raise ValueError("the spacing does not fit inside the analysis radius")
        return cls.from_nodes(np.array(nodes), radius, fine_radius=hi)

    @classmethod
    def from_nodes(cls, nodes, radius, fine_radius=None):
        """Annuli with edges half-way between the given nodes (nodes[0] must be 0)."""
        nodes = np.asarray(nodes, float)
        edges = np.concatenate([[0.0], 0.5 * (nodes[1:] + nodes[:-1]), [radius]])
        return cls(nodes, edges, fine_radius)

    @property
    def fine(self):
        """Mask of the nodes in the fine band (all nodes without one)."""
        if self.fine_radius is None:
            return np.ones(self.nodes.size, bool)
        return self.nodes <= self.fine_radius

    @property
    def n(self):
        return self.nodes.size

    @property
    def radius(self):
        """Analysis radius a (m)."""
        return float(self.edges[-1])

    @property
    def areas(self):
        """Annulus areas pi (e_{k+1}^2 - e_k^2) (m^2): the weights of force integrals."""
        e = self.edges
        return math.pi * (e[1:] ** 2 - e[:-1] ** 2)

    def force(self, pressure):
        """Force (N) of a piecewise-constant pressure field (Pa): sum p_k * area_k."""
        return float(np.dot(self.areas, pressure))
