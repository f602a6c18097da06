"""What the instrument sees: its force-z curve read off the contact's equilibrium states.

The spring (stiffness k, base at z) holds the sphere at d; equilibrium is k (z - d) = F_ex(d),
so every contact equilibrium is an instrument equilibrium at z = d + F / k, and the
instrument reads F_instrument = k (z - d) = F. The spring holds the whole sphere: F is F_ex
plus the laws' force beyond the analysis radius (F_tail, curve.csv), which a truncated disk
would otherwise drop from what the instrument reads.

Which of them the instrument can hold. With the spring the energy is E = U(w, d) + k (z - d)^2
/ 2; its Hessian in (w, d) holds the Hessian at fixed d as a principal block, so a state the
instrument holds is displacement-stable (a principal block of a positive definite matrix is
positive definite). Given that, the Schur complement says it is stable with the spring iff
dF_ex/dd + k > 0 along the displacement-stable branch (dF_ex/dd being U's second derivative in
d with w relaxed), i.e. iff z increases with d there. So the instrument's states are the
displacement-controlled branches' states where dz/dd > 0: the stepped approach and retract
branches hold all of them (their unstable parts never appear on the instrument), and

- the instrument jumps where z turns along a branch (dF_ex/dd = -k: between the displacement
  fold, k -> infinity, and the largest tension, k -> 0), or at a branch's own fold if z has not
  turned before it;
- it jumps at fixed z in the direction its energy falls, dE/dd = k (z(d) - z_J): toward the flat
  on approach (z has a minimum), away on retract (a maximum); it lands on the nearest state in
  that direction with the same z, dz/dd > 0 (the first energy minimum the quasi-static sphere
  reaches).

The readout interpolates between the computed states (a parabola through three at a turning
point, a line at a landing); its error is reported as the readout's resolution.
"""
from dataclasses import dataclass, field
import math

import numpy as np

#: the walk visits at most this many jumps and seams per piece of branch (a budget: a curve
#: that needs more is refused, naming where it stopped)
MAX_EVENTS_PER_PIECE = 4
#: two states closer in d than this fraction of the local state spacing are the same state
#: (a seam between two traces of one branch, or a landing state repeated in the rows)
SAME_STATE = 1e-6
#: a seam (another trace of the same branch) lies within this fraction of the local spacing
SEAM_FRACTION = 0.5


@dataclass
class Piece:
    """A run of displacement-stable states of one branch, sorted by d (ascending).

    ``fold_lo`` / ``fold_hi``: the branch ends at that end in a displacement fold (a jump of
    the displacement-controlled trace), not merely where this trace stopped."""

    d: np.ndarray
    F: np.ndarray
    branch: str
    fold_lo: bool = False
    fold_hi: bool = False


@dataclass
class InstrumentPath:
    """The instrument's approach and retract paths.

    Attributes
    ----------
    stiffness : float
        k (N/m).
    paths : dict
        branch -> dict of arrays z_m, d_m, F_N and list kind ("point", "fold", "land", "seam")
        in the order the drive visits them.
    jumps : list of dict
        branch, z_m, d_fold_m, d_land_m, F_before_N, F_after_N, and the readout's resolution
        of each (resolution_z_m, resolution_d_m, resolution_F_N).
    """

    stiffness: float
    paths: dict = field(default_factory=dict)
    jumps: list = field(default_factory=list)

    @property
    def incomplete(self):
        """Why the paths stop short of the drive's end (a jump that lands beyond the traced
        separations), each path's reason, or None."""
        return "; ".join(p["incomplete"] for p in self.paths.values() if p["incomplete"]) \
            or None

    def brackets(self):
        """The intervals between computed states (branch, d_lo, d_hi) around z's turning
        points, where the readout interpolates the jumps' positions and the snap-off. Fresh
        states there sharpen it (:func:`femadh.runner.instrument.refine_instrument`)."""
        return [j["turn"] for j in self.jumps]

    def headline(self):
        """The numbers the instrument records (SI), and their readout resolution as
        ``<name>_resolution``: pull_off_N (the largest tension of the retract path),
        snap_off_N (the tension at which it jumps out), jump_in_d_m / jump_in_z_m (the first
        jump of the approach), jump_out_d_m / jump_out_z_m (the last of the retract),
        hysteresis_J (the work the loop encloses, the integral of F dz around it)."""
        out = {"stiffness_N_per_m": self.stiffness}
        ins = [j for j in self.jumps if j["branch"] == "approach"]
        outs = [j for j in self.jumps if j["branch"] == "retract"]
        if ins:
            j = ins[0]
            out.update(jump_in_d_m=j["d_fold_m"], jump_in_d_m_resolution=j["resolution_d_m"],
                       jump_in_z_m=j["z_m"], jump_in_z_m_resolution=j["resolution_z_m"])
        if outs:
            j = outs[-1]
            out.update(jump_out_d_m=j["d_fold_m"],
                       jump_out_d_m_resolution=j["resolution_d_m"],
                       jump_out_z_m=j["z_m"], jump_out_z_m_resolution=j["resolution_z_m"],
                       snap_off_N=j["F_before_N"], snap_off_N_resolution=j["resolution_F_N"])
        ret = self.paths.get("retract")
        if ret is not None and len(ret["F_N"]):
            F, d, kind = ret["F_N"], ret["d_m"], ret["kind"]
            i = int(np.argmax(F))
            value, res = F[i], 0.0
            # an interior maximum between computed states: the parabola's vertex
            if 0 < i < len(F) - 1 and kind[i - 1] == kind[i] == kind[i + 1] == "point":
                v, _ = _vertex(d[i - 1:i + 2], F[i - 1:i + 2])
                if v is not None and v > value:
                    value, res = v, v - F[i]
            if outs and outs[-1]["F_before_N"] >= value:
                value, res = outs[-1]["F_before_N"], outs[-1]["resolution_F_N"]
            out.update(pull_off_N=float(value), pull_off_N_resolution=float(abs(res)))
        if "approach" in self.paths and "retract" in self.paths and not self.incomplete:
            parts = {b: (_loop_integral(self.paths[b], 1), _loop_integral(self.paths[b], 2))
                     for b in ("approach", "retract")}
            w = sum(v[0] for v in parts.values())
            # trapezoid in z, second order: Richardson's difference to every other state, per
            # path in magnitude (the two paths' errors need not cancel where their states
            # differ, e.g. fresh states on one of them)
            out.update(hysteresis_J=float(w), hysteresis_J_resolution=sum(
                abs(a - h) for a, h in parts.values()) / 3.0)
        return out


def stable_pieces(branches, jumps):
    """Cut the displacement-controlled branches into runs of stable states at their jumps.

    Parameters
    ----------
    branches : dict
        branch -> arrays (``d_m``, ``F_ex_N``), as ContactResult.branches.
    jumps : list of dict
        ContactResult.jumps (branch, d_fold_m, d_land_m, F_ex_before_N, F_ex_after_N).

    Returns
    -------
    list of Piece
    """
    pieces = []
    for b, cols in branches.items():
        d, F = np.asarray(cols["d_m"], float), np.asarray(cols["F_ex_N"], float)
        if not len(d):
            continue
        tail = _tail(cols, d)
        F_ex, F = F, F + tail(d)
        sign = -1.0 if b == "approach" else 1.0
        js = [j for j in jumps if j["branch"] == b]
        cur, k, fold_start = [], 0, False
        for i in range(len(d)):
            while k < len(js) and cur and _jumped_before(d[i], F_ex[i], js[k], sign):
                j = js[k]
                cur.append((j["d_fold_m"], j["F_ex_before_N"] + tail(j["d_fold_m"])))
                pieces.append(_piece(cur, b, sign, fold_start, True))
                cur, fold_start, k = ([(j["d_land_m"], j["F_ex_after_N"] + tail(j["d_land_m"]))],
                                      False, k + 1)
            if cur and abs(d[i] - cur[-1][0]) <= SAME_STATE * max(abs(d[i]), 1e-12) \
                    and _close(F[i], cur[-1][1]):
                continue          # the landing state, already there
            cur.append((d[i], F[i]))
        pieces.append(_piece(cur, b, sign, fold_start, False))
    return pieces


def _tail(cols, d):
    """F_tail(d) (N): the laws' force beyond the analysis radius on the undeformed sphere, a
    smooth function of d alone, interpolated between the branch's states (0 without it)."""
    if "F_tail_N" not in cols:
        return lambda x: 0.0 * np.asarray(x, float)
    order = np.argsort(d)
    dd, ft = d[order], np.asarray(cols["F_tail_N"], float)[order]
    return lambda x: np.interp(x, dd, ft)


def _close(a, b):
    return abs(a - b) <= 1e-9 * max(abs(a), abs(b), 1e-300)


def _jumped_before(d_i, F_i, jump, sign):
    """Whether ``jump`` happened before the state (d_i, F_i) of its branch: its fold lies
    short of d_i in the travel direction, or the state is its landing."""
    if sign * (d_i - jump["d_fold_m"]) > 0:
        return True
    return d_i == jump["d_land_m"] and _close(F_i, jump["F_ex_after_N"])


def _piece(rows, branch, sign, fold_start, fold_end):
    d, F = (np.array(x, float) for x in zip(*rows))
    if sign < 0:        # approach rows run toward smaller d
        return Piece(d[::-1].copy(), F[::-1].copy(), branch, fold_lo=fold_end,
                     fold_hi=fold_start)
    return Piece(d, F, branch, fold_lo=fold_start, fold_hi=fold_end)


def read_instrument(branches, jumps, stiffness, directions=("approach", "retract")):
    """The instrument's paths (an :class:`InstrumentPath`) for a spring of stiffness k (N/m)
    in series with a contact whose displacement-controlled branches and jumps are given
    (ContactResult.branches / .jumps).

    Raises
    ------
    ValueError
        If a jump has no stable landing among the computed states, or the walk exceeds its
        budget (the message names the branch, z and d).
    """
    if not stiffness > 0 or not math.isfinite(stiffness):
        raise ValueError(f"instrument stiffness must be a positive finite number, got "
                         f"{stiffness!r}")
    pieces = stable_pieces(branches, jumps)
    out = InstrumentPath(float(stiffness))
    for b in directions:
        if b not in branches or not len(branches[b]["d_m"]):
            continue
        path, js = _walk(pieces, float(stiffness), b, branches[b])
        out.paths[b] = path
        out.jumps.extend(js)
    return out


def _walk(pieces, k, branch, cols):
    s = -1 if branch == "approach" else 1
    d0 = float(cols["d_m"][0])
    p = next(q for q in pieces if q.branch == branch and np.any(q.d == d0))
    i = int(np.flatnonzero(p.d == d0)[0 if s > 0 else -1])
    F0 = float(p.F[i])
    z_of = lambda q: q.d + q.F / k                               # noqa: E731
    rows, jumps, incomplete = [(d0 + F0 / k, d0, F0, "point", p.branch)], [], None
    budget = MAX_EVENTS_PER_PIECE * len(pieces) + 4
    while True:
        z = z_of(p)
        nxt = i + s
        while 0 <= nxt < len(p.d) and s * (z[nxt] - z[i]) > 0 and s * (p.d[nxt] - p.d[i]) > 0:
            rows.append((z[nxt], p.d[nxt], p.F[nxt], "point", p.branch))
            i, nxt = nxt, nxt + s
        at_end = not 0 <= nxt < len(p.d)
        if at_end and not (p.fold_hi if s > 0 else p.fold_lo):
            if _sweep_end(pieces, p, branch, s):
                break
            kind = "seam"                    # this trace of the branch stops: go on another
            zJ, dJ, FJ, rz, rd, rF = z[i], p.d[i], p.F[i], 0.0, 0.0, 0.0
        elif at_end:
            kind = "fold"                    # the branch's own fold before z turns
            zJ, dJ, FJ = z[i], p.d[i], p.F[i]
            j0 = i - s if 0 <= i - s < len(p.d) else i
            rz, rd, rF = abs(z[i] - z[j0]), abs(p.d[i] - p.d[j0]), abs(p.F[i] - p.F[j0])
            turn = (p.branch, *sorted((p.d[j0], p.d[i])))
        else:
            kind = "fold"                    # z turns between states i and nxt
            zJ, dJ, FJ, rz, rd, rF = _turning_point(p, z, i, s)
            lo, hi = max(min(i, nxt) - 1, 0), min(max(i, nxt) + 1, len(p.d) - 1)
            turn = (p.branch, p.d[lo], p.d[hi])
        budget -= 1
        if budget < 0:
            raise ValueError(f"the instrument's {branch} path exceeds its budget of "
                             f"{MAX_EVENTS_PER_PIECE} jumps per piece of branch at z = "
                             f"{zJ * 1e9:.6g} nm, d = {dJ * 1e9:.6g} nm")
        q, a, dL, FL = _landing(pieces, k, zJ, dJ, s, seam=kind == "seam", scale=_spacing(p),
                                origin=(p, FJ))
        if q is None:
            if kind == "seam":
                break                        # no other trace goes on: the path ends here
            # the jump is read; where it lands lies beyond the traced separations
            rows.append((zJ, dJ, FJ, "fold", p.branch))
            jumps.append(_jump(branch, zJ, dJ, math.nan, FJ, math.nan, rz, rd, rF, 0.0))
            jumps[-1]["turn"] = turn
            ends = [q.d[-1] if s > 0 else q.d[0] for q in pieces]
            edge = max(ends) if s > 0 else min(ends)
            incomplete = (f"the instrument's {branch} jump at z = {zJ * 1e9:.6g} nm (d = "
                          f"{dJ * 1e9:.6g} nm, F = {FJ:.4g} N) lands beyond the traced "
                          f"separations: extend the sweep past d = {edge * 1e9:.4g} nm to see "
                          "where (the instrument's hysteresis is not reported)")
            break
        if kind == "fold":
            # the landing's interpolation error: the line against the parabola through the
            # landing segment and its neighbour
            rows.append((zJ, dJ, FJ, "fold", p.branch))
            rows.append((zJ, dL, FL, "land", q.branch))
            jumps.append(_jump(branch, zJ, dJ, dL, FJ, FL, rz, rd, rF,
                               _landing_error(q, a, dL)))
            jumps[-1]["turn"] = turn
        else:
            rows.append((zJ, dL, FL, "seam", q.branch))
        # go on from the landing, on segment [a, a+1] of piece q, toward the drive's direction
        p, i = q, (a + 1 if s > 0 else a)
        rows.append((p.d[i] + p.F[i] / k, p.d[i], p.F[i], "point", p.branch))
    z, d, F, kinds, of = zip(*rows)
    return {"z_m": np.array(z), "d_m": np.array(d), "F_N": np.array(F),
            "kind": list(kinds), "branch_of": list(of), "incomplete": incomplete}, jumps


def _jump(branch, z, d_fold, d_land, F_before, F_after, rz, rd, rF, r_land):
    return {"branch": branch, "z_m": float(z), "d_fold_m": float(d_fold),
            "d_land_m": float(d_land), "F_before_N": float(F_before),
            "F_after_N": float(F_after), "resolution_z_m": float(rz),
            "resolution_d_m": float(rd), "resolution_F_N": float(rF),
            "resolution_land_F_N": float(r_land)}


def _sweep_end(pieces, p, branch, s):
    """Whether piece p's end in direction s is the extreme separation any trace reached."""
    end = p.d[-1] if s > 0 else p.d[0]
    ends = [q.d[-1] if s > 0 else q.d[0] for q in pieces]
    return end == (max(ends) if s > 0 else min(ends))


def _spacing(p):
    return float(np.max(np.abs(np.diff(p.d)))) if len(p.d) > 1 else 0.0


def _parabola(x, y):
    """Coefficients (highest first) of the parabola through three points (x distinct), by
    divided differences: exact where a least-squares fit of nearly coincident abscissae (fresh
    states picometres apart) is ill-conditioned. None if two abscissae coincide."""
    if x[0] == x[1] or x[1] == x[2] or x[0] == x[2]:
        return None
    f01 = (y[1] - y[0]) / (x[1] - x[0])
    f12 = (y[2] - y[1]) / (x[2] - x[1])
    a = (f12 - f01) / (x[2] - x[0])
    b = f01 - a * (x[0] + x[1])
    return np.array([a, b, y[0] - a * x[0] ** 2 - b * x[0]])


def _vertex(x, y):
    """Vertex (value, abscissa) of the parabola through three points, or (None, None)."""
    c = _parabola(x - x[1], y)
    if c is None or c[0] == 0:
        return None, None
    xv = -c[1] / (2 * c[0])
    if not (min(x - x[1]) <= xv <= max(x - x[1])):
        return None, None
    return float(np.polyval(c, xv)), float(xv + x[1])


def _turning_point(p, z, i, s):
    """z's turning point near state i (z stops moving the drive's way between i and i+s):
    the parabola's vertex through the three states around the extreme, F and d there by the
    same parabola in d. Returns z, d, F and their resolutions (vertex minus the state)."""
    j = i if 0 < i < len(p.d) - 1 else min(max(i, 1), len(p.d) - 2)
    sl = slice(max(j - 1, 0), j + 2)

    def the_state():
        # the state itself, resolved to its bracket (fresh states sharpen it)
        return (z[i], p.d[i], p.F[i], float(np.max(np.abs(z[sl] - z[i]))),
                float(np.max(np.abs(p.d[sl] - p.d[i]))),
                float(np.max(np.abs(p.F[sl] - p.F[i]))))
    if len(p.d) < 3:
        return the_state()
    zv, dv = _vertex(p.d[sl], z[sl])
    c = None if zv is None else _parabola(p.d[sl] - p.d[j], p.F[sl])
    if c is None:
        return the_state()
    Fv = float(np.polyval(c, dv - p.d[j]))
    if _overshoots(p.d[sl], p.F[sl], dv, Fv):
        # F runs monotonically through the three states but the parabola puts an extremum of
        # its own between two of them: the curve is not locally parabolic there (a step-like
        # F, e.g. a meniscus that forms within one step), and the vertex is an extrapolation
        # (it read z and F far beyond every state: a repulsive F between attractive states).
        return the_state()
    return zv, dv, Fv, abs(zv - z[i]), abs(dv - p.d[i]), abs(Fv - p.F[i])


def _overshoots(d, F, dv, Fv):
    """Whether a parabola's value Fv at dv leaves the range of the two states around dv while
    F is monotone through the three states (d ascending): an interpolant of monotone data
    that creates an extremum between them (a monotone interpolant never does)."""
    if (F[1] - F[0]) * (F[2] - F[1]) < 0:
        return False                     # F turns here: the parabola's extremum is the curve's
    a, b = (F[0], F[1]) if dv <= d[1] else (F[1], F[2])
    tol = 1e-9 * max(abs(F[0]), abs(F[1]), abs(F[2]))
    return not min(a, b) - tol <= Fv <= max(a, b) + tol


def _landing(pieces, k, zJ, dJ, s, *, seam, scale, origin):
    """The nearest state in direction s from dJ with z = zJ and dz/dd > 0: (piece, segment
    index a, d, F), or (None, ...). A seam (another trace of the same branch, going on where
    this one stopped) is a state within half the local spacing of dJ on either side: the two
    traces' interpolations differ by their interpolation error, not more."""
    best, tol = None, (SEAM_FRACTION if seam else SAME_STATE) * max(scale, 1e-300)
    p, FJ = origin
    step_F = float(np.max(np.abs(np.diff(p.F)))) if len(p.F) > 1 else 0.0
    for q in pieces:
        if q is p and seam:
            continue                 # a seam goes on along another trace
        if not seam and q is not p and q.d[0] <= dJ <= q.d[-1] and \
                abs(np.interp(dJ, q.d, q.F) - FJ) <= step_F:
            # another trace of the departing branch (it passes through the departing state
            # within one state's change of force): its linear interpolation across z's turn
            # would offer a landing on the branch the instrument has just left
            continue
        z = q.d + q.F / k
        dz, dd = np.diff(z), np.diff(q.d)
        # segments the instrument holds (dz/dd > 0) whose z range holds zJ
        ok = (dz > 0) & (dd > 0) & (np.minimum(z[:-1], z[1:]) <= zJ) & \
            (zJ <= np.maximum(z[:-1], z[1:]))
        for a in np.flatnonzero(ok):
            t = (zJ - z[a]) / dz[a]
            dL = q.d[a] + t * dd[a]
            gap = s * (dL - dJ)
            if (abs(gap) > tol) if seam else (gap < tol):
                continue
            gap = abs(gap)
            if best is None or gap < best[0]:
                best = (gap, q, int(a), dL, q.F[a] + t * (q.F[a + 1] - q.F[a]))
    return (None, None, None, None) if best is None else best[1:]


def _landing_error(q, a, dL):
    """|parabola - line| at dL over the landing segment and a neighbour (N)."""
    if len(q.d) < 3:
        return 0.0
    j = min(max(a, 1), len(q.d) - 2)
    sl = slice(j - 1, j + 2)
    c = _parabola(q.d[sl] - q.d[j], q.F[sl])
    if c is None:
        return 0.0
    t = (dL - q.d[a]) / (q.d[a + 1] - q.d[a])
    line = q.F[a] + t * (q.F[a + 1] - q.F[a])
    return abs(float(np.polyval(c, dL - q.d[j])) - line)


def _loop_integral(path, step):
    """Sum of F dz along the path in drive order (trapezoids between consecutive states of
    one run; a jump is at fixed z and adds nothing), using every ``step``-th state of each
    run (step 2: the Richardson partner of the resolution estimate)."""
    z, F, kind = path["z_m"], path["F_N"], path["kind"]
    total, run = 0.0, [0]
    for i in range(1, len(z)):
        if kind[i] in ("land", "seam") or kind[i - 1] == "fold":
            total += _trapz(z, F, run, step)
            run = [i]
        else:
            run.append(i)
    return total + _trapz(z, F, run, step)


def _trapz(z, F, idx, step):
    if len(idx) < 2:
        return 0.0
    sel = idx[::step]
    if sel[-1] != idx[-1]:
        sel = sel + [idx[-1]]
    zz, FF = z[sel], F[sel]
    return float(np.sum(0.5 * (FF[1:] + FF[:-1]) * np.diff(zz)))
