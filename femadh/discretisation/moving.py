"""A band that follows a moving feature: the contact or cohesive-zone edge of a trace.

On the JKR side of the smooth-sphere problem the law acts in a cohesive zone ~ell wide at an
edge that travels hundreds of ell (mu = 20: ~1 z0 at a contact of ~800 z0); a static fine band
over the whole travel would cost nodes like mu^2. A :class:`MovingBand` is the member of the
banded family (:class:`~femadh.discretisation.family.GridFamily`) centred on the feature's
current position; the trace asks :meth:`MovingBand.regrid` after each point and gets a new
problem, leading the feature, once the feature has left the middle half of the band (the
state is carried over by the continuation, :func:`femadh.contact.arclength.trace_curve`).

The stepping continuation of a sigma-gap scene (:func:`femadh.contact.stepping.trace_steps`,
driven by the runner) follows the edge the same way when its [solver.grid] sets ``follow``
(the band's half-width): after each committed state and each landing the runner asks
:meth:`MovingBand.regrid` and carries the state to the new grid at the same separation
(:func:`carry_state`). A static band would have to cover the edge's whole travel at the
spacing the edge needs: the 2-mm slider at sigma = 0.3 nm, 3.6 nm over 5.6 um, 1830 nodes.
"""
import math

import numpy as np

from .family import GridFamily


def contact_edge(problem, w, d, gap):
    """Radius (m) of the contact edge: the outermost r where h(r) <= gap (linear between
    nodes); 0 when no node is that close."""
    h = problem.contour(d) - w
    close = np.flatnonzero(h <= gap)
    if not close.size:
        return 0.0
    k, r = int(close[-1]), problem.grid.nodes
    if k == r.size - 1:
        return float(r[-1])
    return float(r[k] + (gap - h[k]) / (h[k + 1] - h[k]) * (r[k + 1] - r[k]))


class MovingBand:
    """Problems on banded grids that follow a feature (all lengths in m).

    Parameters
    ----------
    radius, spacing, half, grading : float
        Analysis radius a, band spacing h (the family parameter), half-width of the band and
        grading length g (:class:`GridFamily`).
    build : callable(RadialGrid, first) -> ContactProblem
        The problem on a grid (``first``: the first grid of the trace, where the laws are
        checked).
    edge_gap : float
        The gap that marks the feature: the outermost r with h <= edge_gap
        (:func:`contact_edge`).
    fixed : float or None
        A fixed band [0, fixed] instead (the DMT side, where the edge travels less than the
        cohesive zone is wide): :meth:`regrid` never moves it.
    """

    def __init__(self, radius, spacing, half, grading, build, edge_gap, fixed=None):
        self.radius, self.spacing, self.half, self.grading = radius, spacing, half, grading
        self.build, self.edge_gap, self.fixed = build, edge_gap, fixed
        self.centers = {}

    def family(self, center):
        if self.fixed:
            return GridFamily(self.radius, self.fixed, self.grading)
        return follow_family(self.radius, self.half, self.grading, center)

    def problem(self, center=0.0):
        """The problem on the member whose band is centred on ``center``."""
        pb = self.build(self.family(center).member(self.spacing), not self.centers)
        self.centers[id(pb)] = center
        return pb

    def band_offset(self, problem, edge):
        """|edge - band centre| / band half-width on ``problem``'s grid (0 for a fixed band;
        above 1 the edge is outside the fine band)."""
        if self.fixed:
            return 0.0
        return abs(edge - self.centers[id(problem)]) / self.half

    def regrid(self, problem, w, d):
        """A grid whose band leads the edge, once the edge has left the band's middle half;
        None while it is inside."""
        if self.fixed:
            return None
        center = self.centers[id(problem)]
        edge = contact_edge(problem, w, d, self.edge_gap)
        if abs(edge - center) <= 0.5 * self.half:
            return None
        # lead the moving edge: it crosses the whole band before the next exchange
        return self.problem(edge + math.copysign(0.5 * self.half, edge - center))


def interpolate_state(old, new, d, w):
    """Displacements ``w`` (m) on ``old``'s grid, interpolated linearly in r onto ``new``'s
    grid, and the contact set they imply there (gap within 1e-9 of sigma; none without a
    gap constraint). The gaps are kept at sigma or above (the interpolated surface may not
    cut into the floor between two contact nodes)."""
    w = np.interp(new.grid.nodes, old.grid.nodes, w)
    if new.sigma is None:
        return w, None
    b = new.contour(d)
    w = np.minimum(w, b - new.sigma)
    return w, (b - w) <= new.sigma * (1 + 1e-9)


def carry_state(old, new, state, *, tol, max_iter):
    """The equilibrium at ``state.d`` on ``new``'s grid, from ``state`` (an equilibrium on
    ``old``'s grid): Newton from the interpolated displacements and contact set
    (:func:`interpolate_state`), or the energy-descent landing from them if Newton ends
    elsewhere than on a stable state. Returns the State (converged and stable, or as the
    landing left it: the caller checks)."""
    from ..contact.complementarity import solve_complementarity
    from ..contact.landing import land

    w0, active0 = interpolate_state(old, new, state.d, state.w)
    st = solve_complementarity(new, state.d, w0, tol=tol, max_iter=max_iter, active0=active0)
    if st.converged and st.stable:
        return st
    return land(new, state.d, w0, tol=tol, max_iter=max_iter)


def follow_family(radius, half, grading, center):
    """The member family whose band [center - half, center + half] (clipped to [0, radius])
    surrounds a feature at radius ``center`` (m)."""
    return GridFamily(radius, min(radius, max(center, 0.0) + half), grading,
                      inner=max(center, 0.0) - half)


class EdgeBand(MovingBand):
    """A band that follows the features of a stepping sweep (all lengths in m).

    The band spans [lo - half, hi + half] (clipped to [0, radius]): ``lo`` the outermost
    radius where the gap is at most ``inner_gap`` (the contact or cohesive-zone edge: the
    smallest feature gap of the laws), ``hi`` where it is at most ``edge_gap`` (the largest:
    a meniscus edge far out at high humidity, or the cohesive zone's outer end). Where the
    two coincide (LJ alone, a meniscus at low humidity) it is a band of width 2 half around
    the edge; where they are far apart it covers both and what lies between.

    :meth:`regrid` gives a new problem once ``lo`` or ``hi`` has moved more than half a
    half-width from where the band was built for; the new band leads each moving edge by
    half a half-width (it crosses the band's middle before the next exchange).
    """

    def __init__(self, radius, spacing, half, grading, build, edge_gap, inner_gap):
        super().__init__(radius, spacing, half, grading, build, edge_gap)
        self.inner_gap = min(inner_gap, edge_gap)
        self.spans = {}

    def span_family(self, lo, hi):
        """The family whose band is [lo - half, hi + half] (clipped)."""
        lo, hi = max(lo, 0.0), max(hi, lo, 0.0)
        return GridFamily(self.radius, min(self.radius, hi + self.half), self.grading,
                          inner=lo - self.half)

    def problem(self, lo=0.0, hi=None):
        """The problem on the member whose band surrounds the edges lo and hi (m)."""
        hi = lo if hi is None else hi
        pb = self.build(self.span_family(lo, hi).member(self.spacing), not self.spans)
        self.spans[id(pb)] = (lo, hi)
        self.centers[id(pb)] = 0.5 * (lo + hi)
        return pb

    def edges(self, problem, w, d):
        """(lo, hi): the radii (m) of the inner and outer feature edges of a state."""
        return (contact_edge(problem, w, d, self.inner_gap),
                contact_edge(problem, w, d, self.edge_gap))

    def band_offset(self, problem, edge):
        """How far (in half-widths) ``edge`` lies beyond the span the band was built for (0
        inside it; above 1 the edge is outside the fine band)."""
        lo, hi = self.spans[id(problem)]
        return max(0.0, lo - edge, edge - hi) / self.half

    def regrid(self, problem, w, d):
        """A grid whose band leads the moving edges, once either has moved more than half a
        half-width from where the band was built; None while both are within it."""
        lo0, hi0 = self.spans[id(problem)]
        lo, hi = self.edges(problem, w, d)
        lim = 0.5 * self.half
        if abs(lo - lo0) <= lim and abs(hi - hi0) <= lim:
            return None

        def lead(x, x0):
            return x + math.copysign(lim, x - x0) if abs(x - x0) > lim else x
        return self.problem(lead(lo, lo0), lead(hi, hi0))
