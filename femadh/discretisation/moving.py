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
There the band spans the contact edge to the cohesive zone's end (:func:`zone_gap`) and,
given the sweep's grid step, leads the edges' travel over the next grid steps
(:meth:`EdgeBand._travel_regrid`); the adaptive plan chooses it where the static band is too
large (:func:`femadh.runner.adaptive._follow_trial`; validation/results/sigma03_follow.md).
"""
import math

import numpy as np

from .family import GridFamily

#: the band's outer feature edge: the gap where the laws' softening at the contact edge has
#: fallen to this fraction of its largest (the cohesive zone's outer end; LJ's h^-4 softening:
#: 10^(1/4) sigma). A smoothed step (the meniscus) counts by its secant softening from the
#: floor across its edge, and only where that is this fraction of the largest: at
#: p/psat = 0.05 on sigma = 0.3 nm its edge (0.36 nm) is part of the zone; at p/psat = 0.95
#: it lies 23 nm up the gap, microns out, where the graded spacing resolves it (the sub-grid
#: quadrature integrates the step exactly on the interpolated gaps)
ZONE_FRACTION = 0.1
#: a travel-aware band (:class:`EdgeBand` with ``step``) is exchanged when the edge's
#: predicted travel over the next NEED_STEPS grid steps would take it closer than half a
#: half-width to the band's fine span's end, and the new band covers LEAD_STEPS grid steps
#: of that travel ahead (fewer exchanges than one per step; measured on the stiction map's
#: sigma = 0.3 nm corner, the edge moves 50-250 nm per 0.2-nm grid step, fastest near the
#: pull-off: a band that only led by half a half-width let the edge run into the graded
#: part within a grid step, where it unzipped node by node)
NEED_STEPS, LEAD_STEPS = 1.25, 2.5
#: ... and rebuilt narrower once its span exceeds this multiple of the span it would be built
#: with now (a fast phase is over: its nodes are no longer needed)
SHRINK_RATIO = 2.0
#: the static band [0, band] a failed landing on a follow band falls back to
#: (:func:`femadh.runner.tracing.trace_steps`) is built only up to this many nodes: at the
#: band spacing a cohesive zone of tens of nm needs (1.8-3.8 nm on the sigma = 0.3 nm column)
#: it would hold 3234 nodes over 12 um, measured 37 s for the carry alone at load 8 and
#: minutes per grid step; the landing's failure is reported instead
WIDEN_MAX_NODES = 1000


def zone_gap(effects, floor):
    """The outer end (m) of the cohesive zone at a contact edge on the floor gap: the largest
    gap where a collocated law's softening -P'(h) is at least ZONE_FRACTION of the largest
    softening there, or a smoothed step's edge h_c + 2w where its secant softening from the
    floor (:meth:`~femadh.laws.step.SmoothStepLaw.edge_softening`) is; ``floor`` without
    laws."""
    from ..laws.step import SmoothStepLaw

    h = floor * np.logspace(0, 3, 1500)
    soft, edges = [], []
    for law in effects.values():
        if isinstance(law, SmoothStepLaw):
            edges.append((law.edge_softening(floor), law._center + 2.0 * law.width))
        else:
            s = -np.asarray(law.dpressure(h), float)
            soft.append(s)
    top = max([float(np.max(s)) for s in soft] + [e for e, _ in edges] + [0.0])
    if not (top > 0 and math.isfinite(top)):
        return float(floor)
    out = float(floor)
    for s in soft:
        ok = np.flatnonzero(s >= ZONE_FRACTION * top)
        if ok.size:
            out = max(out, float(h[ok[-1]]))
    for e, gap in edges:
        if e >= ZONE_FRACTION * top:
            out = max(out, float(gap))
    return out


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

    def __init__(self, radius, spacing, half, grading, build, edge_gap, inner_gap,
                 step=None):
        super().__init__(radius, spacing, half, grading, build, edge_gap)
        self.inner_gap = min(inner_gap, edge_gap)
        self.spans = {}
        #: the sweep's grid step (m): the band leads the edges' travel (:meth:`regrid`)
        self.step = step
        self.track = None          # (d, lo, hi) of the last state seen on the branch
        self.move = None           # the edges' last travel over one grid step (m, signed)

    def widen_affordable(self, band):
        """Whether the static band [0, ``band``] (m) at this band's spacing and grading has
        at most WIDEN_MAX_NODES nodes (the fallback of a failed landing)."""
        return GridFamily(self.radius, min(band, self.radius), self.grading).count(
            self.spacing) <= WIDEN_MAX_NODES

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

    def regrid(self, problem, w, d, landed=False):
        """A grid whose band leads the moving edges, once either has moved more than half a
        half-width from where the band was built; None while both are within it.

        With ``step`` (the travel-aware band) the rule is the edges' predicted travel
        instead (:meth:`_travel_regrid`); ``landed``: the state is a landing after a fold
        (the edge jumped: no travel is read from it)."""
        if self.step:
            return self._travel_regrid(problem, w, d, landed)
        lo0, hi0 = self.spans[id(problem)]
        lo, hi = self.edges(problem, w, d)
        lim = 0.5 * self.half
        if abs(lo - lo0) <= lim and abs(hi - hi0) <= lim:
            return None

        def lead(x, x0):
            return x + math.copysign(lim, x - x0) if abs(x - x0) > lim else x
        return self.problem(lead(lo, lo0), lead(hi, hi0))

    def _travel(self, d, lo, hi, landed):
        """(move_lo, move_hi): the edges' predicted signed travel over the next grid step (m),
        from their travel since the last state seen (scaled to a grid step); after a landing,
        a resume or at the start, the last travel's size in both directions (None: none)."""
        prev, self.track = self.track, (d, lo, hi)
        if prev is not None and not landed and abs(d - prev[0]) > 0:
            scale = self.step / abs(d - prev[0])
            self.move = ((lo - prev[1]) * scale, (hi - prev[2]) * scale)
            return self.move
        if landed:
            self.track = None      # the jump is no travel: the next state starts a track
        return None

    def _travel_regrid(self, problem, w, d, landed):
        """The travel-aware exchange: None while the band's fine span holds both edges with
        half a half-width to spare over their predicted travel of NEED_STEPS grid steps (and
        is not more than SHRINK_RATIO too wide); else the problem whose span covers the
        travel of LEAD_STEPS grid steps ahead."""
        lo0, hi0 = self.spans[id(problem)]
        lo, hi = self.edges(problem, w, d)
        move = self._travel(d, lo, hi, landed)

        def span(k):
            if move is None:
                # direction unknown: the last travel's size both ways (none yet: the edges
                # themselves - the sweep's first states, before any contact)
                m = max(abs(x) for x in self.move) if self.move else 0.0
                return lo - k * m, hi + k * m
            return (min(lo, lo + k * move[0]), max(hi, hi + k * move[1]))
        need, lead = span(NEED_STEPS), span(LEAD_STEPS)
        # the band's fine part is [lo0 - half, hi0 + half] (clipped to [0, radius])
        inside = (need[0] - 0.5 * self.half >= lo0 - self.half or lo0 - self.half <= 0) and \
            need[1] + 0.5 * self.half <= hi0 + self.half
        wide = (hi0 - lo0) > SHRINK_RATIO * (lead[1] - lead[0]) + 2 * self.half
        if inside and not wide:
            return None
        return self.problem(max(lead[0], 0.0), lead[1])
