"""A traced equilibrium curve (pseudo-arclength continuation) and the displacement-controlled
approach and retract paths read off it: stable runs, folds, and the landing at fixed d on the
next stable piece (:meth:`EquilibriumCurve.walk`, :meth:`EquilibriumCurve.branch`); what an
experiment reads off it - pull-offs under load and displacement control, the jumps, the
hysteresis - in :func:`read_curve`."""
from dataclasses import dataclass, field
import math

import numpy as np
from scipy import optimize

from ..errors import ConvergenceError

#: arclength resolution of :meth:`EquilibriumCurve.maximize`, relative to its bracket: the
#: value at a smooth maximum is off by ~(curvature) x (this x bracket)^2, ~1e-10 relative
MAXIMIZE_XTOL = 1e-5


@dataclass
class CurvePoint:
    """An equilibrium on the curve: separation d (m), displacements w (m), unit tangent t
    (scaled units, t[-1] = dd/ds), Hessian positive definite (``stable``), iterations."""

    d: float
    w: np.ndarray
    t: np.ndarray
    stable: bool
    n_iter: int
    residual: float
    seg: int = 0           # the grid segment (index into EquilibriumCurve.tracers) it lives on

    @property
    def t_d(self):
        return float(self.t[-1])


@dataclass
class Fold:
    """A fold of the curve between points ``index`` and ``index + 1``, at separation d (m)."""

    index: int
    d: float
    w: np.ndarray
    s_offset: float
    seg: int = 0


@dataclass
class EquilibriumCurve:
    """Points in arclength order from d_start to d_end and the folds between them.

    A curve traced on a grid that moves with the contact edge is made of segments, one per
    grid (``tracers[k].problem``); consecutive points of different segments are the same
    equilibrium on two grids (a seam: at the same d, or near a fold at d differing by the
    grids' difference), not an interval of the curve.
    """

    points: list = field(default_factory=list)
    folds: list = field(default_factory=list)
    n_solves: int = 0
    n_factor: int = 0
    n_krylov: int = 0
    wall_time: float = 0.0
    tracers: list = field(default_factory=list)
    refused: list = field(default_factory=list)   # (d, why) of grid exchanges not made

    @property
    def _tracer(self):
        return self.tracers[-1]

    @property
    def d(self):
        return np.array([p.d for p in self.points])

    def problem_of(self, seg):
        """The ContactProblem (grid) of segment ``seg``."""
        return self.tracers[seg].problem

    def _seam(self, i):
        """True if points i and i+1 lie on different grids (no curve interval between)."""
        return self.points[i].seg != self.points[i + 1].seg

    def walk(self, direction):
        """Segments of the displacement-controlled path in visiting order.

        Returns a list of ``(kind, i, j_or_t)`` items:
        ``("run", i0, i1)`` - stable points i0..i1 (inclusive, either order) visited in turn;
        ``("fold", k, None)`` - the k-th fold reached at the end of the previous run;
        ``("land", a, (s_lo, s_hi))`` - the landing state, on the curve at an arclength offset
        in [s_lo, s_hi] along point a's tangent (s_hi None: up to point a+1).
        Raises ValueError if a fold has no stable landing on the traced curve.
        """
        pts, n = self.points, len(self.points)
        fold_after = {f.index: k for k, f in enumerate(self.folds)}
        sign = -1.0 if direction == "approach" else 1.0     # d decreases on approach
        # runs of consecutive stable points (arc order)
        runs, i = [], 0
        while i < n:
            if pts[i].stable:
                j = i
                while j + 1 < n and pts[j + 1].stable and j not in fold_after:
                    j += 1
                runs.append((i, j))
                i = j + 1
            else:
                i += 1
        if not runs:
            raise ValueError("no stable state on the traced curve")
        out = []
        start = 0 if direction == "approach" else n - 1
        run = next(r for r in runs if r[0] <= start <= r[1])
        lo, hi, i = run[0], run[1], start
        visited = set()
        forced = None       # after a landing: the index direction toward the travel side
        while True:
            visited.add(run)
            # direction along the run in which d moves the right way (after a landing in
            # the first interval of a run, lo == hi: only the landing knows the direction)
            step = forced if forced is not None else (
                1 if hi == lo or sign * (pts[hi].d - pts[lo].d) > 0 else -1)
            end = hi if step == 1 else lo
            out.append(("run", i, end))
            # what lies beyond the run's end: a fold (then jump) or the curve's end
            k_fold = fold_after.get(end) if step == 1 else fold_after.get(end - 1)
            if k_fold is None:
                if end not in (0, n - 1):
                    raise ValueError(f"stability changes at d = {pts[end].d:.6g} m without a "
                                     "fold of the curve (a bifurcation): not handled")
                return out
            d_f = self.folds[k_fold].d
            out.append(("fold", k_fold, None))
            landing = None
            # the nearest stable piece along the curve first: past a lattice micro-loop (a
            # fold pair as the edge crosses a node, d within ~1e-4 z0) the surface descends
            # to the adjacent piece of the same branch, not to a distant branch at that d
            k_at = self.folds[k_fold].index
            for r in sorted(runs, key=lambda r: min(abs(r[0] - k_at), abs(r[1] - k_at))):
                if r in visited:
                    continue
                # a stable branch's pieces: fold -> first point, point -> point, last -> fold
                # as (from point a, arclength bracket on its tangent, next run point, step)
                pieces = []
                k_in, k_out = fold_after.get(r[0] - 1), fold_after.get(r[1])
                if k_in is not None:
                    f = self.folds[k_in]
                    pieces.append((r[0] - 1, f.d, pts[r[0]].d, (f.s_offset, None),
                                   r[0], r[0]))
                for a in range(r[0], r[1]):
                    if not self._seam(a):
                        pieces.append((a, pts[a].d, pts[a + 1].d, (0.0, None), a, a + 1))
                if k_out is not None:
                    f = self.folds[k_out]
                    pieces.append((r[1], pts[r[1]].d, f.d, (0.0, f.s_offset), r[1], r[1]))
                for a, d_lo, d_hi, bracket, first, last in pieces:
                    da, db = d_lo - d_f, d_hi - d_f
                    if da * db <= 0 and da != db:
                        landing = (r, a, bracket, first, last, db - da)
                        break
                if landing:
                    break
            if landing is None:
                raise ValueError(f"the fold at d = {d_f:.6g} m has no stable landing on the "
                                 "traced curve (trace further, or the curve has an isola)")
            run, a, bracket, first, last, dd = landing
            out.append(("land", a, bracket))
            # continue from the landing toward the travel direction
            if sign * dd > 0:
                lo, hi, i, forced = last, run[1], last, 1
            else:
                lo, hi, i, forced = run[0], first, first, -1

    def _dist(self, p, q):
        tr = self.tracers[p.seg]
        dx = (np.r_[q.w, q.d] - np.r_[p.w, p.d]) / tr.scale
        return float(np.sqrt(tr.omega * (dx[:-1] @ dx[:-1]) + dx[-1] ** 2))

    def _on_curve(self, p, off):
        """(d, w) of the curve point at arclength offset ``off`` from point p, or None."""
        tr = self.tracers[p.seg]
        xc, _, _, ok = tr.correct(np.r_[p.w, p.d] / tr.scale + off * p.t, p.t)
        return (xc[-1] * tr.scale, xc[:-1] * tr.scale) if ok else None

    def point_at(self, i, d, bracket=(0.0, None)):
        """The curve's state w (m) at separation d beyond point i: root of d(s) = d in the
        arclength offset s from point i, within ``bracket`` (s_hi None: up to point i+1), on
        which d(s) must be monotone."""
        pts = self.points
        a, b = pts[i], pts[i + 1]
        s_lo, s_hi = bracket[0], self._dist(a, b) if bracket[1] is None else bracket[1]
        known = {0.0: (a.d, a.w)}
        if bracket[1] is None:
            known[s_hi] = (b.d, b.w)

        def at(s):
            r = known.get(s) or self._on_curve(a, s)
            if r is None:
                raise ConvergenceError("a state on the traced curve could not be recomputed",
                                       d=d, residual=math.nan, n_iter=0)
            known[s] = r
            return r[0] - d
        s = bracketed_root(at, s_lo, s_hi, xtol=1e-12 * self._dist(a, b))
        return known[s][1] if s in known else self._on_curve(a, s)[1]

    def maximize(self, i, value):
        """Largest value(d, w) on the curve between points i-1 and i+1 (bounded search in
        arclength; each evaluation is a corrected point). Returns (value, d, w)."""
        pts = self.points
        # a seam is no interval of the curve: search only the neighbours on point i's grid
        s1 = 0.0 if self._seam(i - 1) else self._dist(pts[i - 1], pts[i])
        s2 = 0.0 if self._seam(i) else self._dist(pts[i], pts[i + 1])
        best = [value(pts[i].d, pts[i].w), pts[i].d, pts[i].w]
        if s1 + s2 == 0.0:
            return tuple(best)

        def neg(s):
            r = self._on_curve(*((pts[i - 1], s) if s < s1 else (pts[i], s - s1)))
            if r is None:
                return -best[0]
            v = value(*r)
            if v > best[0]:
                best[:] = [v, r[0], r[1]]
            return -v
        optimize.minimize_scalar(neg, bounds=(0.0, s1 + s2), method="bounded",
                                 options={"xatol": MAXIMIZE_XTOL * (s1 + s2)})
        return tuple(best)

    def branch(self, direction, segments=False):
        """The states along the displacement-controlled path, folds and landings included.

        Parameters
        ----------
        direction : {"approach", "retract"}
        segments : bool
            Also return each state's grid segment (see :meth:`problem_of`).

        Returns
        -------
        list of (kind, d, w) or (kind, d, w, seg)
            In visiting order; kind is ``"point"`` (a curve point), ``"fold"`` (the last state
            of a branch) or ``"land"`` (where it jumped to, at the same d, recomputed on the
            curve between the two points that bracket it).
        """
        pts = self.points
        out = []
        for kind, i, j in self.walk(direction):
            if kind == "run":
                for k in range(i, j + (1 if j >= i else -1), 1 if j >= i else -1):
                    out.append(("point", pts[k].d, pts[k].w, pts[k].seg))
            elif kind == "fold":
                f = self.folds[i]
                out.append(("fold", f.d, f.w, f.seg))
            else:
                d_f = out[-1][1]
                out.append(("land", d_f, self.point_at(i, d_f, j), pts[i].seg))
        return out if segments else [e[:3] for e in out]


    def cycle_work(self, force):
        """Work (J) of the approach-retract cycle, the loop integral of F dd along the two
        displacement-controlled paths (the area their closed loop encloses in the (d, F)
        plane; the jumps at fixed d add none), so that it equals the energy the jumps
        release (the hysteresis) up to the quadrature error.

        Each stretch of a path lies on one interval of the curve (between two of its points,
        or a point and a fold or a landing); there d and F = force(d, w) (N) are interpolated
        quadratically in the offset along the interval's first tangent through a midpoint
        corrected onto the curve, and F d'(s) is integrated by Simpson's rule (exact for
        these quadratics: error O(stretch^5) per stretch)."""
        pts = self.points
        total = 0.0

        def offset(a, d, w):
            p, tr = pts[a], self.tracers[pts[a].seg]
            dx = (np.r_[w, d] - np.r_[p.w, p.d]) / tr.scale
            return float(tr.omega * (p.t[:-1] @ dx[:-1]) + p.t[-1] * dx[-1])

        def stretch(a, lo, hi):
            """int F dd from state lo to state hi (each (d, w)) on interval a."""
            s0, s1 = offset(a, *lo), offset(a, *hi)
            if s0 == s1:
                return 0.0
            mid = self._on_curve(pts[a], 0.5 * (s0 + s1))
            if mid is None:
                raise ConvergenceError("cycle work: a midpoint on the curve could not be "
                                       "recomputed", d=lo[0], residual=math.nan, n_iter=0)
            d0, dm, d1 = lo[0], mid[0], hi[0]
            f0, fm, f1 = force(*lo), force(*mid), force(*hi)
            # Simpson on F(s) d'(s) with d' of the quadratic through the three points
            return (f0 * (-3 * d0 + 4 * dm - d1) + 4 * fm * (d1 - d0)
                    + f1 * (d0 - 4 * dm + 3 * d1)) / 6.0

        for direction in ("approach", "retract"):
            here = None             # (d, w) where the path stands, and its interval side
            for kind, i, j in self.walk(direction):
                if kind == "run":
                    if here is not None:            # from the landing to the run's start
                        a = here[2]
                        total += stretch(a, here[:2], (pts[i].d, pts[i].w))
                    step = 1 if j >= i else -1
                    for k in range(i, j, step):
                        a = min(k, k + step)
                        if not self._seam(a):
                            total += stretch(a, (pts[k].d, pts[k].w),
                                             (pts[k + step].d, pts[k + step].w))
                    end = j
                    here = None
                elif kind == "fold":
                    f = self.folds[i]
                    total += stretch(f.index, (pts[end].d, pts[end].w), (f.d, f.w))
                    d_f = f.d
                else:
                    w = self.point_at(i, d_f, j)
                    here = (d_f, w, i)
        return total


@dataclass
class CycleReadout:
    """What an experiment reads off a traced curve (SI units; forces attractive positive).

    Attributes
    ----------
    pull_off : float
        Load-controlled pull-off (N): the largest tension anywhere on the curve, refined
        between the neighbours of the best traced point (:meth:`EquilibriumCurve.maximize`).
    pull_off_displacement : float or None
        Displacement-controlled pull-off (N): the tension at the fold where the retract path
        leaves the contact (the last retract fold); None without folds.
    pull_off_path : float
        The largest tension (N) a displacement-controlled retract meets: ``pull_off`` where
        its point is stable (the path passes through it), else the largest along the retract
        path (its points, folds and landings).
    jump_in, jump_out : float or None
        Separations (m) of the approach path's first fold and the retract path's last.
    hysteresis : float
        Energy (J) released at the jumps of one approach-retract cycle (the energies of the
        fold and landing states at the same d), i.e. the work the cycle dissipates.
    loop_work : float
        The same by the trapezoidal loop integral of F dd along both paths (a cross-check).
    force : ndarray
        F (N) at each point of the curve.
    paths : dict
        {"approach" | "retract": (d (m), F (N))} along the displacement-controlled paths.
    """

    pull_off: float
    pull_off_displacement: float | None
    pull_off_path: float
    jump_in: float | None
    jump_out: float | None
    hysteresis: float
    loop_work: float
    force: np.ndarray
    paths: dict


def read_curve(curve, force):
    """Pull-offs, jumps and hysteresis of a traced curve (:class:`CycleReadout`).

    Parameters
    ----------
    curve : EquilibriumCurve
    force : callable(problem, d, w) -> float
        Force (N, attractive positive) of a state on a segment's problem (e.g. the law's
        pressure integrated over the disk plus its exact tail beyond it).

    The hysteresis is the energy released at the jumps: the work of the closed cycle, since
    the interaction beyond the analysis radius is continuous in d and drops out; each jump
    is from a fold state to the landing at the same d, energies from
    ``problem.energy(w, d)`` of their segments' problems.
    """
    pb = curve.problem_of
    paths = {k: curve.branch(k, segments=True) for k in ("approach", "retract")}
    F = {k: np.array([force(pb(g), d, w) for _, d, w, g in v]) for k, v in paths.items()}
    D = {k: np.array([d for _, d, _, _ in v]) for k, v in paths.items()}
    released = 0.0
    for v in paths.values():
        for (k1, d1, w1, g1), (k2, _, w2, g2) in zip(v, v[1:]):
            if k1 == "fold" and k2 == "land":
                released += pb(g1).energy(w1, d1) - pb(g2).energy(w2, d1)
    trap = getattr(np, "trapezoid", None) or np.trapz
    loop = trap(F["retract"], D["retract"]) + trap(F["approach"], D["approach"])
    pts = curve.points
    cf = np.array([force(pb(p.seg), p.d, p.w) for p in pts])
    i = int(np.argmax(cf))
    pull = cf[i]
    if 0 < i < len(pts) - 1:
        seg = pb(pts[i].seg)
        pull = max(pull, curve.maximize(i, lambda d, w: force(seg, d, w))[0])
    r_folds = [(d, w, g) for kind, d, w, g in paths["retract"] if kind == "fold"]
    a_folds = [d for kind, d, _, _ in paths["approach"] if kind == "fold"]
    pull_disp = force(pb(r_folds[-1][2]), *r_folds[-1][:2]) if r_folds else None
    pull_path = float(pull) if pts[i].stable else float(np.max(F["retract"]))
    return CycleReadout(float(pull), pull_disp, pull_path, a_folds[0] if a_folds else None,
                        r_folds[-1][0] if r_folds else None, float(released), float(loop),
                        cf, {k: (D[k], F[k]) for k in D})


def bracketed_root(f, lo, hi, *, xtol):
    """Root of f in [lo, hi] with f(lo) f(hi) <= 0 (scipy's Brent method)."""
    return optimize.brentq(f, lo, hi, xtol=xtol, rtol=4 * np.finfo(float).eps, maxiter=100)
