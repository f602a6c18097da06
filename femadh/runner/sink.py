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
        # the state of largest F_ex and its neighbours (the peak search needs them)
        self.peak, self._prev, self._need_next = None, None, False
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
        """Keep the committed state of largest F_ex (the first of equals) and its neighbours
        on its branch."""
        f = snap.f_ex
        prev = self._prev if self._prev is not None and self._prev[0] == branch else None
        if self._need_next and self.peak is not None and self.peak[0] == branch:
            self.peak[4] = snap
        self._need_next = False
        if self.peak is None or f > self.peak[1]:
            self.peak = [branch, f, prev[1] if prev else None, snap, None]
            self._need_next = True
        self._prev = (branch, snap)
        self.last[branch] = snap

    def jump(self, jump):
        p = self.problem
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
            "F_ex_before_N": state_forces(p, jump.before)[2],
            "F_ex_after_N": state_forces(p, jump.after)[2],
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
        neighbours and the last state of each branch (from fields.csv: the same bits)."""
        import csv

        from ..io.resume_check import field_states

        rows = resume["rows"]
        with open(folder / "curve.csv") as f:
            head = f.readline().strip().split(",")
        col = [head.index(c) for c in self.columns]
        per_branch = {}
        # the peak bookkeeping replayed over the committed rows (state numbers stand in for
        # the states until the few it needs are read)
        for k, r in enumerate(rows):
            b = r[1]
            vals = [r[j] for j in col]
            self.rows.setdefault(b, []).append(
                [v == "True" if c in ("converged", "stable") else float(v)
                 for c, v in zip(self.columns, vals)])
            per_branch.setdefault(b, []).append(k)
            self._track_peak(b, Committed(float(r[2]), None, None,
                                          float(vals[self.columns.index("r_c_m")]), float(
                                              vals[self.columns.index("F_ex_N")])))
            self.last[b].w = k           # (the state number, replaced below)
        for b in self.rows:
            self._publish(b)
        # the profiles the uninterrupted run kept: the picks of each branch's full length
        picks = {b: [ks[j] for j in sorted(_picks(len(self.scene.d_values))) if j < len(ks)]
                 for b, ks in per_branch.items()}
        snaps = [s for s in ([self.peak[2], self.peak[3], self.peak[4]] if self.peak else [])
                 + list(self.last.values()) if s is not None]
        wanted = {s.w for s in snaps} | {k for ks in picks.values() for k in ks}
        fields = field_states(folder, wanted)
        self.last_k = {b: s.w for b, s in self.last.items()}
        for s in {id(s): s for s in snaps}.values():
            d, w, _, p_el = fields[s.w]
            s.w, s.active = w, p_el != 0
        for b, ks in picks.items():
            for k in ks:
                d, w, p_lj, p_el = fields[k]
                self._profile(b, d, w, p_lj, p_el)
        with open(folder / "jumps.csv", newline="") as f:
            for j, r in enumerate(csv.DictReader(f)):
                if j >= resume["jumps"]:
                    break
                self.result.jumps.append({k: (v if k == "branch" else float(v))
                                          for k, v in r.items()})


def _picks(n):
    """Indices of the states of a branch of n whose surface profiles the result keeps."""
    return set(np.linspace(0, n - 1, min(n, PROFILES)).round().astype(int))
