"""Resuming a contact run: where its committed rows end (every file checked first) and the
checkpoint that lets a stopped sweep continue bit for bit."""
import math

import numpy as np

from ..contact import State


def resume_point(folder, scene, problem, run_id, prev, resume_from, res):
    """What a resumed run keeps of the folder (:mod:`femadh.io.resume_check`): its committed
    states whose rows match their record and are complete in every file, their field rows,
    the jumps before them; None to start from the first state. Notes of a repair go to the
    result's warnings; a damaged record raises DamagedFolder (one line)."""
    from ..io.resume_check import DamagedFolder, check_curve, check_side_files, kept_jumps

    k, rows, notes = check_curve(folder.path, scene, problem, run_id, resume_from)
    if str(prev.get("status", "")).startswith("unknown"):
        # summary.json lost or unreadable: the checksum of the first row, seeded with the
        # scene id, is the proof that the folder holds this scene's run
        if k == 0:
            raise DamagedFolder(f"{folder.path}: summary.json is missing or unreadable and "
                                "curve.csv has no committed row to show it is this scene's "
                                "run; use --overwrite")
        notes.append("resume: summary.json was missing or unreadable; rewritten (curve.csv's "
                     "rows check with this scene)")
    if k:
        k, more = check_side_files(folder.path, rows, problem.grid.n)
        notes += more
    res.warnings += notes
    if k == 0:
        return None
    return {"states": k, "fields_rows": k * problem.grid.n,
            "jumps": kept_jumps(folder.path, rows[:k]), "rows": rows[:k]}


#: the last committed state of a sweep stopped by a signal or its time limit, whole (its
#: factorisation included): a resumed sweep continues from it bit for bit
CHECKPOINT = "checkpoint.npz"


def save_checkpoint(folder, sink):
    """Write the last committed state whole (npz, no pickle), if the sweep has one this
    format holds (complementarity / smooth laws; the closure's states are re-solved)."""
    from ..contact.linalg import TrailingCholesky, TrailingLU
    from ..io.atomic import save_atomic

    if sink is None or sink.writer is None or sink.last_state is None:
        return
    k, branch, st = sink.last_state
    if st.diagnostics or sink.problem.contact_model == "hertz-closure":
        return
    data = {"k": np.array(k), "branch": np.array(branch), "d": np.array(st.d), "w": st.w,
            "h": st.h, "p_contact": st.p_contact, "active": st.active,
            "r_c": np.array(st.r_c), "n_iter": np.array(st.n_iter),
            "residual": np.array(st.residual), "flags": np.array([st.converged, st.stable]),
            "effects": np.array(list(st.p_effects))}
    if st.edge_from is not None:        # the edge predictor's second point (stepping)
        data["edge_from"] = np.array(st.edge_from, dtype=float)
    data.update(_rhythm_data(st.snap_rhythm))
    data.update({f"pe_{name}": v for name, v in st.p_effects.items()})
    data.update(_fold_data(sink))
    data.update(_fold_records(sink))
    lu = st.lu
    if lu is None:
        data["lu_kind"] = np.array("none")
    elif isinstance(lu, TrailingLU):
        data.update(lu_kind=np.array("trailing"), lu=lu.lu, piv=lu.piv,
                    dims=np.array([lu.n, lu.m0, lu.k_valid]))
        if lu.scale is not None:
            data["scale"] = lu.scale
    elif isinstance(lu, TrailingCholesky):
        data.update(lu_kind=np.array("cholesky_kept"), lu=lu.kept, dims=np.array([lu.n, lu.m0,
                                                                             lu.k_valid]))
    elif isinstance(lu, tuple) and len(lu) == 2 and isinstance(lu[0], tuple):
        data.update(lu_kind=np.array("dense"), lu=lu[0][0], piv=lu[0][1], lu_I=lu[1])
    else:
        return
    def write(path):
        with open(path, "wb") as f:
            np.savez(f, **data)
    save_atomic(folder.path / CHECKPOINT, write)


def load_checkpoint(folder, k, d):
    """The whole state number k at separation d from the checkpoint, or None (absent, of
    another state, unreadable: the caller re-solves the state from fields.csv)."""
    from ..contact.linalg import TrailingCholesky, TrailingLU

    path = folder / CHECKPOINT
    if not path.exists():
        return None
    try:
        with np.load(path, allow_pickle=False) as z:
            if int(z["k"]) != k or float(z["d"]) != d:
                return None
            kind = str(z["lu_kind"])
            if kind == "trailing":
                lu = TrailingLU.__new__(TrailingLU)
                lu.n, lu.m0, lu.k_valid = (int(x) for x in z["dims"])
                lu.lu, lu.piv = z["lu"], z["piv"]
                lu.scale = z["scale"] if "scale" in z.files else None
                lu._block = (None, None)
            elif kind == "cholesky_kept":
                # (a checkpoint of an older femadh holds the factor's inverse under
                # "cholesky": read as no factorisation, which the resumed state rebuilds)
                lu = TrailingCholesky.from_kept(z["lu"], *(int(x) for x in z["dims"]))
            elif kind == "dense":
                lu = ((z["lu"], z["piv"]), z["lu_I"])
            else:
                lu = None
            conv, stable = (bool(x) for x in z["flags"])
            st = State(float(z["d"]), z["w"], z["h"],
                       {str(n): z[f"pe_{n}"] for n in z["effects"]}, z["p_contact"],
                       z["active"], float(z["r_c"]), int(z["n_iter"]),
                       float(z["residual"]), conv, stable, lu)
            if "edge_from" in z.files:
                d_p, m_p = (float(x) for x in z["edge_from"])
                st.edge_from = (d_p, int(m_p))
            st.snap_rhythm = _rhythm_read(z)
            return st
    except (OSError, ValueError, KeyError):
        return None


def _rhythm_data(snapshot):
    """The stepping's snap rhythm as the state left it
    (:meth:`~femadh.contact.snap.SnapRhythm.snapshot`: branch, the last lattice-snap folds
    (m), the aimed target and creep end (m, NaN for none)) as arrays; none for None."""
    if snapshot is None:
        return {}
    branch, folds, target, creep_to = snapshot
    return {"snap_branch": np.array(branch), "snap_folds": np.array(folds, dtype=float),
            "snap_aim": np.array([math.nan if x is None else x for x in (target, creep_to)],
                                 dtype=float)}


def _rhythm_read(z):
    """The snapshot :func:`_rhythm_data` wrote, or None (a checkpoint of an older femadh:
    the resumed trace starts with a fresh rhythm, as it did then)."""
    if "snap_folds" not in z.files:
        return None
    target, creep_to = (None if math.isnan(x) else float(x) for x in z["snap_aim"])
    return (str(z["snap_branch"]), tuple(float(x) for x in z["snap_folds"]), target,
            creep_to)


def _fold_data(sink):
    """The fold states (a fold's last state, a landing) that bracket the kept peak or its
    tied rival (:class:`~femadh.runner.sink.Sink`): the files do not hold them, and a
    resumed peak search needs them (bit for bit: :func:`load_fold_states`)."""
    ids = {id(s) for folds in getattr(sink, "pieces", {}).values() for _, b, a in folds
           for s in (b, a)}
    held = [s for x in (sink.peak, getattr(sink, "_rival", None)) if x is not None
            for s in x[2:5] if s is not None and id(s) in ids]
    held = list({id(s): s for s in held}.values())
    n = sink.problem.grid.n
    if not held or any(np.ndim(s.w) != 1 or np.size(s.w) != n for s in held):
        # (none, or on an exchanged grid: a run whose band follows the edge is not resumed
        # mid-sweep)
        return {}
    return {"fold_d": np.array([s.d for s in held]), "fold_f": np.array([s.f_ex for s in held]),
            "fold_w": np.array([s.w for s in held]),
            "fold_active": np.array([s.active for s in held]),
            "fold_r_c": np.array([s.r_c for s in held], dtype=float)}


def _fold_records(sink):
    """Every fold of the sweep so far (``sink.folds``: branch, d_fold, d_land, its last state
    and its landing, each (d, w, active, r_c)): the estimate's reduced members start their
    fold searches from them (femadh.runner.members._folds); without them a resumed run's
    members traced the fine run's grid steps instead - more solves, and the jump and
    hysteresis errors moved in their last digits. Empty where a state is off the grid (an
    exchanged grid: not resumed mid-sweep)."""
    folds = getattr(sink, "folds", [])
    n = sink.problem.grid.n
    states = [s for f in folds for s in f[3:5]]
    if not folds or any(np.ndim(s.w) != 1 or np.size(s.w) != n for s in states):
        return {}
    return {"folds_branch": np.array([f[0] for f in folds]),
            "folds_d": np.array([[f[1], f[2]] for f in folds], dtype=float),
            "folds_state_d": np.array([[f[3].d, f[4].d] for f in folds], dtype=float),
            "folds_w": np.array([[f[3].w, f[4].w] for f in folds]),
            "folds_active": np.array([[f[3].active, f[4].active] for f in folds]),
            "folds_r_c": np.array([[f[3].r_c, f[4].r_c] for f in folds], dtype=float)}


def load_fold_records(folder):
    """[(branch, d_fold, d_land, (d, w, active, r_c) before, ... after)] of the folds the
    checkpoint holds (empty: none, no checkpoint, unreadable)."""
    path = folder / CHECKPOINT
    if not path.exists():
        return []
    try:
        with np.load(path, allow_pickle=False) as z:
            if "folds_d" not in z.files:
                return []
            return [(str(b), float(dd[0]), float(dd[1]),
                     *((float(sd[i]), w[i], a[i], float(rc[i])) for i in (0, 1)))
                    for b, dd, sd, w, a, rc in zip(z["folds_branch"], z["folds_d"],
                                                  z["folds_state_d"], z["folds_w"],
                                                  z["folds_active"], z["folds_r_c"])]
    except (OSError, ValueError, KeyError):
        return []


def load_fold_states(folder):
    """{(d, F_ex): (w, active, r_c)} of the fold states the checkpoint holds (empty: none, no
    checkpoint, unreadable)."""
    path = folder / CHECKPOINT
    if not path.exists():
        return {}
    try:
        with np.load(path, allow_pickle=False) as z:
            if "fold_d" not in z.files:
                return {}
            return {(float(d), float(f)): (w, a, float(rc)) for d, f, w, a, rc in zip(
                z["fold_d"], z["fold_f"], z["fold_w"], z["fold_active"], z["fold_r_c"])}
    except (OSError, ValueError, KeyError):
        return {}
