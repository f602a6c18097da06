"""A simulated force curve as a function a measured curve can be compared with.

A femadh run gives F_ex at the separations it solved, per branch, and its jumps (folds). The
model at a measured point is the run's curve of that point's branch, interpolated linearly in
the separation ``d = z - z_offset``, in the AFM sign convention ``F_AFM = -F_ex``
(:mod:`femadh.io.force_curve`). A jump is a vertical step at its fold separation: the state
before it is inserted there, so that the step does not smear over the grid interval around
the fold (and the model moves continuously with the parameters except where a measured point
crosses a fold). Beyond the simulated range the end values are used: the scene's sweep should
cover the measured range (:func:`coverage` counts the points outside).
"""
from dataclasses import dataclass, field

import numpy as np


@dataclass
class SimCurve:
    """Per branch: position ``x`` (ascending, m) and force ``f`` (N, AFM sign: repulsive
    positive), with each jump's step inserted; ``jumps``: (branch, x, f_before, f_after);
    ``x_kind``: "d" (femadh's separation) or "z" (an instrument's piezo position)."""

    x: dict = field(default_factory=dict)
    f: dict = field(default_factory=dict)
    jumps: list = field(default_factory=list)
    x_kind: str = "d"

    def force_at(self, z, branch, offset):
        """Model force (N, AFM sign) at measured positions ``z`` (m) of the given branches
        (array of "approach"/"retract"), for the contact-point offset ``offset`` (m)."""
        z = np.asarray(z, float)
        out = np.empty_like(z)
        for b in np.unique(branch):
            sel = branch == b
            out[sel] = np.interp(z[sel] - offset, self.x[b], self.f[b])
        return out

    def slope_at(self, z, branch, offset, h):
        """d(model force)/d(offset) by a central difference of step ``h`` (m): no run needed."""
        return (self.force_at(z, branch, offset + h) - self.force_at(z, branch, offset - h)) \
            / (2 * h)

    def range(self, b):
        return float(self.x[b][0]), float(self.x[b][-1])


def sim_curve(res):
    """The :class:`SimCurve` of a ContactResult (or any object with ``branches`` and
    ``jumps``). A run with an [instrument] (``res.instrument["paths"]``, or z_m and
    F_instrument_N columns) gives the model in the drive position z, which a measured piezo
    height compares with; otherwise in the separation d."""
    out = SimCurve()
    paths = (getattr(res, "instrument", None) or {}).get("paths")
    if paths:
        return _instrument_curve(paths)
    for b, cols in res.branches.items():
        if not len(cols["d_m"]):
            continue
        # the instrument's columns as curve.csv carries them (a result read back from
        # disk): the measured curve is compared in the drive z; F_instrument_N = k (z - d)
        # has F_ex's sign (adhesion positive), hence the minus for the AFM convention
        if "z_m" in cols and "F_instrument_N" in cols:
            out.x_kind = "z"
            x, f = np.asarray(cols["z_m"], float), -np.asarray(cols["F_instrument_N"], float)
            jumps = []
        else:
            x, f = np.asarray(cols["d_m"], float), -np.asarray(cols["F_ex_N"], float)
            jumps = [j for j in res.jumps if j["branch"] == b]
        x, f = list(x), list(f)
        for j in jumps:
            _insert_jump(x, f, b, j)
            out.jumps.append((b, float(j["d_fold_m"]), -float(j["F_ex_before_N"]),
                              -float(j["F_ex_after_N"])))
        x, f = np.array(x), np.array(f)
        if x[0] > x[-1]:                # approach runs towards smaller d: make x ascending
            x, f = x[::-1], f[::-1]
        if np.any(np.diff(x) < 0):     # a path that is not monotone in x (never seen)
            k = np.argsort(x, kind="stable")
            x, f = x[k], f[k]
        out.x[b], out.f[b] = x, f
    return out


def _instrument_curve(paths):
    """The model in the drive position z of an [instrument] run: its paths (branch -> z_m,
    d_m, F_N, kind in drive order) already hold each jump as a fold and a landing at the same
    z. F_N = k (z - d) has F_ex's sign (adhesion positive): minus for the AFM convention."""
    out = SimCurve(x_kind="z")
    for b, p in paths.items():
        x, f = np.asarray(p["z_m"], float), -np.asarray(p["F_N"], float)
        kind = list(p["kind"])
        for i in range(len(kind) - 1):
            if kind[i] == "fold":
                out.jumps.append((b, float(x[i]), float(f[i]), float(f[i + 1])))
        if len(x) and x[0] > x[-1]:
            x, f = x[::-1], f[::-1]
        if np.any(np.diff(x) < 0):
            k = np.argsort(x, kind="stable")
            x, f = x[k], f[k]
        out.x[b], out.f[b] = x, f
    return out


def _insert_jump(x, f, branch, j):
    """Insert a jump's pre-fold state (and its landing, if no state is there) into the path
    ``x, f`` (lists in path order): the step is then vertical at the fold."""
    d_fold, d_land = float(j["d_fold_m"]), float(j["d_land_m"])
    down = branch == "approach"
    # first path index at or beyond the fold in the direction of travel
    k = next((i for i, xi in enumerate(x) if (xi <= d_fold if down else xi >= d_fold)),
             len(x))
    if not any(xi == d_land for xi in x):
        x.insert(k, d_land)
        f.insert(k, -float(j["F_ex_after_N"]))
    x.insert(k, d_fold)
    f.insert(k, -float(j["F_ex_before_N"]))


def coverage(sim, curve, offset):
    """Number of measured points outside the simulated range of their branch."""
    n = 0
    for b in curve.branches():
        lo, hi = sim.range(b)
        d = curve.z[curve.branch == b] - offset
        n += int(np.sum((d < lo) | (d > hi)))
    return n


def initial_offset(sim, curve):
    """A first contact-point offset (m): the measured pull-off (most negative force of the
    retract branch, else of the approach) on the simulated one, then the best offset on a grid
    over half the measured z span each side (no runs: the model is interpolated)."""
    b = "retract" if "retract" in curve.branches() and "retract" in sim.x else \
        curve.branches()[0]
    sel = curve.branch == b
    guess = float(curve.z[sel][np.argmin(curve.force[sel])] - sim.x[b][np.argmin(sim.f[b])])
    span = float(np.ptp(curve.z)) or 1e-9
    return best_offset(sim, curve, guess, span / 2)


def best_offset(sim, curve, guess, half_width, n=401):
    """The offset minimising the squared residual: a grid of ``n`` offsets in
    ``guess +- half_width`` (robust against the local minima the jumps make), then a bounded
    1-D refinement between the grid neighbours of the best."""
    from scipy.optimize import minimize_scalar

    grid = guess + np.linspace(-half_width, half_width, n)

    def rss(o):
        r = sim.force_at(curve.z, curve.branch, o) - curve.force
        return float(r @ r)

    vals = [rss(o) for o in grid]
    k = int(np.argmin(vals))
    lo, hi = grid[max(k - 1, 0)], grid[min(k + 1, n - 1)]
    if hi <= lo:
        return float(grid[k])
    r = minimize_scalar(rss, bounds=(lo, hi), method="bounded",
                        options={"xatol": 1e-6 * (hi - lo)})
    return float(r.x) if r.fun <= vals[k] else float(grid[k])
