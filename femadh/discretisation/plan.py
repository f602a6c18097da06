"""Which member of which family a scene needs: planned from its laws and sweep, steered by the
error estimate.

- **Band** [0, r_b]: every r where the gap reaches the laws' short-scale features during the
  sweep. A law's feature gap H is the largest gap at which its stiffness |P'(h)| is still
  FEATURE_FRACTION of its largest over the reachable gaps (h >= sigma, or the repulsive gap of
  a smooth law): 10^(1/2) sigma for LJ's h^-4 softening, the fill gap for a capillary
  meniscus edge. On the rigid contour at the deepest separation, b(r_b; d_min) = H, widened by
  BAND_MARGIN for the surface's own deformation (the contact edge of the Fig 4 scene sits at
  0.73 of the rigid r(H); the edge is checked after the run and the band widened if it left).
- **Analysis radius** a: the smallest doubling of the scene's own radius at which the laws'
  force beyond it on the undeformed contour (the tail, exact for the paraboloid) is at most
  TAIL_SHARE of the requested accuracy of the adhesion scale 2 pi R W: in a graded family
  the far field costs a few nodes, so truncation is not left to dominate the error (it was
  8.5e-3 of the Fig 3 scene's largest adhesion on the uniform a = 6.3 um disk).
- **Spacing** h: a node in the band must not snap on its own (its surface-force softening
  below its own stiffness: lattice trapping) - not in the fine member, and not in the coarser
  members of the estimate either; within that, h starts at BAND_NODES per band and is refined
  by the estimate.
"""
from dataclasses import dataclass
import math

import numpy as np

from .family import GridFamily

#: a law's feature ends where |P'(h)| falls to this fraction of its largest reachable value
FEATURE_FRACTION = 1e-2
#: the band reaches this multiple of the rigid contour's feature radius
BAND_MARGIN = 1.15
#: the tail beyond the analysis radius may be this share of the requested accuracy
TAIL_SHARE = 0.05
#: doublings of the analysis radius the tail planning may make
MAX_RADIUS_DOUBLINGS = 12
#: nodes across the band of the first member (refined by the estimate from there)
BAND_NODES = 150
#: grading length over the band radius: the spacing beyond the band grows by ~h per g
GRADING_FRACTION = 0.05
#: node softening over node stiffness (at the floor gap, band nodes) the coarsest member of
#: an estimate may reach. The guard refuses 1.0 on the states; measured on the Fig 4 scene
#: (sigma = 0.5 nm): the uniform N = 100 member (0.47) already lands micro-jump after
#: micro-jump and made its estimate 10x pessimistic, N = 200 (0.24) is clean; the banded
#: member at 94 nm (0.53) is 1.9e-2 off against 2e-3 at 67 nm (0.38)
TRAP_SAFE = 0.3


#: the fine member's ratio of a sub-grid step's secant softening (edge_softening) to a band
#: node's stiffness at which :func:`safe_spacing` caps the spacing (measured on the stiction
#: map's fine members: clean traces at up to 0.29, node-by-node unzipping at 0.53 and 0.86)
STEP_SAFE = 0.3


def reach_floor(effects, sigma):
    """Smallest gap (m) the surfaces reach: sigma with the gap constraint, else the largest
    gap where the summed laws turn repulsive (~z0 for LJ)."""
    if sigma is not None:
        return float(sigma)
    scan = np.logspace(-7, -11, 4000)
    total = sum(e.pressure(scan) for e in effects.values()) if effects else 0 * scan
    rep = np.flatnonzero(total < 0)
    return float(scan[rep[0]]) if rep.size else float(scan[-1])


def _scan(floor):
    return floor * np.logspace(0, 4, 1200)


def feature_gap(effects, floor):
    """Largest feature gap H (m) of the laws: per law the largest gap where |P'(h)| is
    FEATURE_FRACTION of its largest over h >= floor; the floor itself without laws."""
    h = _scan(floor)
    out = floor
    for law in effects.values():
        stiff = np.abs(law.dpressure(h))
        top = float(np.max(stiff))
        if top > 0 and math.isfinite(top):
            out = max(out, float(h[np.flatnonzero(stiff >= FEATURE_FRACTION * top)[-1]]))
    return out


def band_radius(sphere, gap, d_min, radius):
    """Radius (m) where the rigid contour at the deepest separation d_min reaches ``gap``,
    times BAND_MARGIN, within (0, radius]."""
    s = gap - d_min
    if s <= 0:
        return min(radius, BAND_MARGIN * 1e-3 * radius)
    R = sphere.radius
    r = math.sqrt(2 * R * s) if sphere.profile == "paraboloid" else math.sqrt(
        min(s, R) * (2 * R - min(s, R)))
    return min(radius, BAND_MARGIN * r)


def tail_force(effects, sphere, radius, d):
    """Force (N, attractive positive) of the laws beyond ``radius`` on the undeformed contour
    at separation d: -2 pi R U(b(a; d)) (paper 1 eq 3 integrated, exact for the paraboloid)."""
    h_a = np.array([d + float(sphere.shape(radius))])
    return float(-2 * math.pi * sphere.radius * sum(np.asarray(e.energy(h_a))[0]
                                                    for e in effects.values()))


def work_of_adhesion(effects, floor):
    """-sum U(floor) (J/m^2): the laws' energy per area to separate from the floor gap."""
    h = np.array([floor])
    return float(-sum(np.asarray(e.energy(h))[0] for e in effects.values()))


def tail_delta(effects, sphere, radius, d_min, target, floor):
    """The analysis radius (m): ``radius`` doubled until the tail at d_min is at most
    TAIL_SHARE * target of 2 pi R W (W the work of adhesion from the floor); ``radius``
    itself without adhesive laws. Doubled no further than R (the exact sphere: 0.5 R, its cap
    ends at R; the paraboloid of eq 4 is a sphere only for r << R, and a scene's radius must
    stay below R): a small tip keeps the rest of its tail as F_tail, exact for the
    paraboloid, and the estimate's tail part."""
    if not effects:
        return radius
    scale = 2 * math.pi * sphere.radius * abs(work_of_adhesion(effects, floor))
    if scale <= 0:
        return radius
    cap = 0.5 * sphere.radius if sphere.profile == "sphere" else sphere.radius
    a = radius
    for _ in range(MAX_RADIUS_DOUBLINGS):
        if abs(tail_force(effects, sphere, a, d_min)) <= TAIL_SHARE * target * scale or \
                2 * a > cap:
            break
        a *= 2
    return a


def trapping_ratio(problem):
    """max over the band's nodes of the laws' largest reachable softening -P'(h) over the
    node's own stiffness K_kk (the guard's ratio, restricted to where gaps reach the floor:
    the graded far field never comes close).

    Smoothed steps (a capillary meniscus edge) are left out: their softening P0/(4w) is set
    by the smoothing width w, a regularisation of a sharp edge, not by a length the grid must
    resolve (at p/psat = 0.05 it would ask for sub-nm spacing over a 5 um band); a node
    crossing such an edge alone moves the edge by one spacing, which the estimate sees.
    A sub-grid step (the capillary condensate) counts instead by its secant softening from
    the floor across the edge (:meth:`~femadh.laws.step.SmoothStepLaw.edge_softening`): a
    meniscus edge just above sigma is a cohesive zone at the contact edge, and a spacing
    comparable to that zone unzips the contact node by node (the stiction map's
    low-humidity points, validation/results/stiction_map.md)."""
    from ..laws.step import SmoothStepLaw

    floor = reach_floor(problem.effects, problem.sigma)
    h = _scan(floor)[:600]
    soft = 0.0
    for law in problem.effects.values():
        if not isinstance(law, SmoothStepLaw):
            soft = max(soft, float(np.max(-law.dpressure(h))))
        elif getattr(law, "SUBGRID", False) and problem.sigma is not None:
            # scaled so that safe_spacing puts the fine member at STEP_SAFE
            soft = max(soft, law.edge_softening(floor)
                       * TRAP_SAFE / MIN_MEMBER_RATIO**2 / STEP_SAFE)
    # the band's nodes: [0, r_b] of a static band; a band that follows the edge is coarse
    # towards the centre (its nodes there are inside the contact, pinned), so only the
    # nodes of the band's own spacing count
    grid = problem.grid
    fine = grid.fine if grid.nodes[1] <= 1.02 * float(np.min(np.diff(grid.nodes))) \
        else problem.finest_nodes
    k = np.diag(problem.K)[fine]
    return float(max(soft, 0.0) / np.min(k))


def trapping_spacing(problem, limit=TRAP_SAFE):
    """Band spacing (m) at which the trapping ratio reaches ``limit``: the ratio grows like
    the spacing (K_kk ~ E*/h up to a logarithm), measured on the problem's own grid."""
    ratio = trapping_ratio(problem)
    h = float(problem.grid.nodes[1])
    return math.inf if ratio <= 0 else h * limit / ratio


#: smallest spacing ratio between the members of an estimate (Richardson divides by r^p - 1)
MIN_MEMBER_RATIO = 2.0**0.5


def member_ratio(problem):
    """Spacing ratio r of an estimate's members: MIN_MEMBER_RATIO = sqrt 2 (members at
    sqrt2 h and 2 h). Measured on the Fig 3 scene: with r = 2 the 4h member has ~10 nodes
    across a 40-node band, is pre-asymptotic, and the estimate of F_LJ at the deepest state
    was 20x the true error (sqrt 2: 1.2-2.8x); the members cost 0.35 + 0.13 of the solve.
    The adaptive plan keeps h fine enough that the 2h member is below TRAP_SAFE
    (:func:`safe_spacing`); an explicit grid coarser than that still gets sqrt 2."""
    return MIN_MEMBER_RATIO


def safe_spacing(problem):
    """Largest band spacing (m) whose estimate members at ratio MIN_MEMBER_RATIO stay below
    TRAP_SAFE (the coarsest is twice as coarse)."""
    return trapping_spacing(problem, TRAP_SAFE / MIN_MEMBER_RATIO**2)


@dataclass(frozen=True)
class GridPlan:
    """A planned family, the member's spacing and why (lengths in m)."""

    family: GridFamily
    spacing: float
    feature_gap: float
    d_min: float

    def grid(self):
        return self.family.member(self.spacing)

    def nodes(self):
        return self.family.count(self.spacing)


def plan_grid(effects, sigma, sphere, radius, d_values, target, nodes=BAND_NODES):
    """The first member for a scene's laws, sphere and sweep (see the module docstring);
    the trapping limit is applied by the caller once the member's stiffness is known."""
    floor = reach_floor(effects, sigma)
    d_min = float(min(d_values))
    a = tail_delta(effects, sphere, radius, d_min, target, floor)
    H = feature_gap(effects, floor)
    band = band_radius(sphere, H, d_min, a)
    fam = GridFamily(a, band, GRADING_FRACTION * band)
    return GridPlan(fam, band / nodes, H, d_min)


#: a band that follows the contact edge: the real nodal ratio (:func:`edge_trapping_ratio`)
#: its coarsest estimate member (twice the fine spacing) may reach - the measured limit of
#: clean traces (STEP_SAFE)
EDGE_SAFE = STEP_SAFE


def edge_trapping_ratio(problem):
    """The softening a band node at the contact edge meets, over its own stiffness: the
    collocated laws' -P'(floor) plus each sub-grid step's secant softening from the floor
    across its edge (:meth:`~femadh.laws.step.SmoothStepLaw.edge_softening`), summed - both
    act at the same edge when a meniscus edge lies just above sigma - over min K_kk of the
    finest nodes.

    Unlike :func:`trapping_ratio` (which keeps the larger of the two, the step's scaled, as
    the static plan was measured with) this is the ratio a node actually meets: on the
    stiction map's sigma = 0.3 nm, p/psat = 0.05 corner, LJ 1.80e18 Pa/m and the meniscus
    step 2.07e18 Pa/m against K_kk = 7.6e18 Pa/m at 6 nm: 0.51, where the retract unzipped
    node by node (validation/results/sigma03_follow.md); the static measure says 0.24."""
    from ..laws.step import SmoothStepLaw

    floor = reach_floor(problem.effects, problem.sigma)
    soft = 0.0
    for law in problem.effects.values():
        if isinstance(law, SmoothStepLaw):
            if getattr(law, "SUBGRID", False) and problem.sigma is not None:
                soft += law.edge_softening(floor)
            continue
        soft += max(0.0, float(np.max(-law.dpressure(_scan(floor)[:600]))))
    k = np.diag(problem.K)[problem.finest_nodes]
    return float(soft / np.min(k))


def follow_safe_spacing(problem):
    """Largest band spacing (m) of a band following the edge whose coarsest estimate member
    (MIN_MEMBER_RATIO^2 coarser) stays at EDGE_SAFE (:func:`edge_trapping_ratio`; the ratio
    grows like the spacing, measured on the problem's own finest spacing)."""
    ratio = edge_trapping_ratio(problem)
    h = float(np.min(np.diff(problem.grid.nodes)))
    return math.inf if ratio <= 0 else h * EDGE_SAFE / MIN_MEMBER_RATIO**2 / ratio
