"""The smooth LJ sphere (no sigma-gap) as a building block: its problem at a Tabor parameter,
its deepest separation, its lateral length scales and its force with the exact tail.

Shared by the regime map (:mod:`femadh.studies.regime`), the peer benchmark, the layered-film
study in ``validation/`` and the tests. The Tabor parameter mu = (R dg^2 / (E*^2 z0^3))^(1/3)
with dg = A / (16 pi z0^2) (paper 1 eq 19) fixes E* at given R, A, z0.

One point of the map as a problem: :class:`PointSetup` (E* from mu, the analysis radius, the
lateral length ell, the band that follows the contact edge, where the trace starts and ends)
at a :class:`Resolution` (the grid family's spacing, band and grading in units of ell), traced
through its folds by :func:`trace_point`.

Grid (JKR side): the law acts in a cohesive zone at the contact edge whose width scales like the
elastocohesive length E* z0^2 / dg, while the contact radius grows like mu^(1/2): at mu = 20
(R = 1 um) the zone is ~1 z0 wide at a contact of ~800 z0. A node coarser than the zone snaps on
its own (lattice trapping: extra folds, an early jump-out). The grid is therefore a band of
uniform fine spacing around the *current* contact edge, coarsening linearly with the distance
from it (:meth:`RadialGrid.banded`), and it moves with the edge during the trace
(:class:`~femadh.discretisation.moving.MovingBand`). The lateral length that sets the spacing is
the smaller of the elastocohesive length and sqrt(R z0 / 8) (the DMT side, where the contact is
smaller than the cohesive zone and the law's range over the paraboloid sets the scale).
"""
from dataclasses import dataclass, replace
import math

import numpy as np

from ..contact import ContactProblem
from ..contact.arclength import trace_curve
from ..contact.complementarity import solve_complementarity
from ..contact.stability import is_positive_definite
from ..discretisation.moving import MovingBand, follow_family
from ..elastic import GreenOperator, RadialGrid
from ..errors import ConvergenceError
from ..estimate.guards import TRAPPING_LIMIT, trapping_message
from ..indenter import Sphere
from ..laws import LennardJones
from ..reference.adhesion import dmt_contact_radius, jkr_contact_radius
from ..reference.maugis import (jkr_approach, lj_dugdale_lambda, maugis_fixed_grip_pull_off,
                                maugis_length_units)

#: a priori: LJ softening stiffness below this fraction of a node's (fixed graded grid)
STIFFNESS_TARGET = 0.4
#: compressive load (units pi R dg) at the deepest point of a curve without folds (DMT side)
PRELOAD = 0.5
#: fixed graded grid: uniform spacing up to this multiple of the JKR radius at PRELOAD
FINE_MARGIN = 1.15


def lateral_length(law, radius, e_star):
    """ell (m): the smaller of the elastocohesive length E* z0^2/dg (cohesive-zone width at a
    JKR-like edge) and sqrt(R z0 / 8) (the gap of the rigid paraboloid grows by z0/16 over it:
    the DMT side, where the law's range, not the edge, sets the lateral scale)."""
    return min(e_star_length(law, e_star), math.sqrt(radius * law.z0 / 8))


def e_star_length(law, e_star):
    """Elastocohesive length E* z0^2 / dg (m)."""
    return e_star * law.z0**2 / law.work_of_adhesion


def lj_sphere_problem(mu, radius, hamaker, z0, stiffness_target, min_nodes):
    """The smooth-sphere problem at Tabor mu on a fixed graded grid: uniform fine spacing (set
    by the LJ softening stiffness against a node's) up to where the contact edge travels.

    Returns (problem, lj, e_star, a, d_min): a is the analysis radius (m), d_min the
    separation (m) of the deepest point, where the JKR load is PRELOAD pi R dg.
    """
    lj = LennardJones(hamaker, z0)
    dg = lj.work_of_adhesion
    e_star = math.sqrt(radius * dg * dg / (mu**3 * z0**3))
    a_unit = maugis_length_units(radius, e_star, dg)[0]
    a = max(4.32 * a_unit, math.sqrt(2 * radius * 20 * z0))
    a_max = jkr_contact_radius(PRELOAD * math.pi * radius * dg, radius, e_star, dg)
    d_min = deepest_separation(mu, radius, e_star, lj)
    # node self-stiffness scales like 1/spacing: calibrate it on a coarse uniform probe
    probe = ContactProblem(GreenOperator(RadialGrid.uniform(a, 60), e_star), Sphere(radius),
                           {"lj": lj})
    ratio0, _, _, _ = probe.surface_force_stiffness()
    dr = a / 59.5 * stiffness_target / ratio0
    if dr >= a / (min_nodes - 0.5):
        grid = RadialGrid.uniform(a, min_nodes)
    else:
        grid = RadialGrid.graded(a, dr, FINE_MARGIN * a_max)
    problem = ContactProblem(GreenOperator(grid, e_star), Sphere(radius), {"lj": lj})
    return problem, lj, e_star, a, d_min


def deepest_separation(mu, radius, e_star, law):
    """Separation (m) of the deepest point: where the load is PRELOAD pi R dg in the nearer
    limit (DMT below mu = 1, JKR above), from where the rigid sphere's force vanishes
    (U(d) = 0: d = z0 / 4^(1/6) for LJ)."""
    dg, z0 = law.work_of_adhesion, law.z0
    load = PRELOAD * math.pi * radius * dg
    if mu < 1:
        delta = dmt_contact_radius(load, radius, e_star, dg) ** 2 / radius
    else:
        delta = jkr_approach(jkr_contact_radius(load, radius, e_star, dg), radius, e_star, dg)
    return z0 / 4 ** (1 / 6) - delta


def lj_force(problem, lj, d, w):
    """Force on the disk (N, attractive positive) of a state: the law's pressure integrated
    over the analysis disk plus the tail beyond it, where the surface is undeformed and the
    paraboloid's force is exactly -2 pi R U(b(a; d)) (Derjaguin is exact for a paraboloid:
    2 pi r dr = 2 pi R dh)."""
    h = problem.contour(d) - w
    return problem.grid.force(problem.pressure(h)) + paraboloid_tail_force(
        lj, problem.sphere.radius, d, problem.grid.radius)


def paraboloid_tail_force(law, radius, d, a):
    """The force (N, attractive positive) of one law beyond the analysis radius a (m) of a
    paraboloid of radius R at separation d (m), where the surface is undeformed:
    -2 pi R U(d + a^2 / 2R) (Derjaguin, exact for a paraboloid). Not
    :func:`femadh.discretisation.plan.tail_force` (every law of a scene on its sphere's own
    contour, used to choose the analysis radius) nor :func:`femadh.contact.forces.tail_force`
    (a problem's laws)."""
    return -2 * math.pi * radius * float(law.energy(d + a * a / (2 * radius)))


#: analysis radius in units of Maugis' a_unit = (pi dg R^2 / K)^(1/3) (the rigid-LJ tail beyond
#: it is added to the force exactly); at least sqrt(2 R 20 z0) (the rigid gap there is 20 z0)
ANALYSIS_RADIUS = 8.0
#: banded grid family (lengths in units of the lateral length ell, see lateral_length):
#: band spacing (the family parameter), half-width of the fine band, and the grading length
#: over which the spacing grows by one band spacing
SPACING = 0.1
BAND = 4.0
GRADING = 2.0
#: above this Tabor parameter the band's half-width grows like mu: near the flat jump-out
#: fold the two grids of an exchange disagree on the side of the fold (measured at mu = 20,
#: band 4 ell: 43 exchanges refused while the edge travelled ~3 ell, and it left the band)
BAND_MU = 10.0
#: gap (units of z0) that marks the contact edge: the outermost r with h <= EDGE_GAP z0
EDGE_GAP = 1.5
#: the continuation's step control (:func:`~femadh.contact.arclength.trace_curve`): the
#: corrector may move a gap by about this fraction of itself, and the largest step (units of
#: z0, or 2 % of the start separation). Larger steps take fewer points (mu = 4: 154 instead
#: of 193 at 0.15 and 1.5) but move the contact edge further between grid exchanges (a
#: 1-ell band: the edge strays 0.87-1.05 half-widths from its centre instead of 0.65)
TRACE_CORRECTION = 0.05
DS_MAX = 0.5


@dataclass(frozen=True)
class Resolution:
    """Discretisation of one regime-map point.

    Attributes
    ----------
    spacing : float
        Fine-band node spacing / lateral length ell (the grid family's parameter).
    band, grading : float
        Half-width of the fine band (units of ell; x mu / BAND_MU beyond BAND_MU) and grading
        length (units of ell).
    analysis_radius : float
        Analysis radius in units of Maugis' a_unit (at least sqrt(40 R z0)).
    ds_max : float or None
        Largest continuation step (units of z0); None: from the trace's length.
    stiffness_target, min_nodes : float, int or None
        Legacy fixed graded grid (today's explicit settings, no moving band): when either is
        set the grid is :func:`~femadh.studies.smooth_sphere.lj_sphere_problem`'s and its
        coarser member has twice the spacing.
    follow_edge : bool
        On the JKR side, trace the contact branch on a grid whose nodes move with the edge
        (:func:`trace_edge_point`; the default); False: the whole curve by arclength on the
        moving band (:func:`trace_point`).
    edge_grading : float or None
        Grading length (units of ell) of the edge-following contact grid; None: EDGE_GRADING.
    """

    spacing: float = SPACING
    band: float = BAND
    grading: float = GRADING
    analysis_radius: float = ANALYSIS_RADIUS
    ds_max: float | None = None
    stiffness_target: float | None = None
    min_nodes: int | None = None
    follow_edge: bool = True
    edge_grading: float | None = None

    @property
    def legacy(self):
        return self.stiffness_target is not None or self.min_nodes is not None

    def coarser(self, factor=2.0):
        """A coarser member of the same grid family (spacing x factor)."""
        if self.legacy:
            return replace(self, stiffness_target=factor * (self.stiffness_target or
                                                            STIFFNESS_TARGET),
                           min_nodes=max(8, int((self.min_nodes or 120) / factor)))
        return replace(self, spacing=factor * self.spacing)

    def finer(self, factor=2.0):
        if self.legacy:
            return replace(self, stiffness_target=(self.stiffness_target or STIFFNESS_TARGET)
                           / factor, min_nodes=int((self.min_nodes or 120) * factor))
        return replace(self, spacing=self.spacing / factor)


#: laws whose derivative and energy have passed :func:`femadh.laws.check_law` in this process
#: (the check is a pure function of the law's parameters: a map point's members, its
#: coarser member and the points of a map share one law; ~1 ms each, a tenth of a small
#: point's solve)
_CHECKED = set()


def _checked(law):
    """True if this (hashable) law has passed the check in this process."""
    try:
        return law in _CHECKED
    except TypeError:       # a law that cannot be hashed is checked every time
        return False


def _remember(law):
    try:
        _CHECKED.add(law)
    except TypeError:
        pass


#: PointSetup's ``fixed_grip`` when the caller has not solved Maugis-Dugdale for this mu
COMPUTE = object()


def md_fixed_grip(mu):
    """Maugis-Dugdale's fixed-grip pull-off (-P, D) at the lambda of Tabor parameter mu
    (:func:`~femadh.reference.maugis.maugis_fixed_grip_pull_off`; None below lambda 0.938):
    a scan of its curve, ~0.4 ms, solved once per map point and handed to its members'
    :class:`PointSetup`."""
    return maugis_fixed_grip_pull_off(lj_dugdale_lambda(mu))


class PointSetup:
    """Physical problem of one map point and the grids of one resolution. ``fixed_grip``:
    :func:`md_fixed_grip` of this mu if the caller has it (solved here otherwise)."""

    def __init__(self, mu, radius, law, res, fixed_grip=COMPUTE):
        self.mu, self.radius, self.law, self.res = mu, radius, law, res
        dg, z0 = law.work_of_adhesion, law.z0
        self.dg, self.z0 = dg, z0
        self.e_star = math.sqrt(radius * dg * dg / (mu**3 * z0**3))
        a_unit, d_unit = maugis_length_units(radius, self.e_star, dg)
        self.a = max(res.analysis_radius * a_unit, math.sqrt(2 * radius * 20 * z0))
        self.ell = lateral_length(law, radius, self.e_star)
        # DMT side (the range, not an edge, sets ell): one grid, fine over the whole travel
        # of the edge (up to the JKR radius at PRELOAD, which bounds Maugis-Dugdale's); a
        # moving band would carry states across the narrow loops near the cusp
        self.fixed_band = None
        if self.ell < e_star_length(law, self.e_star):
            a_max = jkr_contact_radius(PRELOAD * math.pi * radius * dg, radius, self.e_star, dg)
            self.fixed_band = min(FINE_MARGIN * a_max, 0.5 * self.a)
        self.spacing = res.spacing * self.ell
        # half-width of the moving band (m): wider beyond BAND_MU, where the jump-out fold is
        # so flat that the grids' folds lie apart and exchanges are refused over a window
        self.half = res.band * self.ell * max(1.0, mu / BAND_MU)
        self.d_end = deepest_separation(mu, radius, self.e_star, law)
        # start beyond the jump-out (Maugis-Dugdale's fixed-grip approach + margin), so that
        # its landing on the approach branch is on the curve
        fg = md_fixed_grip(mu) if fixed_grip is COMPUTE else fixed_grip
        d_out = z0 - (fg[1] * d_unit if fg else 0.0)
        self.d_start = max(12 * z0, 1.5 * d_out)
        self.d_out_md = d_out
        self.bistable = fg is not None
        self.ds_max = res.ds_max if res.ds_max else max(DS_MAX, 0.02 * self.d_start / z0)
        self.sphere = Sphere(radius)

        def build(grid, first):
            check = first and not _checked(law)
            pb = ContactProblem(GreenOperator(grid, self.e_star), self.sphere,
                                {"law": self.law}, check_laws=check)
            if check:       # (only once it passed)
                _remember(law)
            return pb
        # the grid family of this resolution: a band following the contact edge (one home
        # for the moving band: femadh.discretisation.moving)
        self.band = MovingBand(self.a, self.spacing, self.half, res.grading * self.ell, build,
                               EDGE_GAP * z0, fixed=self.fixed_band)

    @property
    def follows_edge(self):
        """True where the point is traced with the grid following the contact edge
        (:func:`trace_edge_point`): where the curve has a jump-in and a jump-out
        (Maugis-Dugdale's fixed-grip pull-off exists: lambda > 0.938, mu > 0.81), unless
        ``follow_edge`` is off or the grid is the legacy one."""
        return self.res.follow_edge and not self.res.legacy and self.bistable

    def problem(self, center=0.0):
        """The problem on a grid fine around the contact edge at ``center`` (m)."""
        if self.res.legacy:
            if not isinstance(self.law, LennardJones):
                raise ValueError("the legacy fixed grid is defined for LennardJones only")
            return lj_sphere_problem(self.mu, self.radius, self.law.hamaker, self.z0,
                                     self.res.stiffness_target or STIFFNESS_TARGET,
                                     self.res.min_nodes or 120)[0]
        return self.band.problem(center)

    def approach_problem(self):
        """The approach branch's problem of the edge-following trace (:func:`trace_edge_point`):
        the member of the family whose band [0, half] surrounds the centre, also on the DMT
        side of bistability, where the arclength trace's fixed band [0, FINE_MARGIN a_max]
        holds the contact edge's travel: the approach branch has no contact edge, only the
        bulge under the sphere (measured, peer Lj82 mu = 1 at 3e-3: 65 nodes instead of 82,
        the jump-in's error 3.5e-4 instead of 6.6e-5 and the hysteresis's 1.1e-2 instead of
        1.9e-2 against the reference, each within its estimate)."""
        family = follow_family(self.a, self.half, self.res.grading * self.ell, 0.0)
        return self.band.build(family.member(self.spacing), not self.band.centers)

    def stop(self, curve):
        """End the trace once the stable branch after the folds has passed both the smallest
        fold separation (so the jump-in's landing is on the curve) and its largest tension
        (the tension falls again between the last two points: the load-controlled pull-off
        is behind). Curves without folds run to d_end."""
        pts = curve.points
        if not curve.folds or curve.folds[-1].index >= len(pts) - 2:
            return False
        p, q = pts[-2], pts[-1]
        if not (q.stable and p.stable and p.seg == q.seg and q.d < p.d):
            return False
        if q.d >= min(f.d for f in curve.folds):
            return False
        pb = curve.problem_of(q.seg)
        return lj_force(pb, self.law, q.d, q.w) < lj_force(pb, self.law, p.d, p.w)

    def band_offset(self, problem, edge):
        """|edge - band centre| / band half-width (0 for a fixed band or the legacy grid)."""
        return 0.0 if self.res.legacy else self.band.band_offset(problem, edge)

    def regrid(self, problem, w, d):
        """A grid whose band leads the edge (:meth:`MovingBand.regrid`)."""
        return None if self.res.legacy else self.band.regrid(problem, w, d)


def trace_point(setup, tol, progress):
    """The equilibrium curve of one map point (a :class:`PointSetup`) by pseudo-arclength
    continuation on its moving band, from ``setup.d_start`` to its stop rule.

    Parameters
    ----------
    setup : PointSetup
    tol : float
        Residual tolerance of each state (m).
    progress : callable or None
        Progress callback of :func:`femadh.contact.arclength.trace_curve`.

    Returns
    -------
    The traced curve (points, folds, the problems of its grids).
    """
    z0 = setup.z0
    return trace_curve(setup.problem(0.0), setup.d_start, setup.d_end, tol=tol, scale=z0,
                       ds=0.2, ds_max=setup.ds_max, progress=progress,
                       regrid=None if setup.res.legacy else setup.regrid,
                       stop=setup.stop, max_points=20000,
                       target_correction=TRACE_CORRECTION)


#: the edge-following trace (:func:`trace_edge_point`): half-width of the fine band around
#: the edge node and the grading length (units of ell); the band's nodes move with the edge,
#: so it needs to hold only the cohesive zone (~0.7 ell) and the edge's near field
EDGE_BAND = 2.0
EDGE_GRADING = 2.0
#: the reference grid's analysis radius relative to the point's: the grid shrinks with the
#: edge down to the jump-out fold (~0.5 of JKR's pull-off radius, where it starts), so the
#: radius stays above ~1.4 of the point's (measured: 3 -> 4 moves no quantity by more than
#: 4e-6 relative at mu = 3 and 20; 2 moves the fixed-grip pull-off by 4.5e-4 at mu = 2.7)
EDGE_RADIUS_MARGIN = 3.0
#: first relative step in the centre gap of the approach branch (from g = d_out, where the
#: surface bulges by a fraction of the gap and the branch is smooth)
APPROACH_STEP0 = 0.08
#: Gauss-Legendre nodes of the contact branch's work between the landing and the fold (F d'(c)
#: is smooth in c: 6, 8 and 12 nodes agree to 1e-9 relative at mu = 1, 3, 20; 4 nodes move
#: the hysteresis by 3.7e-7, 4e-8 and 1.2e-8 relative at mu = 1, 3, 20 (LJ, spacing 0.1 ell,
#: measured), below the map's 1e-3 by 2700x, for two solves fewer per member)
HYSTERESIS_NODES = 4


def jkr_start(branch, setup, c):
    """A start for Newton at edge radius c: the JKR pressure of contact radius c (Johnson
    1985 eq 5.31: Hertz plus the flat punch of the adhesive tension), its displacements
    through the scaled operator, gaps inside the contact held at z0 (where the LJ pressure
    vanishes) and d from the edge gap on node k."""
    pb = branch.problem(c)
    r = pb.grid.nodes
    e, R, dg = setup.e_star, setup.radius, setup.dg
    x = np.clip(1.0 - (r / c) ** 2, (setup.ell / c) ** 2, None)
    inside = r < c
    p = np.where(inside, 2 * c * e / (math.pi * R) * np.sqrt(x)
                 - math.sqrt(2 * dg * e / (math.pi * c)) / np.sqrt(x), 0.0)
    w = -(pb.C @ p)
    k = branch.k
    d = branch.edge_gap - float(pb.shape[k]) + float(w[k])
    w = np.where(inside, np.minimum(w, d + pb.shape - setup.z0), w)
    return w, d


def trace_edge_point(setup, tol):
    """One bistable map point traced with the grid following the contact edge.

    The contact branch is traced by Newton in its edge radius c on a grid that moves with the
    edge (:mod:`femadh.contact.edge_branch`), from JKR's pull-off radius down through the
    largest tension to the jump-out fold; the approach branch (no contact yet) by Newton in
    its centre gap g on the band at the centre (:class:`~femadh.contact.edge_branch.
    CentreGapBranch`: d(g) is smooth through the jump-in fold, its minimum) from g = d_out,
    the jump-out separation (so that its separations start beyond d_out, where the retract
    path lands), to the jump-in fold; then the contact branch up past the landing of the
    jump-in. The unstable branch between the folds is not traced: no headline quantity is
    read off it. Every state's residual is ``tol`` (m).

    Returns
    -------
    dict
        The headline quantities in SI (pull_off, pull_off_displacement (N), jump_in,
        jump_out (m), hysteresis, loop_work (J)) and the states and counts the map reports.
    """
    from ..contact.edge_branch import (BranchTrace, CentreGapBranch, EdgeBranch, edge_grid,
                                       gauss_legendre, tail_energy_change)

    law, z0, R = setup.law, setup.z0, setup.radius
    ell, h = setup.ell, setup.spacing

    def force(pb, d, w):
        return lj_force(pb, law, d, w)

    # contact branch: reference grid fine around its node k at JKR's load-controlled
    # pull-off radius (9 pi dg R^2 / 8 E*)^(1/3), where it starts (the
    # largest tension is near, the fold (JKR: 0.48 of it) and the landing on either side)
    c0 = (9 * math.pi * setup.dg * R * R / (8 * setup.e_star)) ** (1 / 3)
    a_ref = EDGE_RADIUS_MARGIN * setup.a
    half = EDGE_BAND * ell
    grading = (setup.res.edge_grading or EDGE_GRADING) * ell
    grid, k = edge_grid(a_ref, c0, h, half, grading)
    base = GreenOperator(grid, setup.e_star)
    branch = EdgeBranch(base, k, setup.sphere, {"law": law}, EDGE_GAP * z0, tol)
    # a grid whose nodes snap on their own cannot carry the edge (a priori, at the law's
    # steepest softening against the edge node's stiffness)
    trapped = trapping_message(branch.softening_ratio(), TRAPPING_LIMIT)
    if trapped:
        raise ConvergenceError(f"edge trace at spacing {setup.res.spacing:g} ell: {trapped}; "
                               "lower spacing")
    tr = BranchTrace(branch)
    c0 = float(grid.nodes[k])
    w0, d0 = jkr_start(branch, setup, c0)
    start = branch.solve(c0, w0, d0)
    if start is None:
        raise ConvergenceError(f"edge trace: Newton from the JKR state at c = {c0:.4g} m "
                               "did not converge", d=d0)
    tr.states.append(start)

    def F(st):
        # the grid's force from the state's own pressures, and the exact tail
        if st.force is None:
            st.force = branch.grid_force(st) + paraboloid_tail_force(law, R, st.d,
                                                                     branch.radius(st))
        return st.force

    def Fa(st):
        """The force (N) of an approach state (as lj_force, from its own pressures)."""
        if st.force is None:
            st.force = app.grid.force(st.P) + paraboloid_tail_force(law, R, st.d, app.grid.radius)
        return st.force

    # down in c past the jump-out fold (d(c) has its largest value there) and past the
    # largest tension (the load-controlled pull-off is the largest tension anywhere on the
    # curve: beyond the fold, on the unstable side, it would be missed)
    down = tr.march(start, -1, lambda run: len(run) >= 3 and run[-1].d < run[-2].d
                    and F(run[-1]) < F(run[-2]))
    i_fold = next(i for i in range(2, len(down)) if down[i].d < down[i - 1].d)
    fout = tr.fold(down[i_fold].c, down[i_fold - 2].c)
    # approach branch: the centre band of the point's family, traced in its centre gap g
    # (d(g) is smooth through the jump-in fold, its minimum) up to the fold, from the centre
    # gap g = d_out (its separation d = g + w(0) lies beyond the jump-out: the approach
    # state at d_out is between traced states). Before d_out nothing is read off the branch
    app = setup.approach_problem()
    abranch = CentreGapBranch(app, tol)
    atr = BranchTrace(abranch)
    d_out = fout.d
    g_app = d_out + float(app.shape[0])
    first = abranch.solve(g_app, np.zeros(app.grid.n), d_out)
    if first is None:
        raise ConvergenceError(f"edge trace: no approach state of centre gap {g_app / z0:.4g} "
                               "z0 (the jump-out separation)", d=d_out)
    atr.states.append(first)
    g_floor = z0     # below it the centre is in repulsive contact: no jump-in before
    arun = atr.march(first, -1, lambda run: (len(run) >= 3 and run[-1].d > run[-2].d)
                     or run[-1].c < g_floor, step0=APPROACH_STEP0)
    if arun[-1].c < g_floor or len(arun) < 3:
        raise ConvergenceError("edge trace: the approach branch has no jump-in fold before "
                               f"the centre gap {arun[-1].c / z0:.4g} z0", d=arun[-1].d)
    fin = atr.fold(arun[-1].c, arun[-3].c)
    apts = sorted([s for s in atr.states if s.c > fin.c], key=lambda s: -s.c)
    # up in c past the jump-in landing (d below the jump-in fold's) and the largest tension
    tr.march(start, +1, lambda run: run[-1].d < fin.d and (
        len(run) >= 2 and F(run[-1]) < F(run[-2])))
    traced = tr.states
    i = int(np.argmax([F(s) for s in traced]))
    if i in (0, len(traced) - 1):
        raise ConvergenceError("edge trace: the largest tension lies at an end of the traced "
                               f"contact branch (c = {traced[i].c:.4g} m)", d=traced[i].d)
    pull_c, _ = tr.maximize(F, traced[i - 1], traced[i], traced[i + 1])
    stable = [s for s in tr.states if s.c > fout.c]
    j = next(j for j in range(len(stable)) if stable[j].d < fin.d)
    land = tr.where_d(fin.d, stable[j - 1].c if j else fout.c, stable[j].c)
    if not is_positive_definite(land.problem.energy_hessian(land.problem.contour(land.d)
                                                            - land.w)):
        raise ConvergenceError(f"edge trace: the jump-in landing at d = {fin.d / z0:.4g} z0 "
                               "is not stable", d=fin.d)
    # the retract path leaves the contact at the fold and lands on the approach branch
    pba = app
    ia = next((i for i in range(len(apts) - 1)
               if (apts[i].d - d_out) * (apts[i + 1].d - d_out) <= 0), None)
    if ia is not None:
        # Newton at d_out from the states on either side (the approach branch is a function
        # of d there); the state must lie between them in centre gap, else located in g
        hi, lo = apts[ia], apts[ia + 1]
        t = (d_out - hi.d) / (lo.d - hi.d)
        st = abranch.at_separation(d_out, hi.w + t * (lo.w - hi.w))
        if st is None or not lo.c <= st.c <= hi.c:
            st = atr.where_d(d_out, lo.c, hi.c)
        w_out = st.w
    elif d_out < fin.d:
        raise ConvergenceError(f"edge trace: the jump-out separation {d_out / z0:.4g} z0 lies "
                               f"below the jump-in's {fin.d / z0:.4g} z0", d=d_out)
    else:   # beyond the traced approach branch: Newton from the undeformed surface
        out = solve_complementarity(pba, d_out, np.zeros(pba.grid.n), tol=tol, max_iter=60)
        if not (out.converged and out.stable
                and np.min(pba.contour(d_out) - out.w) > EDGE_GAP * z0):
            raise ConvergenceError(f"edge trace: no approach state (without contact) at the "
                                   f"jump-out separation {d_out / z0:.4g} z0", d=d_out,
                                   residual=out.residual, n_iter=out.n_iter)
        w_out = out.w
    # the work of the cycle (the energy its jumps release): int F dd along the contact
    # branch from the landing to the fold (Gauss-Legendre in c, where F d'(c) is smooth)
    # less the same along the approach branch (its energy difference on one grid: F = dE/dd
    # with the exact tail). Energies of states on grids of different analysis radii are not
    # compared: the deformation beyond the radius is not modelled, differently on each
    x, wq = gauss_legendre(HYSTERESIS_NODES)
    half_c, mid_c = 0.5 * (land.c - fout.c), 0.5 * (land.c + fout.c)
    contact_work = 0.0
    for xi, wi in zip(x, wq):
        st = tr.at(mid_c + half_c * xi)
        contact_work += wi * half_c * F(st) * branch.slope(st)
    approach_work = (pba.energy(fin.w, fin.d) - pba.energy(w_out, d_out)
                     + tail_energy_change(law, R, pba.grid.radius, fin.d, d_out))
    released = approach_work - contact_work
    # the paths (for the loop integral and the figures)
    fa = np.array([Fa(p) for p in apts])
    da = np.array([p.d for p in apts])
    cs = sorted([s for s in tr.states if s.c >= land.c] + [land], key=lambda s: s.c)
    rs = sorted([s for s in tr.states if s.c >= fout.c] + [fout], key=lambda s: -s.c)
    app_d = np.r_[da, fin.d, [s.d for s in cs]]
    app_F = np.r_[fa, Fa(fin), [F(s) for s in cs]]
    keep = da >= d_out
    ret_d = np.r_[[s.d for s in rs], d_out, da[keep][::-1]]
    ret_F = np.r_[[F(s) for s in rs], force(pba, d_out, w_out), fa[keep][::-1]]
    trap = getattr(np, "trapezoid", None) or np.trapz
    loop = trap(ret_F, ret_d) + trap(app_F, app_d)
    all_c = tr.states
    trapping = max([abranch.node_softening_ratio(p) for p in apts]
                   + [branch.node_softening_ratio(s) for s in all_c])
    return {
        "pull_off": max(float(np.max(fa)), pull_c), "pull_off_displacement": F(fout),
        "jump_in": fin.d, "jump_out": d_out, "hysteresis": released, "loop_work": loop,
        "trapping": trapping,
        # against the point's own analysis radius, as the static trace's: c over the scaled
        # grid's radius is the same at every state (the grid scales with c)
        "edge_ratio": max(s.c for s in all_c) / setup.a,
        "nodes": max(app.grid.n, grid.n), "nodes_approach": app.grid.n, "nodes_contact": grid.n,
        "n_points": len(apts) + len(all_c), "n_approach": len(apts),
        "n_branch_solves": branch.n_solves,
        "n_solves": abranch.n_solves + branch.n_solves,
        "n_newton": abranch.n_iter + branch.n_iter,
        "n_folds": 2,
        "curve_d": np.r_[da, fin.d, [s.d for s in all_c]],
        "curve_F": np.r_[fa, Fa(fin), [F(s) for s in all_c]],
        "curve_stable": np.r_[np.ones(len(apts), bool), False, [s.c > fout.c for s in all_c]],
        "approach": (app_d, app_F), "retract": (ret_d, ret_F),
        "n_factor": abranch.n_factor + branch.n_factor, "n_krylov": 0,
    }
