"""Smooth-sphere Lennard-Jones adhesion regime map (beyond the papers).

A smooth elastic sphere against a flat with the LJ law of paper 1 eq (3) and no sigma-gap: the
repulsive term carries the contact. Swept in the Tabor parameter
mu = (R dg^2 / (E*^2 z0^3))^(1/3), dg = A / (16 pi z0^2) (eq 19), by choosing E* at fixed R, A,
z0. Each point traces the whole equilibrium curve F(d) by pseudo-arclength continuation
(:mod:`femadh.contact.arclength`), through its folds; the approach and retract paths of a
displacement-controlled experiment, the jump-in and jump-out separations (the folds) and the
hysteresis follow from it. The pull-off is the largest tensile force on the retract path
(load-controlled pull-off), normalised by pi R dg and compared with Maugis-Dugdale at
lambda = 1.157 mu (Johnson & Greenwood 1997) and the JKR (1.5) and DMT (2) limits.

Classic computations of this problem: Greenwood 1997, Proc. R. Soc. A 453, 1277 ("Adhesion of
elastic spheres"); Feng 2000, J. Colloid Interface Sci. 238, 318.

Mesh: the contact edge must be resolved by nodes whose own stiffness exceeds the LJ law's
largest softening stiffness, or single nodes snap on their own (lattice trapping, a mesh
artefact). That spacing shrinks like mu^-2 in units of the contact radius, so the grid is
uniform with that spacing only where the contact edge travels and grows geometrically beyond.
"""
from dataclasses import dataclass
import math
import time
import warnings

import numpy as np

from ..contact import ContactProblem
from ..contact.arclength import trace_curve
from ..elastic import GreenOperator, RadialGrid
from ..errors import MeshResolutionWarning
from ..indenter import Sphere
from ..laws import LennardJones
from ..reference.adhesion import dmt_contact_radius, jkr_contact_radius
from ..reference.maugis import jkr_approach, lj_dugdale_lambda, maugis_pull_off

R_DEFAULT, A_DEFAULT, Z0_DEFAULT = 1e-6, 1e-19, 0.165e-9

#: a priori: the fine spacing keeps the LJ softening stiffness below this fraction of a node's
STIFFNESS_TARGET = 0.4
#: a posteriori: above this local ratio (on any traced state) a node could snap on its own
TRAPPING_LIMIT = 1.0
#: compressive load (units pi R dg) at the deepest point of the sweep: beyond the jump-in
#: landing (which is tensile), so the whole approach-retract cycle is on the curve
PRELOAD = 0.5
#: uniform spacing up to this multiple of the JKR contact radius at PRELOAD (the largest
#: contact of the sweep; JKR bounds Maugis-Dugdale's radius at a given load from above)
FINE_MARGIN = 1.15
#: analysis radius in the same units (the rigid-LJ tail beyond it is added to the force)
ANALYSIS_RADIUS = 4.32


@dataclass
class RegimePoint:
    """One point of the regime map (forces / (pi R dg), separations / z0)."""

    mu: float
    e_star: float
    pull_off: float            # load-controlled pull-off (largest tension on the curve) / pi R dg
    pull_off_displacement: float  # largest tension on the displacement-controlled retract path
    maugis: float              # Maugis-Dugdale pull-off at lambda = 1.157 mu
    jump_in: float | None      # d / z0 of the approach fold
    jump_out: float | None     # d / z0 of the last retract fold
    hysteresis: float          # energy dissipated per cycle / (pi R dg z0), from energy jumps
    hysteresis_trapezoid: float  # the same by integrating F dd around the loop (cross-check)
    n_folds: int               # folds of the traced curve (2 for one S; more: mesh wiggles)
    trapping_ratio: float      # max over states and nodes of -P'(h_k) / K_kk
    n_points: int
    n_solves: int
    nodes: int
    wall_time: float
    curves: dict


def _lj_problem(mu, radius, hamaker, z0, stiffness_target, min_nodes):
    """The smooth-sphere problem at Tabor mu, on a grid fine where the contact edge travels.

    Returns (problem, lj, e_star, a, d_min): a is the analysis radius (m), d_min the
    separation (m) of the deepest point, where the JKR load is PRELOAD pi R dg.
    """
    lj = LennardJones(hamaker, z0)
    dg = lj.work_of_adhesion
    e_star = math.sqrt(radius * dg * dg / (mu**3 * z0**3))
    K = 4 * e_star / 3
    a_unit = (math.pi * dg * radius**2 / K) ** (1 / 3)
    a = max(ANALYSIS_RADIUS * a_unit, math.sqrt(2 * radius * 20 * z0))
    load = PRELOAD * math.pi * radius * dg
    a_max = jkr_contact_radius(load, radius, e_star, dg)
    # the approach for that load in the nearer limit (DMT below mu = 1, JKR above), from
    # where the rigid sphere's LJ force vanishes, d = z0 / 4^(1/6) (eq 14: U(d) = 0)
    if mu < 1:
        delta = dmt_contact_radius(load, radius, e_star, dg) ** 2 / radius
    else:
        delta = jkr_approach(a_max, radius, e_star, dg)
    d_min = z0 / 4 ** (1 / 6) - delta
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


def lj_force(problem, lj, d, w):
    """Force on the disk (N, attractive positive) of a state: the LJ pressure integrated over
    the analysis disk plus the tail beyond it, where the surface is undeformed and the
    paraboloid's LJ force is eq 14's, -2 pi R U(b(a; d)) (the tail is 0.3-11 % of the rigid
    force at d = z0 ... 10 z0 on the regime map's grids)."""
    a, radius = problem.grid.radius, problem.sphere.radius
    h = problem.contour(d) - w
    tail = -2 * math.pi * radius * float(lj.energy(d + a * a / (2 * radius)))
    return problem.grid.force(problem.pressure(h)) + tail


def lj_sphere(mu, *, radius=R_DEFAULT, hamaker=A_DEFAULT, z0=Z0_DEFAULT, tol=1e-19,
              stiffness_target=STIFFNESS_TARGET, min_nodes=120, ds_max=0.5, progress=None):
    """Trace the equilibrium curve of a smooth LJ sphere at Tabor parameter mu (approach from
    d = 12 z0 to a compressive load of about PRELOAD pi R dg) and read the regime-map numbers
    off it. ``ds_max`` is the largest continuation step (units of z0).
    """
    t0 = time.perf_counter()
    problem, lj, e_star, a, d_min = _lj_problem(mu, radius, hamaker, z0, stiffness_target,
                                                   min_nodes)
    dg = lj.work_of_adhesion
    d0 = 12 * z0
    curve = trace_curve(problem, d0, d_min, tol=tol, scale=z0, ds=0.2, ds_max=ds_max,
                        progress=progress)

    def force(d, w):
        return lj_force(problem, lj, d, w)

    scale = math.pi * radius * dg
    paths = {k: curve.branch(k) for k in ("approach", "retract")}
    F = {k: np.array([force(d, w) for _, d, w in v]) for k, v in paths.items()}
    D = {k: np.array([d for _, d, _ in v]) for k, v in paths.items()}

    # hysteresis: the work of the closed cycle is the energy released at the jumps (the
    # interaction beyond a is continuous in d and drops out); the loop integral checks it
    released = 0.0
    for v in paths.values():
        for (k1, d1, w1), (k2, _, w2) in zip(v, v[1:]):
            if k1 == "fold" and k2 == "land":
                released += problem.energy(w1, d1) - problem.energy(w2, d1)
    trap = getattr(np, "trapezoid", None) or np.trapz
    loop = trap(F["retract"], D["retract"]) + trap(F["approach"], D["approach"])

    # pull-off under load control (as Maugis-Dugdale's): the largest tensile force anywhere on
    # the equilibrium curve, refined between the neighbours of the best traced point; under
    # displacement control the retract path may leave the curve (jump-out) before reaching it
    cf = np.array([force(p.d, p.w) for p in curve.points])
    i = int(np.argmax(cf))
    pull = cf[i]
    if 0 < i < len(curve.points) - 1:
        pull = max(pull, curve.maximize(i, force)[0])
    # under displacement control the same maximum is reached if it lies on a stable state;
    # otherwise the retract path jumps out before it, at its largest tension on the path
    pull_disp = pull if curve.points[i].stable else float(np.max(F["retract"]))

    folds_a = [d for kind, d, _ in paths["approach"] if kind == "fold"]
    folds_r = [d for kind, d, _ in paths["retract"] if kind == "fold"]
    trapping = max(problem.node_softening_ratio(problem.contour(p.d) - p.w)
                   for p in curve.points)
    if trapping > TRAPPING_LIMIT:
        warnings.warn(f"mu = {mu:g}: a traced state reached -P'(h)/K_kk = {trapping:.2f} > "
                      f"{TRAPPING_LIMIT} (nodes can snap alone); lower stiffness_target",
                      MeshResolutionWarning, stacklevel=2)
    cd = curve.d
    return RegimePoint(
        mu, e_star, float(pull / scale), pull_disp / scale, maugis_pull_off(lj_dugdale_lambda(mu)),
        folds_a[0] / z0 if folds_a else None, folds_r[-1] / z0 if folds_r else None,
        float(released / (scale * z0)), float(loop / (scale * z0)), len(curve.folds),
        trapping, len(curve.points), curve.n_solves, problem.grid.n,
        time.perf_counter() - t0,
        {"curve_d": cd / z0, "curve_F": cf / scale,
         "curve_stable": np.array([p.stable for p in curve.points]),
         "approach_d": D["approach"] / z0, "approach_F": F["approach"] / scale,
         "retract_d": D["retract"] / z0, "retract_F": F["retract"] / scale,
         "n_factor": curve.n_factor, "n_krylov": curve.n_krylov})


def regime_map(mus, progress=None, **kw):
    """lj_sphere at each mu (keywords passed on); ``progress(i, point)`` after each."""
    out = []
    for i, mu in enumerate(mus):
        out.append(lj_sphere(float(mu), **kw))
        if progress:
            progress(i, out[-1])
    return out


REGIME_HEADER = ["mu", "lambda", "e_star_Pa", "nodes", "pull_off", "pull_off_displacement",
                 "maugis_dugdale", "jump_in_d_over_z0", "jump_out_d_over_z0", "hysteresis",
                 "hysteresis_loop_integral", "n_folds", "trapping_ratio", "n_points",
                 "wall_time_s"]


def write_regime(pts, out_dir):
    """regime.csv (forces / (pi R dg), separations / z0, work / (pi R dg z0)) and the figures.
    Returns the csv path."""
    import csv
    from pathlib import Path

    from ..io.plots import regime_figures

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    with open(out / "regime.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(REGIME_HEADER)
        for p in pts:
            w.writerow([f"{p.mu:.6g}", f"{lj_dugdale_lambda(p.mu):.6g}", f"{p.e_star:.6g}",
                        p.nodes, f"{p.pull_off:.6f}", f"{p.pull_off_displacement:.6f}",
                        f"{p.maugis:.6f}", "" if p.jump_in is None else f"{p.jump_in:.6f}",
                        "" if p.jump_out is None else f"{p.jump_out:.6f}",
                        f"{p.hysteresis:.6g}", f"{p.hysteresis_trapezoid:.6g}", p.n_folds,
                        f"{p.trapping_ratio:.4f}", p.n_points, f"{p.wall_time:.3f}"])
    regime_figures(pts, out)
    return out / "regime.csv"
