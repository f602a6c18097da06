"""Smooth-sphere Lennard-Jones adhesion regime map over the whole Tabor range (beyond the papers).

A smooth elastic half-space against a rigid paraboloid with the LJ law of paper 1 eq (3) (or any
gap law with ``work_of_adhesion`` and ``z0``, e.g. :class:`femadh.laws.Lj82`) and no sigma-gap:
the repulsive term carries the contact. Swept in the Tabor parameter
mu = (R dg^2 / (E*^2 z0^3))^(1/3), dg = A / (16 pi z0^2) (eq 19), by choosing E* at fixed R, A,
z0. Each point traces the equilibrium curve F(d) by pseudo-arclength continuation
(:mod:`femadh.contact.arclength`) through its folds; the approach and retract paths of a
displacement-controlled experiment follow from it. Read off the curve:

- load-controlled pull-off: the largest tension on the curve (Maugis-Dugdale's pull-off);
- displacement-controlled pull-off: the tension where the retract path leaves the contact (the
  jump-out fold: Maugis-Dugdale's vertical tangent of P(D), -(5/6) pi R dg in the JKR limit);
- jump-in / jump-out separations (the folds) and the hysteresis (energy released at the jumps).

Classic computations of this problem: Greenwood 1997, Proc. R. Soc. A 453, 1277; Feng 2000,
J. Colloid Interface Sci. 238, 318.

Grid: where the curve is bistable (mu > 0.81) the contact branch is traced in its edge radius
on a grid whose nodes move with the edge, the edge on a node at every state
(:func:`~femadh.studies.smooth_sphere.trace_edge_point`, :mod:`femadh.contact.edge_branch`): no
lattice wiggles, a fine band of +-2 ell around the edge only, nodes growing like ln mu (mu = 20
at 1e-3: 247 nodes, against 852 on the moving band); the approach branch by Newton in its
centre gap to the jump-in fold. Elsewhere, and with ``Resolution(follow_edge=False)``, the
whole curve is traced by arclength on a band of uniform fine spacing that follows the contact
edge in steps, graded beyond it (:class:`~femadh.studies.smooth_sphere.PointSetup`,
:class:`Resolution`); ``band_offset`` reports how far the edge strayed from the band's centre,
the guards refuse a point whose edge left it, whose nodes snap alone or whose contact reaches
the analysis radius.

Accuracy: every result carries an a-posteriori error estimate from a coarser member of the
grid family (spacing x 1.5, or x 2 after a refinement; Richardson with the observed order 2).
``accuracy=`` chooses the spacing from the measured error model, capped so that the coarser
member stays below 0.075 elastocohesive lengths on the JKR side when the fixed-grip pull-off
is judged (coarser, lattice wiggles move the flat jump-out fold and Richardson no longer
applies; ``judged=`` names the quantities the request is asked of), and refines until the
estimate meets the request. Richardson, the guards and the refine-until-met loop with its
budget are the runner's too (:mod:`femadh.estimate`); the curve readout is
:func:`femadh.contact.curve.read_curve`, the smooth-sphere problem
:mod:`femadh.studies.smooth_sphere`, the moving band and the contact edge
:mod:`femadh.discretisation.moving`: this module keeps the map.

Stability: each fold flips it unless another Hessian mode is already negative there (at
mu >= 5 a second mode turns negative after the jump-in and back: four folds, the piece
between the middle two of index 2).
"""
from dataclasses import dataclass, field, replace
import math
import time
import warnings

import numpy as np

from ..contact.curve import read_curve
from ..discretisation.moving import contact_edge
from ..errors import ConvergenceError, MeshResolutionWarning
from ..estimate import (TRAPPING_LIMIT, Budget, discretisation, outside_bounds,
                        refine_until_met, trapping_message, worst_relative)
from ..laws import LennardJones
from ..reference.maugis import lj_dugdale_lambda, maugis_fixed_grip_pull_off, maugis_pull_off
# the smooth-sphere problem of one point (re-exported: the map's public names)
from .smooth_sphere import (ANALYSIS_RADIUS, BAND, BAND_MU, DS_MAX,  # noqa: F401
                            EDGE_GAP, EDGE_GRADING, GRADING, SPACING,  # noqa: F401
                            TRACE_CORRECTION, COMPUTE, PointSetup,  # noqa: F401
                            Resolution, e_star_length, lateral_length, lj_force, md_fixed_grip,
                            trace_edge_point, trace_point)

R_DEFAULT, A_DEFAULT, Z0_DEFAULT = 1e-6, 1e-19, 0.165e-9

#: a contact edge further than this fraction of the band's half-width from its centre is
#: not resolved (the cohesive zone, ~0.7 ell wide, reaches the graded part); exchanges keep
#: it within ~0.55 (measured max 0.53-0.74 at mu = 3-20, band 4 ell)
BAND_LIMIT = 0.9
#: a contact edge beyond this fraction of the analysis radius is not resolved
from ..estimate.guards import SMOOTH_EDGE_FRACTION as EDGE_LIMIT  # noqa: E402 (its home)
#: observed order of the spacing error of the headline quantities (measured, see
#: validation/results/accuracy_regime.md); Richardson divides the coarse-fine change by 2^p - 1
ORDER = 2.0
#: hysteresis errors are relative to max(hysteresis, this) (units pi R dg z0): near the onset
#: of bistability the loop closes and a relative error of a vanishing work is not meaningful
HYSTERESIS_FLOOR = 0.1
#: refinements (halvings of the spacing) an accuracy request may take
MAX_REFINEMENTS = 4
#: node budget of a refinement (a dense grid of N nodes costs ~N^2 per Krylov iteration at
#: every continuation step: 1600 nodes ~ 10x the cost of 500)
from ..estimate.refine import CONTINUATION_MAX_NODES as MAX_NODES  # noqa: E402 (its home)
#: the budget of an accuracy request (:func:`femadh.estimate.refine.refine_until_met`)
BUDGET = Budget(MAX_REFINEMENTS, MAX_NODES)
#: the headline quantities and the accuracy they are judged by
QUANTITIES = ("pull_off", "pull_off_displacement", "jump_in", "jump_out", "hysteresis")
#: proven bounds of the load-controlled pull-off / (pi R dg) for a paraboloid (see
#: _check_bounds): 2 (rigid Derjaguin, exact for a paraboloid) above, JKR's 1.5 below
DERJAGUIN, JKR = 2.0, 1.5


class ResolutionError(ConvergenceError):
    """A traced state is not resolved by the grid (lattice trapping, a contact reaching the
    analysis radius) or a result leaves its proven bounds: not a converged map point."""


@dataclass
class RegimePoint:
    """One point of the regime map (forces / (pi R dg), separations / z0, work / (pi R dg z0)).

    ``*_error`` are the a-posteriori estimates of the absolute errors of the same quantities
    (Richardson from the next coarser grid of the family); None where a quantity does not
    exist (no folds: no jumps, no displacement-controlled jump-out).
    """

    mu: float
    e_star: float
    pull_off: float            # load-controlled pull-off (largest tension on the curve)
    pull_off_displacement: float | None  # tension at the jump-out (fixed-grip pull-off)
    maugis: float              # Maugis-Dugdale load-controlled pull-off at lambda = 1.157 mu
    maugis_displacement: float | None  # Maugis-Dugdale fixed-grip pull-off (None: none)
    jump_in: float | None      # d / z0 of the approach fold
    jump_out: float | None     # d / z0 of the last retract fold
    hysteresis: float          # energy dissipated per cycle / (pi R dg z0), from energy jumps
    hysteresis_trapezoid: float  # the same by integrating F dd around the loop (cross-check)
    n_folds: int               # folds of the traced curve (2 for one S; more: mesh wiggles)
    trapping_ratio: float      # max over states and nodes of -P'(h_k) / K_kk
    n_points: int
    n_solves: int
    nodes: int                 # nodes of the (largest) grid of the reported result
    wall_time: float
    curves: dict
    errors: dict = field(default_factory=dict)   # estimated absolute errors by quantity
    resolution: Resolution | None = None
    spacing_m: float = math.nan   # fine-band node spacing (m)
    lateral_length: float = math.nan  # ell (m)
    analysis_radius_m: float = math.nan
    edge_ratio: float = math.nan  # largest contact-edge radius / analysis radius
    n_grids: int = 1              # grids the moving band used along the curve
    accuracy: float | None = None  # the requested relative accuracy (None: explicit settings)
    failed: str | None = None      # why the point is not a converged result (None: it is)
    band_offset: float = math.nan  # largest |contact edge - band centre| / band half-width
    judged: tuple = QUANTITIES     # the quantities the accuracy was asked of

    def error(self, name):
        """Estimated absolute error of quantity ``name`` (None if it does not exist)."""
        return self.errors.get(name)

    def relative_error(self, name):
        """Estimated error relative to the quantity (hysteresis: to its floor)."""
        e, v = self.errors.get(name), getattr(self, name)
        if e is None or v is None:
            return None
        ref = max(abs(v), HYSTERESIS_FLOOR) if name == "hysteresis" else abs(v)
        return e / ref

    pull_off_error = property(lambda self: self.error("pull_off"))
    pull_off_displacement_error = property(lambda self: self.error("pull_off_displacement"))
    jump_in_error = property(lambda self: self.error("jump_in"))
    jump_out_error = property(lambda self: self.error("jump_out"))
    hysteresis_error = property(lambda self: self.error("hysteresis"))


def _read(setup, curve):
    """Headline quantities (units of the map) and diagnostics of a traced curve (dict): the
    readout of :func:`femadh.contact.curve.read_curve` with the smooth sphere's force (grid
    plus exact tail), the grids' resolution diagnostics."""
    law, z0 = setup.law, setup.z0
    scale = math.pi * setup.radius * setup.dg
    pb = curve.problem_of
    ro = read_curve(curve, lambda problem, d, w: lj_force(problem, law, d, w))
    pts = curve.points
    trapping = max(pb(p.seg).node_softening_ratio(pb(p.seg).contour(p.d) - p.w) for p in pts)
    edges = [contact_edge(pb(p.seg), p.w, p.d, EDGE_GAP * z0) for p in pts]
    band_offset = max((setup.band_offset(pb(p.seg), e) for p, e in zip(pts, edges)),
                      default=0.0)
    (da, fa), (dr, fr) = ro.paths["approach"], ro.paths["retract"]
    return {
        "pull_off": float(ro.pull_off / scale),
        "pull_off_displacement": (None if ro.pull_off_displacement is None
                                  else ro.pull_off_displacement / scale),
        "jump_in": None if ro.jump_in is None else ro.jump_in / z0,
        "jump_out": None if ro.jump_out is None else ro.jump_out / z0,
        "hysteresis": float(ro.hysteresis / (scale * z0)),
        "hysteresis_trapezoid": float(ro.loop_work / (scale * z0)),
        "trapping": float(trapping), "edge_ratio": max(edges) / setup.a,
        "band_offset": band_offset,
        "nodes": max(t.problem.grid.n for t in curve.tracers),
        "curves": {"curve_d": curve.d / z0, "curve_F": ro.force / scale,
                   "curve_stable": np.array([p.stable for p in pts]),
                   "approach_d": da / z0, "approach_F": fa / scale,
                   "retract_d": dr / z0, "retract_F": fr / scale,
                   "n_factor": curve.n_factor, "n_krylov": curve.n_krylov},
    }


def _unresolved(setup, q):
    """Why the traced states are not resolved (str naming quantity, value and the setting to
    change), or None."""
    trapped = trapping_message(q["trapping"], TRAPPING_LIMIT)
    if trapped:
        return (f"mu = {setup.mu:g}: on a traced state {trapped}; refine the grid (spacing = "
                f"{setup.res.spacing:g} ell, stiffness_target = "
                f"{setup.res.stiffness_target}) or give accuracy=")
    if q["band_offset"] > BAND_LIMIT:
        return (f"mu = {setup.mu:g}: the contact edge left the fine band (|edge - centre| = "
                f"{q['band_offset']:.2f} half-widths > {BAND_LIMIT}): the grid did not follow "
                f"it; widen the band (band = {setup.res.band:g} ell)")
    if q["edge_ratio"] > EDGE_LIMIT:
        return (f"mu = {setup.mu:g}: the contact edge reached {q['edge_ratio']:.2f} of the "
                f"analysis radius (limit {EDGE_LIMIT}); raise analysis_radius "
                f"(= {setup.res.analysis_radius:g} a_unit) or give accuracy=")
    return None


def estimate_errors(fine, coarse, ratio=2.0):
    """Estimates of the fine result's absolute errors from a coarser member whose spacing is
    ``ratio`` times the fine one: Richardson at the family's measured ORDER
    (:func:`femadh.estimate.richardson.discretisation` on two members); a quantity the coarse
    grid missed (no fold there) has its own size as the estimate."""
    rich = discretisation({k: fine[k] for k in QUANTITIES},
                          {k: coarse[k] for k in QUANTITIES}, None, ratio, order=ORDER)
    out = {}
    for k in QUANTITIES:
        if fine[k] is None:
            out[k] = None
        elif coarse[k] is None:   # the coarse grid missed the feature: its size is the estimate
            out[k] = abs(fine[k])
        else:
            out[k] = abs(rich[k])
    return out


def _worst(q, errors, judged=QUANTITIES):
    """(name, relative error) of the judged quantity furthest from its accuracy."""
    return worst_relative({k: q[k] for k in judged}, {k: errors[k] for k in judged},
                          {"hysteresis": HYSTERESIS_FLOOR})


def _check_bounds(mu, q, errors):
    """No pull-off outside what is proven for a paraboloid (ResolutionError otherwise).

    Proven: the rigid paraboloid's pull-off is exactly 2 pi R dg (Derjaguin: F = -2 pi R U(d)
    and U >= -dg). Elastic compliance lowers it towards JKR's 1.5 (every computation and
    Maugis-Dugdale lie in [1.5, 2]: an empirical band for the elastic case, not a theorem).
    The fixed-grip tension at the jump-out is a point of the curve: it cannot exceed the
    largest tension on it (proven), and lies above the JKR fixed-grip 5/6 (empirical)."""
    p, e = q["pull_off"], errors.get("pull_off") or 0.0
    if outside_bounds(p, e, JKR, DERJAGUIN, rel=0.0):
        raise ResolutionError(f"mu = {mu:g}: pull-off {p:.6f} pi R dg outside [{JKR}, "
                              f"{DERJAGUIN}] (estimated error {e:.2g}): not a resolved result")
    pd = q["pull_off_displacement"]
    if pd is not None and outside_bounds(pd, e, upper=p):
        raise ResolutionError(f"mu = {mu:g}: fixed-grip pull-off {pd:.6f} exceeds the largest "
                              f"tension on the curve {p:.6f}")


def solve_point(mu, radius, law, res, tol, progress, fixed_grip=COMPUTE):
    """One map point at one resolution, without an error estimate: the traced curve's
    headline quantities and diagnostics (dict; ``setup`` holds its :class:`PointSetup`).

    Parameters
    ----------
    mu : float
        Tabor parameter.
    radius : float
        Sphere radius (m).
    law : LennardJones or Lj82
        The gap law.
    res : Resolution
        Grid of this member.
    tol : float
        Residual tolerance (m).
    progress : callable or None
    fixed_grip : optional
        Maugis-Dugdale's fixed-grip solution at this mu (:func:`md_fixed_grip`) if the caller
        has it.
    """
    setup = PointSetup(mu, radius, law, res, fixed_grip)
    if setup.follows_edge:
        return _read_edge(setup, trace_edge_point(setup, tol))
    curve = trace_point(setup, tol, progress)
    q = _read(setup, curve)
    q.update(setup=setup, n_points=len(curve.points), n_solves=curve.n_solves,
             n_folds=len(curve.folds), n_grids=len(curve.tracers))
    return q


def _read_edge(setup, e):
    """The map's readout (units of the map) of a point traced with the grid following the
    edge (:func:`~femadh.studies.smooth_sphere.trace_edge_point`): two grids (the approach
    branch's and the contact branch's), the edge on a node of the latter at every state
    (band offset 0), two folds traced (jump-in and jump-out; the unstable branch between
    them, with its two further folds at mu >= 5, is not traced)."""
    z0 = setup.z0
    scale = math.pi * setup.radius * setup.dg
    (da, fa), (dr, fr) = e["approach"], e["retract"]
    return {
        "pull_off": float(e["pull_off"] / scale),
        "pull_off_displacement": float(e["pull_off_displacement"] / scale),
        "jump_in": float(e["jump_in"] / z0), "jump_out": float(e["jump_out"] / z0),
        "hysteresis": float(e["hysteresis"] / (scale * z0)),
        "hysteresis_trapezoid": float(e["loop_work"] / (scale * z0)),
        "trapping": float(e["trapping"]), "edge_ratio": float(e["edge_ratio"]),
        "band_offset": 0.0, "nodes": int(e["nodes"]),
        "curves": {"curve_d": e["curve_d"] / z0, "curve_F": e["curve_F"] / scale,
                   "curve_stable": e["curve_stable"],
                   "approach_d": da / z0, "approach_F": fa / scale,
                   "retract_d": dr / z0, "retract_F": fr / scale,
                   "n_factor": e["n_factor"], "n_krylov": e["n_krylov"],
                   "n_newton": e["n_newton"]},
        "setup": setup, "n_points": e["n_points"], "n_solves": e["n_solves"],
        "n_folds": e["n_folds"], "n_grids": 2,
    }


def _coarse_member(mu, radius, law, res, tol, edge, fixed_grip=COMPUTE):
    """The coarser member for the estimate: spacing x COARSE_RATIO (x 2 if that one cannot be
    traced; where the grid follows the edge (``edge``) x COARSE_RATIO_EDGE, else x
    COARSE_RATIO). Returns (result, ratio)."""
    ratios = (COARSE_RATIO_EDGE, COARSE_RATIO) if edge else (COARSE_RATIO, 2.0)
    why = None
    for ratio in ratios:
        try:
            return (solve_point(mu, radius, law, res.coarser(ratio), tol, None, fixed_grip),
                    ratio)
        except (ConvergenceError, ValueError) as exc:
            why = str(exc)
            continue
    raise ResolutionError(f"mu = {mu:g}: the coarser grids (spacing x {ratios[0]:g}, "
                          f"x {ratios[1]:g} of {res.spacing:g} ell) cannot be traced ({why}): "
                          f"no error estimate; lower spacing")


def lj_sphere(mu, *, radius=R_DEFAULT, hamaker=A_DEFAULT, z0=Z0_DEFAULT, law=None, tol=None,
              accuracy=None, resolution=None, spacing=None, stiffness_target=None,
              min_nodes=None, ds_max=None, progress=None, judged=QUANTITIES):
    """One regime-map point: trace the curve at Tabor parameter mu and read it.

    Parameters
    ----------
    mu : float
        Tabor parameter (-); sets E* at the given R and law.
    radius, hamaker, z0 : float
        Paraboloid radius R (m) and the LJ law's Hamaker constant (J) and z0 (m).
    law : gap law, optional
        Instead of LennardJones(hamaker, z0): any law with ``work_of_adhesion`` (J/m^2) and
        ``z0`` (m), e.g. :class:`femadh.laws.Lj82`.
    tol : float, optional
        Residual of eq (6) every traced state meets (m). Default TOL; where an accuracy is
        requested and the grid follows the edge, TOL_PER_ACCURACY x accuracy x z0 (at least
        TOL): the states are converged to what the request needs (:func:`state_tolerance`).
    accuracy : float, optional
        Requested relative accuracy of the headline quantities (pull-offs, jump separations,
        hysteresis relative to max(value, HYSTERESIS_FLOOR)). The spacing starts from the
        measured error model and is halved until the a-posteriori estimate meets it.
    judged : tuple of str
        The quantities the accuracy is asked of (default: all of QUANTITIES; every one is
        reported with its estimate). Without "pull_off_displacement" the lattice cap of the
        flat jump-out fold (:func:`lattice_cap`) does not bound the spacing: the largest
        tension is a smooth maximum that coarser grids resolve (peer problem, mu = 3: 1.4e-4
        at 0.133 ell, where the fold's tension is 1.7e-3 off).
    resolution : Resolution, optional
        Explicit discretisation (default: :class:`Resolution` defaults); ``spacing`` (units of
        ell), ``stiffness_target``/``min_nodes`` (legacy fixed grid) and ``ds_max`` (z0)
        override its fields.

    Returns
    -------
    RegimePoint
        With the estimated errors (``pull_off_error``, ...), the chosen resolution and its
        spacing (m), node count and grids.

    Raises
    ------
    ResolutionError
        A traced state is not resolved (lattice trapping, a contact at the analysis radius)
        or the pull-off leaves its bounds, and no accuracy was requested (with one, the grid
        is refined instead) or the refinement budget ran out.
    """
    t0 = time.perf_counter()
    law = LennardJones(hamaker, z0) if law is None else law
    res = resolution or Resolution()
    over = {k: v for k, v in (("spacing", spacing), ("stiffness_target", stiffness_target),
                              ("min_nodes", min_nodes), ("ds_max", ds_max)) if v is not None}
    res = replace(res, **over)
    lam = lj_dugdale_lambda(mu)
    fg = md_fixed_grip(mu)          # (once for the point: every member's setup uses it)
    edge = PointSetup(mu, radius, law, res, fg).follows_edge
    if tol is None:
        tol = state_tolerance(accuracy if edge else None, law.z0)
    if accuracy is not None:
        if not accuracy > 0:
            raise ValueError(f"accuracy must be > 0, got {accuracy}")
        unknown = set(judged) - set(QUANTITIES)
        if unknown or not judged:
            raise ValueError(f"judged must name some of {', '.join(QUANTITIES)}, got "
                             f"{', '.join(sorted(unknown)) or 'none'}")
        if "spacing" not in over and not res.legacy:
            if edge:
                # the grid follows the edge: no lattice wiggles to cap the spacing for
                cap = MAX_SPACING_EDGE / COARSE_RATIO_EDGE
            elif "pull_off_displacement" in judged:
                cap = lattice_cap(mu, radius, law)
            else:
                cap = None
            res = replace(res, spacing=initial_spacing(accuracy, cap))
            if edge and tuple(judged) == ("pull_off",) and resolution is None:
                g = pull_off_grading(accuracy, res.spacing)
                res = replace(res, grading=g, edge_grading=g)
    member = {}
    member["coarse"], member["ratio"] = _coarse_member(mu, radius, law, res, tol, edge, fg)

    def attempt(res):
        fine = solve_point(mu, radius, law, res, tol, progress, fg)
        errors = estimate_errors(fine, member["coarse"], member["ratio"])
        fine["errors"], fine["worst"] = errors, _worst(fine, errors, judged)
        return fine, fine["worst"][1], _unresolved(fine["setup"], fine)

    def refine(res, fine, rel, why):
        if fine["edge_ratio"] > EDGE_LIMIT:
            return replace(res, analysis_radius=1.5 * res.analysis_radius)
        # the fine member becomes the coarser member of the next estimate (ratio 2)
        member["coarse"], member["ratio"] = fine, 2.0
        return res.finer()

    def nodes(res, fine, nxt):
        return 2 * fine["nodes"] if nxt.spacing < res.spacing else fine["nodes"]

    if accuracy is None:
        fine, _, why = attempt(res)
    else:
        out = refine_until_met(res, attempt, refine, accuracy, BUDGET, nodes)
        res, fine, why = out.setting, out.result, out.why
        name, rel = fine["worst"]
        if not out.met:
            if why is None and out.stop == "nodes":
                why = (f"mu = {mu:g}: estimated relative error of {name} {rel:.2g} > "
                       f"requested {accuracy:g} at spacing {res.spacing:g} ell "
                       f"({fine['nodes']} nodes); the next refinement would exceed the "
                       f"budget's max_nodes = {BUDGET.max_nodes}")
            elif why is None:
                why = (f"mu = {mu:g}: estimated relative error of {name} {rel:.2g} > "
                       f"requested {accuracy:g} after {len(out.steps) - 1} refinements "
                       f"(spacing {res.spacing:g} ell)")
            raise ResolutionError(why, n_iter=len(out.steps) - 1)
    if why is not None:
        raise ResolutionError(why)
    errors = fine["errors"]
    _check_bounds(mu, fine, errors)
    if fine["trapping"] > 0.5 * TRAPPING_LIMIT:
        warnings.warn(f"mu = {mu:g}: node softening ratio {fine['trapping']:.2f} is within 2x "
                      f"of the lattice-trapping limit {TRAPPING_LIMIT}", MeshResolutionWarning,
                      stacklevel=2)
    setup = fine["setup"]
    return RegimePoint(
        mu, setup.e_star, fine["pull_off"], fine["pull_off_displacement"],
        maugis_pull_off(lam), fg[0] if fg else None, fine["jump_in"], fine["jump_out"],
        fine["hysteresis"], fine["hysteresis_trapezoid"], fine["n_folds"], fine["trapping"],
        fine["n_points"], fine["n_solves"], fine["nodes"], time.perf_counter() - t0,
        fine["curves"], errors, res, setup.spacing, setup.ell, setup.a, fine["edge_ratio"],
        fine["n_grids"], accuracy, band_offset=fine["band_offset"], judged=tuple(judged))


#: residual of eq (6) (m) every traced state meets by default
TOL = 1e-19
#: where an accuracy is requested of an edge-following point, its states meet the residual
#: TOL_PER_ACCURACY x accuracy x z0 (at least TOL): measured on the peer's Lj82 (mu = 1, 3)
#: and LJ (mu = 2, 20) points at spacing 0.1-0.133 ell, a residual of 1e-6 z0 instead of
#: 6e-10-1e-10 z0 moves no headline quantity by more than 1.7e-7 relative (1e-5 z0: by up to
#: 4.8e-5, the mu = 1 hysteresis), so at 1e-4 x accuracy x z0 the states' convergence error
#: is ~1e-4 of the request; it saves a third of the Newton iterations
TOL_PER_ACCURACY = 1e-4


def state_tolerance(accuracy, z0):
    """The residual (m) the traced states of a point meet: TOL without an accuracy request,
    else TOL_PER_ACCURACY x accuracy x z0 (never below TOL)."""
    if accuracy is None:
        return TOL
    return max(TOL, TOL_PER_ACCURACY * accuracy * z0)


def initial_spacing(accuracy, cap=None):
    """Band spacing (units of ell) expected to meet a relative accuracy: the measured error
    model rel_err ~ C_SPACING * spacing^ORDER (largest C over the headline quantities and the
    map, validation/results/accuracy_regime.md), with a safety factor of 2 on the error, at
    most ``cap`` (default MAX_SPACING / COARSE_RATIO; see :func:`lattice_cap`)."""
    cap = MAX_SPACING / COARSE_RATIO if cap is None else cap
    return min(cap, (accuracy / (2.0 * C_SPACING)) ** (1.0 / ORDER))


def pull_off_grading(accuracy, spacing):
    """Grading length (units of ell) of both grids of an edge-following point whose accuracy
    is asked of the load-controlled pull-off alone, at band spacing ``spacing`` (ell): the
    measured error model of the pull-off, rel_err ~ C_SPACING spacing^ORDER
    (EDGE_GRADING / grading)^GRADING_ORDER, with a safety factor of 2 on the error, within
    [MIN_GRADING, EDGE_GRADING]. A request the band spacing alone over-delivers is met with
    a coarser far field instead of an over-resolved one."""
    g = EDGE_GRADING * (2.0 * C_SPACING * spacing**ORDER / accuracy) ** (1.0 / GRADING_ORDER)
    return min(EDGE_GRADING, max(MIN_GRADING, g))


def lattice_cap(mu, radius, law):
    """Largest starting band spacing (units of ell) whose coarser member (x COARSE_RATIO) stays
    below LATTICE_SPACING elastocohesive lengths on the JKR side (lattice wiggles at the flat
    jump-out fold) and below MAX_SPACING ell. On the DMT side (ell = sqrt(R z0 / 8) <
    E* z0^2 / dg: ratio > 1) the fold is not flat: the first bound grows like ratio^2
    (empirical: mu = 1, ratio 2.8, no lattice folds up to 0.4 ell; mu = 2, ratio 1, lattice
    folds at 0.3)."""
    dg, z0 = law.work_of_adhesion, law.z0
    e_star = math.sqrt(radius * dg * dg / (mu**3 * z0**3))
    ratio = e_star_length(law, e_star) / lateral_length(law, radius, e_star)
    return min(MAX_SPACING, LATTICE_SPACING * ratio**2) / COARSE_RATIO


#: measured error constant of the banded family: rel_err ~ C spacing^2 with C up to 0.016
#: (hysteresis, mu = 1) and 0.02 (fixed-grip pull-off, mu = 3) for spacing <= 0.1
C_SPACING = 0.02
#: largest spacing of the coarser member of an estimate (units of ell): the pull-off
#: converges like spacing^2 below 0.2 (mu = 1: error ratios 3.9 for 0.2 -> 0.1 and 4.0 for
#: 0.1 -> 0.05, but 2.4 for 0.3 -> 0.2 and 1.3 for 0.4 -> 0.3, measured)
MAX_SPACING = 0.2
#: largest band spacing in elastocohesive lengths E* z0^2 / dg for the members of an
#: estimate: beyond it lattice wiggles spoil the flat jump-out fold (measured: mu = 3
#: fixed-grip pull-off 1.2 % off at 0.2, 1.3e-4 at 0.1; mu = 5: 8 folds at 0.15, 38 at 0.2,
#: the physical 4 at 0.1; mu = 2: on the spacing^2 line within 4e-6 up to 0.08, 4e-5 off
#: it at 0.1)
LATTICE_SPACING = 0.075
#: spacing ratio of the coarser member (1.5: both members in the asymptotic range)
COARSE_RATIO = 1.5
#: where the grid follows the edge (:func:`~femadh.studies.smooth_sphere.trace_edge_point`;
#: units of ell) the lattice cap does not apply (the edge sits on a node at every state), but
#: the pull-off leaves the spacing^2 line above ~0.15 ell, where nodes soften to more than
#: ~0.25 of their stiffness (measured, errors against spacing 0.025: LJ mu = 2: 4.4e-4 at
#: 0.2, 3.7e-4 at 0.133 (ratio 1.2 for order-2's 2.25), 1.9e-4 at 0.1; mu = 3: 5.8e-4 at
#: 0.167, 2.8e-4 at 0.133, 1.5e-4 at 0.1; the peer's Lj82 at mu = 3: 1.3e-3 at 0.25, 4.8e-3
#: at 0.3). The coarser member is at most MAX_SPACING_EDGE, COARSE_RATIO_EDGE times the fine
#: one: the pair (0.167, 0.133) estimates the mu = 2 and 3 pull-offs 1.8-1.9x high (the 0.2
#: member would put the mu = 2 estimate 7x low)
MAX_SPACING_EDGE = 1.0 / 6.0
COARSE_RATIO_EDGE = 1.25
#: the pull-off's error against the grading length G of both grids of an edge-following
#: point (spacing 0.133 ell, errors against the peer script's reference, Lj82 R = 100 z0):
#: mu = 1: 3.03e-4 at G = 2 ell, 8.4e-4 at 1, 1.33e-3 at 0.75, 2.66e-3 at 0.5; mu = 3:
#: 1.78e-4, 4.8e-4, 7.7e-4, 1.60e-3 (G = 2 -> 0.75: factors 4.39 and 4.34, i.e.
#: G^-1.51 and G^-1.50): the far field's error, which the coarser member (spacing x 1.25,
#: same G) estimates with effectivity 1.0-1.2. Used only where the accuracy is asked of the
#: pull-off alone (the other quantities' dependence on G is not measured)
GRADING_ORDER = 1.5
#: smallest grading length chosen (units of ell; the smallest measured on the G^-1.5 line)
MIN_GRADING = 0.5


def regime_map(mus, progress=None, **kw):
    """lj_sphere at each mu (keywords passed on); ``progress(i, point)`` after each. A point
    that cannot be resolved is kept with ``failed`` set (its message) and NaN values."""
    out = []
    for i, mu in enumerate(mus):
        try:
            out.append(lj_sphere(float(mu), **kw))
        except ConvergenceError as exc:
            out.append(_failed_point(float(mu), str(exc)))
        if progress:
            progress(i, out[-1])
    return out


def _failed_point(mu, why):
    nan = math.nan
    lam = lj_dugdale_lambda(mu)
    fg = maugis_fixed_grip_pull_off(lam)
    return RegimePoint(mu, nan, nan, None, maugis_pull_off(lam), fg[0] if fg else None, None,
                       None, nan, nan, 0, nan, 0, 0, 0, 0.0, {}, failed=why)


REGIME_HEADER = ["mu", "lambda", "e_star_Pa", "nodes", "pull_off", "pull_off_error",
                 "maugis_dugdale", "pull_off_displacement", "pull_off_displacement_error",
                 "maugis_dugdale_fixed_grip", "jump_in_d_over_z0", "jump_in_error",
                 "jump_out_d_over_z0", "jump_out_error", "hysteresis", "hysteresis_error",
                 "hysteresis_loop_integral", "n_folds", "trapping_ratio", "n_points",
                 "spacing_m", "wall_time_s", "failed"]


def _fmt(x, spec):
    return "" if x is None or (isinstance(x, float) and math.isnan(x)) else format(x, spec)


def regime_row(p):
    """The csv row of a point (REGIME_HEADER order)."""
    e = p.errors
    return [f"{p.mu:.6g}", f"{lj_dugdale_lambda(p.mu):.6g}", _fmt(p.e_star, ".6g"), p.nodes,
            _fmt(p.pull_off, ".6f"), _fmt(e.get("pull_off"), ".2e"), f"{p.maugis:.6f}",
            _fmt(p.pull_off_displacement, ".6f"), _fmt(e.get("pull_off_displacement"), ".2e"),
            _fmt(p.maugis_displacement, ".6f"), _fmt(p.jump_in, ".6f"),
            _fmt(e.get("jump_in"), ".2e"), _fmt(p.jump_out, ".6f"),
            _fmt(e.get("jump_out"), ".2e"), _fmt(p.hysteresis, ".6g"),
            _fmt(e.get("hysteresis"), ".2e"), _fmt(p.hysteresis_trapezoid, ".6g"), p.n_folds,
            _fmt(p.trapping_ratio, ".4f"), p.n_points, _fmt(p.spacing_m, ".4g"),
            f"{p.wall_time:.3f}", p.failed or ""]


def write_regime(pts, out_dir):
    """regime.csv (forces / (pi R dg), separations / z0, work / (pi R dg z0), estimated
    errors) and the figures of the converged points. Returns the csv path."""
    import csv
    from pathlib import Path

    from ..io.plots import regime_figures

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    with open(out / "regime.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(REGIME_HEADER)
        for p in pts:
            w.writerow(regime_row(p))
    good = [p for p in pts if p.failed is None]
    if good:
        regime_figures(good, out)
    return out / "regime.csv"


def regime_table(pts):
    """A short table for people (the CLI prints it; regime.csv holds every column): per
    point mu, the pull-off / (pi R dg) with its estimated error beside Maugis-Dugdale's, the
    jump-in and jump-out d / z0, the hysteresis / (pi R dg z0), the nodes, and why a point
    failed."""
    def pm(v, e):
        if v is None or not math.isfinite(v):
            return "-"
        if e is None or not math.isfinite(e):
            return f"{v:.4f}"
        from ..io.plots import value_error_text     # (the value to its error's place)
        return value_error_text(v, e)

    def num(v, fmt=".3f"):
        return "-" if v is None or not math.isfinite(v) else format(v, fmt)

    head = ["mu", "pull-off/πRΔγ", "Maugis-Dugdale", "jump-in d/z0", "jump-out d/z0",
            "hysteresis", "nodes"]
    rows = []
    for p in pts:
        if p.failed is not None:
            rows.append([f"{p.mu:.3g}", f"failed: {p.failed.split(':')[0][:50]}"])
            continue
        rows.append([f"{p.mu:.3g}", pm(p.pull_off, p.error("pull_off")), f"{p.maugis:.4f}",
                     num(p.jump_in), num(p.jump_out),
                     num(p.hysteresis, ".3g") if p.hysteresis > 0 else "0", str(p.nodes)])
    widths = [max([len(head[i])] + [len(r[i]) for r in rows if len(r) == len(head) or i == 0])
              for i in range(len(head))]
    lines = ["  ".join(h.rjust(w) for h, w in zip(head, widths))]
    for r in rows:
        if len(r) == 2:
            lines.append(r[0].rjust(widths[0]) + "  " + r[1])
        else:
            lines.append("  ".join(c.rjust(w) for c, w in zip(r, widths)))
    return "\n".join(lines)
