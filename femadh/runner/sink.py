"""Where each committed state of a contact run goes: the result's arrays, the csv files and
the progress display, then a safe point (the state is complete on disk)."""
from dataclasses import dataclass
import math

import numpy as np

from ..contact.forces import state_forces
from .. import interrupt
from ..io.progress import advance, begin

#: surface profiles kept in the result per branch (all of them are in fields.csv)
PROFILES = 12


@dataclass
class Committed:
    """What the peak search (and a resume) needs of a committed state: its separation,
    displacements, contact set, contact radius and F_ex - each exactly as written to the
    files (fields.csv, curve.csv), so that a resumed run searches from the same numbers as
    an uninterrupted one."""

    d: float
    w: np.ndarray
    active: np.ndarray
    r_c: float
    f_ex: float


class Sink:
    """Where each state goes as soon as it exists: the result's arrays, the csv files, the
    progress bar; then the interrupt check (a safe point: the state is complete on disk)."""

    def __init__(self, problem, result, writer, progress):
        from ..io.writers import extra_outputs, state_row

        self.problem, self.result, self.writer = problem, result, writer
        self.progress = progress
        # (self.problem: a band that follows the contact edge exchanges the grid mid-sweep)
        self._row = lambda st: state_row(self.problem, st, self._extra)
        self._extra = extra_outputs(problem)
        self.columns = (["d_m", "h0_m", "F_LJ_N", "F_el_N", "F_ex_N", "r_c_m", "n_iter",
                         "residual_m", "converged", "stable", "F_tail_N"]
                        + [o.force for o in self._extra])
        self.rows = {}
        self.profile_picks = {}
        self.bar = None
        self.scene = result.scene
        # the state of largest F_ex and its neighbours on its piece of the branch (the peak
        # search needs them), and a state at the same separation whose F_ex ties it (its
        # bracket may be the wider: see _element)
        self.peak, self._prev, self._need_next = None, None, False
        self._rival = None
        # the problem whose grid the peak's (and the rival's) bracket states are on: a band
        # that follows the edge exchanges grids, and the search solves on the states' own
        # (femadh.runner.tracing.exchange_grid)
        self.peak_problem = self.rival_problem = problem
        # each fold per branch: (committed states of the branch before it, the last state of
        # the departing piece, the landing), the two as Committed records with their F_ex;
        # a landing starts a new piece of the branch (femadh.runner.peak.piece)
        self.pieces = {}
        # the curve's pieces per branch as the states arrive, in the sweep's order:
        # [states, starts at a landing, ends at a fold] (femadh.runner.peak.pieces; recorded
        # by the same rule as the peak's bracket, _element, and replayed with it on resume)
        self.curve_pieces = {}
        # the last committed state of each branch (a resumed branch restarts from it), and
        # the last one whole (state number, branch, State: the checkpoint of a stopped run)
        self.last = {}
        self.last_state = None
        # an instrument's readout solves fresh states between the branch's own
        self.states, self.jump_states = {}, []
        # every committed state's snapshot per branch (the estimate's coarser members
        # start from them: femadh.runner.members)
        self.committed, self.folds = {}, []
        self._keep = getattr(self.scene, "instrument", None) is not None

    def plan(self, branch, n, total=None):
        """A branch of ``total`` states begins (``n`` of them still to compute): which of
        them keep their surface profile."""
        total = n if total is None else total
        self.profile_picks[branch] = _picks(total)
        begin(branch, n)        # the run's display, if one is shown

    def state(self, branch, st):
        from .estimates import check_state

        check_state(self.problem, st, self.scene)
        f = state_forces(self.problem, st)[2]
        snap = Committed(st.d, st.w, st.p_contact != 0, st.r_c, f)
        self._track_peak(branch, snap)
        self.committed.setdefault(branch, []).append(snap)
        if self._keep:
            self.states.setdefault(branch, []).append(st)
        rows = self.rows.setdefault(branch, [])
        if branch in self.profile_picks and len(rows) in self.profile_picks[branch]:
            self._profile(branch, st.d, st.w, st.p_effects.get("lj", 0 * st.w), st.p_contact)
        rows.append([float(v) if not isinstance(v, bool) else v for v in self._row(st)])
        if self.writer:
            k = self.writer.write_state(branch, st)
            self.last_state = (k, branch, st)
        advance()
        self._publish(branch)
        interrupt.check()

    def _profile(self, branch, d, w, p_lj, p_el):
        prof = self.result.profiles.setdefault(
            branch, {"d_m": [], "w_m": [], "P_LJ_Pa": [], "P_el_Pa": []})
        prof["d_m"].append(d)
        prof.setdefault("r_m", []).append(self.problem.grid.nodes.copy())
        prof["w_m"].append(w.copy())
        prof["P_LJ_Pa"].append(p_lj.copy())
        prof["P_el_Pa"].append(p_el.copy())

    def _track_peak(self, branch, snap):
        """A committed state: a candidate for the largest F_ex and the next neighbour of the
        kept one (the last committed state of its branch is kept for a restart)."""
        self._element(branch, snap)
        self.last[branch] = snap

    def _track_fold(self, branch, before, after, count=None):
        """A fold of ``branch``: the departing piece ends at ``before`` (the last state
        found stable on it) and a new piece starts at the landing ``after``; each is a state
        of the curve and a candidate for the largest F_ex. Without this the bracket of a
        peak next to a fold reached across it - an approach's peak just after its jump-in
        was bracketed by the last state before the snap, whose interpolation with the
        contact states the branch test turns down: the search kept the grid value (the
        paper 1 slider, sigma = 0.489 nm, p/psat 0.25, approach only: 3.1e-3 below the
        true maximum, validation/results/peak_after_jump.md)."""
        count = len(self.committed.get(branch, [])) if count is None else count
        self.pieces.setdefault(branch, []).append((count, before, after))
        self._element(branch, before, end=True)
        self._element(branch, after, start=True)

    def _element(self, branch, snap, start=False, end=False):
        """The peak bookkeeping of one state of the curve, in the order of the sweep.

        ``start``: the first state of a piece (a landing): it brackets its own side. ``end``:
        the last state of a piece (a fold's departing state): it is its own next neighbour.
        A state at the separation of the one before it on its piece is that state (a landing
        on a grid separation, a fold right at a committed state): not a new neighbour.
        Ties (the same separation and F_ex within TIE_REL, e.g. approach and retract through
        one contact state): the first is kept unless the other's bracket is wider (it holds
        a part of the curve the first's does not: the first's is cut by a fold)."""
        self._piece(branch, snap, start, end)
        f = snap.f_ex
        prev = self._prev[1] if self._prev is not None and self._prev[0] == branch else None
        if start:
            prev = snap
        elif prev is not None and prev.d == snap.d:
            if end:
                self._close(branch, prev)
            else:
                # (a committed state at a landing's separation is the landing's own state:
                # the next candidate's neighbour from here, as a resume replays it - the
                # replay's landing record has no surface, the committed row's is read back)
                self._prev = (branch, snap)
            return
        self._close(branch, snap)
        peak = self.peak
        if peak is not None and peak[0] != branch and snap.d == peak[3].d and \
                abs(f - peak[1]) <= TIE_REL * abs(peak[1]) and self._rival is None:
            self._rival = [branch, f, prev, snap, snap if end else None]
            self.rival_problem = self.problem
            self._settle()
        elif peak is None or f > peak[1]:
            self.peak = [branch, f, prev, snap, snap if end else None]
            self.peak_problem = self.problem
            self._need_next = not end
            self._rival = None
        self._prev = (branch, snap)

    def _piece(self, branch, snap, start, end):
        """``snap`` joins the curve's pieces of ``branch``: a landing (``start``) or a
        branch's first state opens a piece; a state at the separation of the piece's last
        one is that state (left out, as in :meth:`_element`); a fold's last state (``end``)
        closes its piece."""
        ps = self.curve_pieces.setdefault(branch, [])
        if start or not ps:
            ps.append([[snap], bool(start), False])
        elif not (ps[-1][0] and ps[-1][0][-1].d == snap.d):
            ps[-1][0].append(snap)
        if end:
            ps[-1][2] = True

    def _close(self, branch, snap):
        """``snap`` is the next neighbour of the kept peak (and of its rival) still waiting
        for one on ``branch``."""
        if self._need_next and self.peak is not None and self.peak[0] == branch:
            self.peak[4] = snap
            self._need_next = False
        if self._rival is not None and self._rival[0] == branch and self._rival[4] is None:
            self._rival[4] = snap
            self._settle()

    def _settle(self):
        """The tied rival, once its bracket is complete, takes the kept peak's place if its
        bracket spans more separations (the kept one's is cut by a fold, or missing); with
        equal spans the larger F_ex, as without the rival (the first of equals)."""
        r, p = self._rival, self.peak
        if r[2] is None:                # a branch's first state: no wider bracket
            self._rival = None
            return
        if r[4] is None:                # waits for its next neighbour
            return
        if p[2] is None or p[4] is None or _extent(r) > _extent(p) or (
                _extent(r) == _extent(p) and r[1] > p[1]):
            self.peak, self.peak_problem = r, self.rival_problem
            self._need_next = False
        self._rival = None

    def jump(self, jump):
        p = self.problem
        f_before, f_after = (state_forces(p, s)[2] for s in (jump.before, jump.after))
        self._track_fold(jump.branch, *(Committed(s.d, s.w, s.active, s.r_c, f) for s, f in (
            (jump.before, f_before), (jump.after, f_after))))
        if self._keep:
            self.jump_states.append((jump.branch, jump.before, jump.after))
        # (each fold's last state and landing: where the estimate's members look for theirs)
        self.folds.append((jump.branch, jump.d_fold, jump.d_land, *(
            Committed(s.d, s.w, s.active, s.r_c, math.nan) for s in (jump.before, jump.after))))
        # hysteresis: the energy released by the snap, both states at the landing separation
        # (the closure has no energy: nan)
        released = (math.nan if p.contact_model == "hertz-closure" else
                    float(p.energy(jump.before.w, jump.d_land)
                          - p.energy(jump.after.w, jump.d_land)))
        self.result.jumps.append({
            "branch": jump.branch, "d_fold_m": jump.d_fold, "d_land_m": jump.d_land,
            "resolution_m": jump.resolution,
            "F_ex_before_N": f_before, "F_ex_after_N": f_after,
            "h0_before_m": jump.before.h0, "h0_after_m": jump.after.h0,
            "energy_released_J": released})
        if self.writer:
            self.writer.write_jump(self.result.jumps[-1])

    def _publish(self, branch):
        rows = self.rows[branch]
        cols = list(zip(*rows))
        self.result.branches[branch] = {
            c: np.array(v, dtype=bool if c in ("converged", "stable") else
                        int if c == "n_iter" else float) for c, v in zip(self.columns, cols)}

    def close(self):
        if self.bar is not None:
            self.bar.close()
            self.bar = None
        for prof in self.result.profiles.values():
            for k in list(prof):
                # profiles on exchanged grids (a band following the edge) differ in length
                same = len({np.size(x) for x in prof[k]}) <= 1
                prof[k] = np.array(prof[k]) if same else np.array(prof[k], dtype=object)

    def load(self, folder, resume):
        """Resume: the committed states and jumps of the previous run, into the result, as
        the uninterrupted run held them - the rows, the profiles it kept, the peak and its
        neighbours (the folds' states among them) and the last state of each branch (from
        fields.csv and the checkpoint: the same bits; see :meth:`_fold_fields`)."""
        import csv

        from ..io.resume_check import field_states

        rows = resume["rows"]
        with open(folder / "curve.csv") as f:
            head = f.readline().strip().split(",")
        col = [head.index(c) for c in self.columns]
        with open(folder / "jumps.csv", newline="") as f:
            jumps = [{k: (v if k == "branch" else float(v)) for k, v in r.items()}
                     for j, r in zip(range(resume["jumps"]), csv.DictReader(f))]
        folds = {}
        for jp in jumps:
            folds.setdefault(jp["branch"], []).append(jp)
        per_branch = {}
        # the peak bookkeeping replayed over the committed rows and the folds between them,
        # in the sweep's order (state numbers stand in for the states until the few it
        # needs are read; a fold's states carry the committed state beside them on their
        # piece, from which they are re-solved without a checkpoint)
        for k, r in enumerate(rows):
            b = r[1]
            vals = [r[j] for j in col]
            d = float(r[2])
            # (a fold lands beyond the last state before it, along the sweep)
            sign = -1.0 if b == "approach" else 1.0
            while folds.get(b) and (folds[b][0]["d_land_m"] - d) * sign <= 0:
                jp = folds[b].pop(0)
                before, after = (Committed(jp[f"d_{x}_m"], None, None, math.nan,
                                           jp[f"F_ex_{y}_N"])
                                 for x, y in (("fold", "before"), ("land", "after")))
                before.near, after.near = per_branch.get(b, [k])[-1], k
                self._track_fold(b, before, after, len(per_branch[b]))
            self.rows.setdefault(b, []).append(
                [v == "True" if c in ("converged", "stable") else float(v)
                 for c, v in zip(self.columns, vals)])
            per_branch.setdefault(b, []).append(k)
            snap = Committed(d, None, None, float(vals[self.columns.index("r_c_m")]),
                             float(vals[self.columns.index("F_ex_N")]))
            self._track_peak(b, snap)
            self.committed.setdefault(b, []).append(snap)
            snap.w = k                   # (the state number, replaced below)
        for b in self.rows:
            self._publish(b)
        # the profiles the uninterrupted run kept: the picks of each branch's full length
        picks = {b: [ks[j] for j in sorted(_picks(len(self.scene.d_values))) if j < len(ks)]
                 for b, ks in per_branch.items()}
        held = [x for x in (self.peak, self._rival) if x is not None]
        snaps = [s for s in [t for x in held for t in x[2:5]] + list(self.last.values())
                 if s is not None]
        at_fold = [s for s in {id(s): s for s in snaps}.values() if s.w is None]
        snaps = [s for s in snaps if s.w is not None]
        # every committed state, as the uninterrupted run held them: the estimate's coarser
        # members start from them (femadh.runner.members.eligible; without them a resumed
        # adaptive run traced its members whole and its estimates differed from the
        # uninterrupted run's - Fig 3's F_LJ at the deepest state 4.79e-8 -> 5.49e-8 N)
        wanted = set(range(len(rows))) | {s.near for s in at_fold}
        fields = field_states(folder, wanted)
        self.last_k = {b: s.w for b, s in self.last.items()}
        for s in {id(s): s for s in snaps + [c for cs in self.committed.values()
                                             for c in cs]}.values():
            d, w, _, p_el = fields[s.w]
            s.w, s.active = w, p_el != 0
        self._fold_fields(folder, at_fold, fields)
        # the fold records of the jumps kept (the members' fold searches start from them),
        # from the checkpoint: a run stopped by a signal or its time limit resumes with them;
        # a killed one (no checkpoint) without, its members tracing those grid steps instead
        from .checkpoint import load_fold_records

        kept = {(j["branch"], j["d_fold_m"], j["d_land_m"]) for j in jumps}
        self.folds = [(b, df, dl, *(Committed(d, w, a, rc, math.nan) for d, w, a, rc in st))
                      for b, df, dl, *st in load_fold_records(folder)
                      if (b, df, dl) in kept]
        for b, ks in picks.items():
            for k in ks:
                d, w, p_lj, p_el = fields[k]
                self._profile(b, d, w, p_lj, p_el)
        self.result.jumps += jumps

    def _fold_fields(self, folder, snaps, fields):
        """The displacements of the fold states a resumed peak search needs: from the
        checkpoint of a stopped run (the same bits), else (a kill -9: no checkpoint) traced
        to their separation from the committed state beside them on their piece (the same
        equilibrium to the solver's tolerance, as a resumed branch's restart). One that does
        not trace there is replaced in the bracket by that committed state (the bracket the
        search had before folds bounded it), with a warning."""
        from ..contact import solve_state, trace
        from ..errors import ConvergenceError
        from .checkpoint import load_fold_states

        saved = load_fold_states(folder)
        p, sc = self.problem, self.scene
        for s in snaps:
            got = saved.get((s.d, s.f_ex))
            if got is not None:
                s.w, s.active, s.r_c = got
                continue
            d0, w, _, p_el = fields[s.near]
            kw = {} if p.sigma is None else {"active0": p_el != 0}
            st = None
            try:
                # (the neighbour's re-solve inside: its failure is this fallback's, not the
                # resume's)
                st = solve_state(p, d0, w, tol=sc.tolerance, max_iter=sc.max_iter, **kw)
                ok = st.converged and st.stable
                if ok:
                    sw = trace(p, [d0, s.d], branch="retract" if s.d > d0 else "approach",
                               tol=sc.tolerance, start=st, max_iter=sc.max_iter)
                    ok = not sw.jumps
            except ConvergenceError:
                ok = False
            if ok:
                s.w, s.active, s.r_c = sw.states[-1].w, sw.states[-1].active, \
                    sw.states[-1].r_c
                continue
            # the committed neighbour stands in for a bracket's end (the bracket the search
            # had before folds bounded it): its record from the fields, its F_ex only from a
            # converged stable re-solve - a NaN never enters the bracket; without one the
            # bracket ends at its best state on that side (nothing searched there)
            f0 = (state_forces(p, st)[2] if st is not None and st.converged and st.stable
                  else math.nan)
            stand = Committed(d0, w, p_el != 0, math.nan, f0) if math.isfinite(f0) else None
            lost = False
            for x in (self.peak, self._rival):
                if x is None:
                    continue
                if x[3] is s:
                    # the fold state is the kept maximum itself: nothing to search from it
                    # without its surface; its recorded F_ex (the grid maximum) stays the
                    # largest adhesion (a stand-in would put a smaller force in its place)
                    x[2] = x[4] = s
                    lost = True
                else:
                    x[2:5] = [(x[3] if stand is None else stand) if y is s else y
                              for y in x[2:5]]
            if lost:
                # (the neighbour's surface, a start for Newton near the fold state: the
                # estimate's members solve theirs from it; the search reads none of it)
                s.w, s.active = w, p_el != 0
            self.result.warnings.append(
                f"resume: the fold state at d = {s.d * 1e9:.6g} nm (no checkpoint) did not "
                f"trace again from the state at {d0 * 1e9:.6g} nm; " + (
                    "it is the largest adhesion's grid state: the largest adhesion is its "
                    "recorded grid value, not searched between the states" if lost else
                    "the largest adhesion is searched up to that state instead"
                    if stand is not None else
                    "that state did not re-solve either: the largest adhesion is not "
                    "searched on the fold's side of the bracket"))


#: relative difference of F_ex below which two states at one separation tie (round-off: the
#: approach's and the retract's state through one contact state differ by 1.2e-13 relative on
#: the paper 1 slider at sigma = 0.489 nm, p/psat 0.25; a different state differs by far more)
TIE_REL = 1e-9


def _extent(peak):
    """The length (m) of the separations a peak's bracket spans."""
    return abs(peak[4].d - peak[2].d)


def _picks(n):
    """Indices of the states of a branch of n whose surface profiles the result keeps."""
    return set(np.linspace(0, n - 1, min(n, PROFILES)).round().astype(int))
