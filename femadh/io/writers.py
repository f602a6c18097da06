"""The csv files of a contact run, streamed as each state is computed.

Per state (numbered in the order the run computed it, column ``state``): its node fields go to
``fields.csv``, its diagnostics to ``diagnostics.csv``, its VTK files (FE) to ``vtk/``, and last
its row to ``curve.csv``: curve.csv is the commit record. Each curve.csv row ends with ``crc32``, a
checksum of the row's other cells seeded with the run's scene id (a resumed run checks every
committed row against it: :mod:`femadh.io.resume_check`; ~1 us and 9 bytes a row). Each file grows by whole chunks
(:class:`~femadh.io.atomic.RowLog`), so no reader sees a torn line, and a state is in all the
files or, after a kill between two of them, only in those written before curve.csv - which a
resumed run (and :func:`read_run`) cuts back to the committed states.
"""
import csv
import math
from pathlib import Path
import zlib

import numpy as np

from ..contact.forces import state_forces
from ..laws.registry import extra_outputs  # noqa: F401  (the runner reads it here)
from .atomic import RowLog

CURVE_HEADER = ["state", "branch", "d_m", "h0_m", "F_LJ_N", "F_el_N", "F_ex_N", "r_c_m",
                "n_iter", "residual_m", "converged", "stable", "F_tail_N"]
DIAG_HEADER = ["state", "branch", "d_m", "n_active", "min_gap_minus_sigma_m",
               "min_contact_pressure_Pa", "eq10_violation_inside_m", "node_softening_ratio"]
FIELD_HEADER = ["state", "branch", "d_m", "r_m", "w_m", "h_m", "P_LJ_Pa", "P_el_Pa"]
JUMP_HEADER = ["branch", "d_fold_m", "d_land_m", "resolution_m", "F_ex_before_N",
               "F_ex_after_N", "h0_before_m", "h0_after_m", "energy_released_J"]
#: the last column of curve.csv: the row's checksum (see :func:`row_crc`)
CRC = "crc32"
EQ_CURVE_HEADER = ["arc_index", "d_m", "h0_m", "F_ex_N", "stable", "dd_ds", "residual_m"]

SIGN_NOTE = ("Forces are on the disk, paper 1 eqs 11-13 with area weights: F_LJ = sum P_LJ dA "
             "(attractive positive), F_el = sigma-gap contact force, repulsive positive; "
             "optional F_cap (capillary), F_LJa (asperity adhesion) attractive positive and "
             "F_ela (Greenwood-Williamson asperity elasticity) repulsive positive; "
             "F_ex = F_LJ + F_cap + F_LJa - F_ela - F_el over the analysis disk. The force on "
             "the sphere is -F_ex; adhesion shows as F_ex > 0. F_tail: the laws' force beyond "
             "the analysis radius on the undeformed sphere (the truncation, not in F_ex).")


def row_crc(cells, run_id):
    """Checksum of a curve.csv row (its cells before ``crc32``, as the csv writes them),
    seeded with the run's scene id: a row of another scene, a changed digit, a torn or
    duplicated row does not match. 8 hex digits."""
    seed = zlib.crc32(str(run_id).encode())
    return f"{zlib.crc32(','.join(str(c) for c in cells).encode(), seed):08x}"


def _g(x):
    x = float(x)
    return repr(x) if math.isfinite(x) else str(x)


def field_lines(k, branch, d, columns):
    """fields.csv lines of one state: the cells ``k, branch, d`` then one value of each column
    per node, as :func:`~femadh.io.atomic.csv_text` writes the rows
    ``[k, branch, _g(d), _g(c[0][i]), _g(c[1][i]), ...]`` - byte for byte.

    The per-cell route (a ``_g`` call and a csv cell per value) cost ~11 % of a Fig 3 run
    (88 000 calls; 375 000 at accuracy 1e-4, 867 nodes); here the columns go to Python floats
    at once and ``repr`` formats them (6.2 -> 3.1 ms of CPU for 867 nodes x 5 columns, the
    rest is repr's own shortest-digits search; the writer formats the grid's nodes once per
    grid: 2.5 ms): ``_g(x)`` is ``repr(float(x))`` for every x (finite or not: repr and str of
    a float agree), and no float's repr holds a character csv would quote (',', '"', CR,
    LF), so only the row's leading cells (the branch name) go through the csv writer. A
    column given as a list is taken as its cells already formatted (:func:`formatted`)."""
    from .atomic import csv_text

    head = csv_text([[k, branch, _g(d), ""]])[:-1]          # "k,branch,d," quoted as csv
    cells = [c if isinstance(c, list) else formatted(c) for c in columns]
    return "".join([head + ",".join(row) + "\n" for row in zip(*cells)])


def formatted(values):
    """The cells of a column of numbers as :func:`field_lines` writes them (``_g`` of each:
    the shortest repr that reads back to the same double)."""
    return list(map(float.__repr__, np.asarray(values, dtype=float).tolist()))


def state_row(problem, state, extra):
    """The curve.csv values of a state after ``state`` and ``branch`` (forces in N).
    F_tail is the laws' force beyond the analysis radius (not in F_ex: the truncation)."""
    from ..contact.forces import tail_force

    f_lj, f_el, f_ex = state_forces(problem, state)
    g = problem.grid
    return ([_g(state.d), _g(state.h0), _g(f_lj), _g(f_el), _g(f_ex), _g(state.r_c),
             state.n_iter, _g(state.residual), state.converged, state.stable,
             _g(tail_force(problem, state.d))]
            + [_g(o.sign * g.force(state.p_effects[o.name])) for o in extra])


class ContactWriter:
    """Streams a contact run's csv files (and VTK for FE) into a claimed run folder.

    Parameters
    ----------
    folder : RunFolder
    problem : ContactProblem
    vtk : bool
    resume : dict or None
        ``{"states": k, "jumps": j, "fields_rows": n, "diagnostics_rows": k, "eq_rows": e}``:
        continue after the first k committed states (files are cut back to them).
    """

    def __init__(self, folder, problem, vtk=False, resume=None, run_id=""):
        self.dir = Path(folder.path)
        self.run_id = run_id
        self.problem, self.vtk = problem, vtk
        self.extra = extra_outputs(problem)
        r = resume or {}
        keep = (lambda key: r.get(key)) if resume else (lambda key: None)
        self.curve = RowLog(self.dir / "curve.csv",
                            CURVE_HEADER + [o.force for o in self.extra] + [CRC],
                            keep("states"))
        self.diag = RowLog(self.dir / "diagnostics.csv", DIAG_HEADER, keep("states"))
        self.fields = RowLog(self.dir / "fields.csv",
                             FIELD_HEADER + [o.field for o in self.extra], keep("fields_rows"))
        self.jumps = RowLog(self.dir / "jumps.csv", JUMP_HEADER, keep("jumps"))
        self.eq_curve = None
        self.count = r.get("states", 0)
        self._pvd = self._committed_vtk() if (resume and vtk) else {}
        self._node_cells = (None, None)

    def write_state(self, branch, state):
        """Write one state to every file (curve.csv last); returns its state number."""
        k = self.count
        p = self.problem
        self.fields.append_text(self._field_text(k, branch, state))
        self.diag.append([self._diag_row(k, branch, state)])
        if self.vtk:
            self._write_vtk(k, branch, state)
        cells = [k, branch] + state_row(p, state, self.extra)
        self.curve.append([cells + [row_crc(cells, self.run_id)]])
        self.count += 1
        return k

    def write_jump(self, row):
        """One jump (the dict the run records: see JUMP_HEADER)."""
        self.jumps.append([[row["branch"]] + [_g(row[k]) for k in JUMP_HEADER[1:]]])

    def _field_columns(self, state):
        """The node columns of fields.csv after ``d_m`` (FIELD_HEADER, then the extra
        effects' fields)."""
        p = self.problem
        n = state.w.size
        p_lj = state.p_effects.get("lj", np.zeros(n))
        return [p.grid.nodes, state.w, state.h, p_lj, state.p_contact] + [
            state.p_effects[o.name] for o in self.extra]

    def _field_text(self, k, branch, state):
        cols = self._field_columns(state)
        # the nodes are the same state after state (unless the grid follows the contact
        # edge): their cells are formatted once per grid
        nodes = np.asarray(cols[0], dtype=float)
        key = nodes.tobytes()
        if self._node_cells[0] != key:
            self._node_cells = (key, formatted(nodes))
        return field_lines(k, branch, state.d, [self._node_cells[1]] + cols[1:])

    def _diag_row(self, k, branch, state):
        p = self.problem
        sigma = p.sigma
        return [k, branch, _g(state.d), int(state.active.sum()),
                _g(float(np.min(state.h) - sigma)) if sigma is not None else "",
                _g(float(np.min(state.p_contact[state.active]))) if state.active.any() else "",
                _g(state.diagnostics.get("eq10_violation_inside_m", 0.0)),
                _g(p.node_softening_ratio(state.h))]

    def _committed_vtk(self):
        """The collections' entries of the committed states (resume): the files of state k
        of its branch, as curve.csv lists them."""
        c = read_curve(self.dir / "curve.csv")
        out = {}
        for k, b in zip(c["state"][:self.count], c["branch"][:self.count]):
            k, b = int(k), str(b)
            vol, surf = f"vtk/{b}_{k:04d}.vtu", f"vtk/{b}_surface_{k:04d}.vtu"
            if (self.dir / vol).exists() and (self.dir / surf).exists():
                out.setdefault(b, []).extend([(k, vol, 0), (k, surf, 1)])
        return out

    def _write_vtk(self, k, branch, state):
        from .vtk import write_pvd, write_state

        entries = self._pvd.setdefault(branch, [])
        vol, surf = write_state(self.dir, branch, k, state, self.problem)
        # the collection's time is the state number: ParaView plays the sweep in the order it
        # ran (d is a field of every file; keyed by d the approach would play backwards)
        entries += [(k, vol, 0), (k, surf, 1)]
        write_pvd(self.dir / f"{branch}.pvd", entries)

    def write_curve_point(self, i, point, state):
        """One point of an arclength curve to equilibrium_curve.csv (streamed)."""
        if self.eq_curve is None:
            self.eq_curve = RowLog(self.dir / "equilibrium_curve.csv", EQ_CURVE_HEADER)
        self.eq_curve.append([[i, _g(state.d), _g(state.h0),
                               _g(state_forces(self.problem, state)[2]), point.stable,
                               _g(point.t_d), _g(state.residual)]])

    def close(self):
        for log in (self.curve, self.diag, self.fields, self.jumps, self.eq_curve):
            if log is not None:
                log.close()


def read_curve(path):
    """Read curve.csv into a dict of numpy arrays (and the branch labels); a torn last line
    (from a killed writer) is ignored."""
    with open(path, newline="") as f:
        text = f.read()
    lines = text.split("\n")
    if not text.endswith("\n"):
        lines = lines[:-1]             # a torn last line is not a row
    rows = list(csv.DictReader(lines))
    out = {"branch": np.array([r["branch"] for r in rows])}
    header = rows[0].keys() if rows else CURVE_HEADER
    for k in header:
        if k in ("branch", CRC):
            continue
        if k in ("converged", "stable"):
            out[k] = np.array([r[k] == "True" for r in rows])
        elif k == "state":
            out[k] = np.array([int(r[k]) for r in rows], int)
        else:
            out[k] = np.array([float(r[k]) for r in rows])
    return out


def committed_counts(folder, keep=None):
    """What a resumed run keeps of a previous run's files: its committed states (the complete
    rows of curve.csv, or the first ``keep``), their fields rows, and the jumps that happened
    before its last state on each branch (a jump written just before a kill whose next state
    was not committed is found again by the resumed run)."""
    folder = Path(folder)
    c = read_curve(folder / "curve.csv")
    n = len(c["d_m"]) if keep is None else keep
    last = {}
    for b, d in zip(c["branch"][:n], c["d_m"][:n]):
        last[str(b)] = float(d)
    fields_rows = 0
    with open(folder / "fields.csv", newline="") as f:
        next(f, None)
        for line in f:
            if not line.endswith("\n") or int(line.split(",", 1)[0]) >= n:
                break
            fields_rows += 1
    jumps = 0
    path = folder / "jumps.csv"
    if path.exists():
        with open(path, newline="") as f:
            for r in csv.DictReader(f):
                b, d_land = r["branch"], float(r["d_land_m"])
                if b not in last:
                    break
                reached = d_land >= last[b] if b == "approach" else d_land <= last[b]
                if not reached:
                    break
                jumps += 1
    return {"states": n, "fields_rows": fields_rows, "jumps": jumps}


def read_fields_state(folder, branch):
    """(d, w) of the last committed state of a branch, from fields.csv (resume)."""
    folder = Path(folder)
    c = read_curve(folder / "curve.csv")
    idx = [int(k) for k, b in zip(c["state"], c["branch"]) if b == branch]
    k = idx[-1]
    d, w = None, []
    with open(folder / "fields.csv", newline="") as f:
        for r in csv.DictReader(f):
            if int(r["state"]) == k:
                d = float(r["d_m"])
                w.append(float(r["w_m"]))
            elif w:
                break
    return d, np.array(w)


INSTRUMENT_HEADER = ["branch", "z_m", "d_m", "F_instrument_N", "kind"]


def write_instrument(folder, res):
    """The instrument's outputs of a finished run: ``instrument.csv`` (its approach and
    retract paths in drive order: z, d, the force it reads, and kind point / fold / land /
    seam), and two columns appended to ``curve.csv``: ``z_m`` (the drive at which the
    spring holds that state, d + F/k) and ``F_instrument_N`` (the force the instrument reads
    there, k (z - d); nan for a state its path does not visit). Both files are replaced
    atomically."""
    from .atomic import csv_text, write_atomic

    folder = Path(folder)
    ins = res.instrument
    k = ins["spring"]["stiffness_N_per_m"]
    rows = [INSTRUMENT_HEADER]
    visited = {}
    for b, p in ins["paths"].items():
        for z, d, F, kind, of in zip(p["z_m"], p["d_m"], p["F_N"], p["kind"], p["branch_of"]):
            rows.append([b, _g(z), _g(d), _g(F), kind])
            if kind == "point":
                # keyed by the branch whose state it is: after a landing, the approach path
                # may walk the retract's trace of the contact branch (and vice versa)
                visited[(of, float(d))] = float(F)
    write_atomic(folder / "instrument.csv", csv_text(rows))
    path = folder / "curve.csv"
    with open(path, newline="") as f:
        table = list(csv.reader(f))
    if not table:
        return
    head = table[0]
    if "z_m" in head:
        # a resumed run appended rows without them: recompute both columns for every row
        keep = [i for i, h in enumerate(head) if h not in ("z_m", "F_instrument_N")]
        table = [[r[i] for i in keep if i < len(r)] for r in table]
        head = table[0]
    ib, idd, iF = head.index("branch"), head.index("d_m"), head.index("F_ex_N")
    it = head.index("F_tail_N") if "F_tail_N" in head else None
    out = [head + ["z_m", "F_instrument_N"]]
    for r in table[1:]:
        d = float(r[idd])
        F = float(r[iF]) + (float(r[it]) if it is not None else 0.0)
        out.append(r + [_g(d + F / k), _g(visited.get((r[ib], d), math.nan))])
    write_atomic(path, csv_text(out))
