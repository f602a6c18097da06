"""Run a contact scene: build its problem, trace its branches, stream every state to disk as
it is computed, draw its figures, and return a :class:`ContactResult` (data only).

Nothing is lost: the output folder is claimed before anything is computed (one run per
folder, checked writable), ``summary.json`` says ``running`` from the start and is rewritten
atomically at the end, every committed state is in every csv, SIGINT/SIGTERM stop after the
current state with status ``interrupted``, and ``resume=True`` continues an interrupted or
failed sweep from its last committed state (the run's status and summary:
:mod:`.lifecycle`, the same for every scene kind; :func:`femadh.runner.run.run` dispatches
every kind).
"""
from dataclasses import dataclass
import math
import time
import warnings

import numpy as np

from .._threads import blas_threads
from ..contact import Jump, State, trace
from ..contact.forces import state_forces
from ..errors import ConvergenceError, MeshResolutionWarning, OutputError  # noqa: F401
from ..scene import build_problem, load_scene, scene_id  # noqa: F401 (scene_id: the API)
from .. import interrupt
from .estimates import GuardError
from .figures import draw_figures
from .lifecycle import lifecycle
from .result import ContactResult
from ..io.progress import advance, begin, phase
# run() of every kind: its own module; here too for the callers of femadh.runner.contact.run
from .run import run  # noqa: F401

#: surface-force stiffness over single-node stiffness above which a run warns
STIFFNESS_WARNING = 0.5
#: surface profiles kept in the result per branch (all of them are in fields.csv)
PROFILES = 12


def run_contact(scene, out_dir=None, *, figures=True, progress=False, overwrite=False,
                resume=False, operator=None, estimate=True, folder_id=None, resume_from=None):
    """Solve a contact scene (called by :func:`femadh.runner.run.run`, which documents the
    arguments, inside the run's signal handling, time limit and progress display): an
    adaptive grid or an accuracy target is refined over several runs, else one run into its
    claimed folder, then its figures."""
    if getattr(scene, "adaptive", False):
        from .adaptive import run_adaptive

        return run_adaptive(scene, out_dir, run=run, figures=figures, progress=progress,
                            overwrite=overwrite, resume=resume, estimate=estimate)
    if getattr(scene, "accuracy", None) and estimate is True:
        from .accuracy import run_to_accuracy

        return run_to_accuracy(scene, out_dir, run=run, figures=figures,
                               progress=progress, overwrite=overwrite, resume=resume)
    if out_dir is None:
        return _run(scene, None, progress=progress, operator=operator, estimate=estimate)
    from ..io.run_folder import RunFolder

    mode = "resume" if resume else "overwrite" if overwrite else "new"
    with RunFolder(out_dir, folder_id or scene_id(scene), scene.name, mode) as folder:
        res = _run(scene, folder, progress=progress, operator=operator, estimate=estimate,
                   resume_from=resume_from)
        if figures and res.status in ("converged", "failed") and any(
                len(next(iter(b.values()))) for b in res.branches.values()):
            with phase("figures"):
                draw_figures(res, folder)
            folder.write_summary(res.summary())
        return res


def solve_sweeps(scene, problem=None):
    """The solver-level trace of a stepping scene, for scripts that need the states themselves
    (their fields, the problem's operator), not only the result's curves.

    Returns (problem, {branch: Sweep}, error message or None); on failure the sweeps hold the
    states computed before it. Writes nothing.
    """
    if scene.continuation == "arclength":
        raise ValueError("solve_sweeps traces stepping scenes; use contact.arclength.trace_curve")
    with blas_threads():
        problem = problem or build_problem(scene)
        sweeps, start = {}, None
        for branch, d_vals in _plan(scene):
            try:
                sw = trace(problem, d_vals, branch=branch, tol=scene.tolerance, start=start,
                           max_iter=scene.max_iter)
            except ConvergenceError as exc:
                if getattr(exc, "sweep", None) is not None and exc.sweep.states:
                    sweeps[branch] = exc.sweep
                return problem, sweeps, str(exc)
            sweeps[branch], start = sw, sw.states[-1]
    return problem, sweeps, None


def _timed(fn):
    t0 = time.perf_counter()
    fn()
    return time.perf_counter() - t0


def _run(scene, folder, *, progress, operator=None, estimate=True, resume_from=None):
    t0 = time.perf_counter()
    res = ContactResult(scene.name, scene, out_dir=None if folder is None else str(folder.path))
    from ..io.progress import note

    say = note if progress else None
    run_id = scene_id(scene)
    # an adaptive run's trial claims the folder under the user's scene: its summary says
    # so (a trial's "converged" is not the run's end: --resume may continue the run)
    trial = folder is not None and folder.scene_id != run_id
    prev = folder.previous if folder is not None else None
    if prev and trial and prev.get("run_id") not in (None, run_id):
        # the folder holds another trial of this adaptive run (a later one, stopped): this
        # trial starts afresh in it
        folder.clean()
        prev = None
    resuming = bool(prev)
    if resuming and scene.continuation == "arclength":
        # an arclength trace cannot restart mid-curve from the files: its paths are read off
        # the whole curve, whose orientation and fold history are not on disk; it is traced
        # again from its start (the files are rewritten, consistent at every point)
        def rows(name):
            f = folder.path / name
            return max(0, len(f.read_text(errors="replace").splitlines()) - 1) \
                if f.exists() else 0

        res.warnings.append("resume: the arclength curve was traced again from its start "
                            f"({rows('equilibrium_curve.csv')} curve points and "
                            f"{rows('curve.csv')} branch states of the previous run replaced)")
        resuming = False
    elif resuming and (getattr(scene, "instrument", None) is not None
                       or (getattr(scene, "grid", None) or {}).get("follow")):
        # an instrument's readout refines between the sweep's own states and its jumps'
        # fold and landing states, which the files do not hold: the sweep is run again
        res.warnings.append("resume: the sweep was computed again from its start (" + (
            "its grid follows the contact edge: the files do not say which grid each state "
            "was continued on" if getattr(scene, "instrument", None) is None else
            "an instrument's readout needs every state of it in memory") + ")")
        resuming = False
    resume = None

    def write_summary(status=None):
        if folder is not None:
            folder.write_summary({**res.summary(status),
                                  **({"trial": True} if trial else {})})
    with lifecycle(res, write_summary, failures=(ConvergenceError, GuardError),
                   announce=not resuming, t0=t0) as life:
        if resuming:
            # refused while checking the folder (one line): it is left as it was
            life.untouched_on = (OutputError,)
        t1 = time.perf_counter()
        # the build writes nothing but whole cache files: a signal stops it at once
        with phase("operator"), interrupt.immediate():
            problem = build_problem(scene, operator=operator, progress=say)
        res.timings["operator_s"] = time.perf_counter() - t1
        if resuming:
            # every committed row checked before anything is appended (refused in one
            # line, or the side files cut back to what is complete in all of them)
            resume = _resume_point(folder, scene, problem, run_id, prev, resume_from, res)
            life.untouched_on = ()
            life.write_summary("running")
        res.nodes = problem.grid.nodes.copy()
        g = problem.grid
        res.grid = {"kind": "uniform" if g.fine_radius is None else "banded", "nodes": g.n,
                    "analysis_radius_m": g.radius}
        if g.fine_radius is not None:
            res.grid.update(band_m=g.fine_radius, spacing_m=float(g.nodes[1]),
                            grading_m=scene.grid["grading"] if scene.grid else None)
        res.warnings += _stiffness_warning(scene, problem)
        interrupt.check()
        writer = None
        if folder is not None:
            from ..io.writers import ContactWriter

            writer = ContactWriter(folder, problem, vtk=scene.vtk, resume=resume,
                                   run_id=run_id)
            life.cleanup(writer.close)
        sink = Sink(problem, res, writer, progress)
        # stopped inside the sweep: its last committed state saved whole (the checkpoint)
        life.on_stop = lambda: _save_checkpoint(folder, sink)
        if resume:
            sink.load(folder.path, resume)
        t1 = time.perf_counter()
        if scene.continuation == "arclength":
            _trace_arclength(scene, problem, sink)
        else:
            _trace_steps(scene, problem, sink, resume)
        res.timings["solve_s"] = time.perf_counter() - t1
        life.on_stop = None
        if folder is not None and (folder.path / CHECKPOINT).exists():
            (folder.path / CHECKPOINT).unlink()     # the sweep is complete: not needed
        if res.status == "running":
            _finish(scene, res, problem, sink, estimate)
            if folder is not None and res.instrument is not None:
                from ..io.writers import write_instrument

                write_instrument(folder.path, res)
    return res


def _finish(scene, res, problem, sink, estimate):
    """Headline numbers, their error estimates and the bound guard of a finished sweep."""
    from .estimates import estimate_errors, guard_bounds, refine_peak
    from .headline import headline

    problem = sink.problem          # the last grid of a band that follows the edge
    t1 = time.perf_counter()
    res.headline = headline(res, problem)
    if estimate:
        with phase("peak search"):
            half = refine_peak(scene, res, problem, sink)
        if getattr(scene, "instrument", None) is not None and res.instrument is not None:
            from .instrument import refine_instrument

            t2 = time.perf_counter()
            res.instrument["fresh_states"] = refine_instrument(scene, res, problem, sink)
            res.timings["instrument_s"] = time.perf_counter() - t2
        if estimate is True:
            res.estimates = estimate_errors(scene, res, problem, sink, half, run=run)
        guard_bounds(res, problem)
    res.timings["estimate_s"] = time.perf_counter() - t1


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


def _stiffness_warning(scene, problem):
    ratio, h_at, soft, k_node = problem.surface_force_stiffness()
    if ratio <= STIFFNESS_WARNING:
        return []
    msg = (f"{scene.path or scene.name}: the surface forces' stiffness -dP/dh = {soft:.3g} Pa/m "
           f"at h = {h_at * 1e9:.3g} nm is {ratio:.2f} x the stiffness of one surface node "
           f"({k_node:.3g} Pa/m): single nodes can snap on their own and the result depends on "
           f"the mesh. " + (f"Use [solver] nodes >= "
                            f"{int(scene.nodes * ratio / STIFFNESS_WARNING) + 1}."
                            if problem.grid.fine_radius is None else
                            f"Use [solver.grid] spacing <= "
                            f"{float(problem.grid.nodes[1]) * STIFFNESS_WARNING / ratio:.3g} m "
                            "(or leave the grid to femadh)."))
    # (the caller of run(): _run <- run_contact <- runner.run.run <- the caller)
    warnings.warn(msg, MeshResolutionWarning, stacklevel=5)
    return [msg]


def _plan(scene):
    d = scene.d_values
    if "approach" in scene.directions:
        plan = [("approach", d)]
        if "retract" in scene.directions:
            plan.append(("retract", d[::-1]))
        return plan
    return [("retract", d)]


class _Regrid(Exception):
    """Raised from a trace's callback: the contact edge left the middle of the band that
    follows it; the sweep goes on from ``state`` (the last state, carried to ``problem``'s
    grid) through ``remaining`` separations (the first is the state's own)."""

    def __init__(self, problem, state, remaining):
        super().__init__("regrid")
        self.problem, self.state, self.remaining = problem, state, remaining


def _follower(scene, problem):
    """The :class:`~femadh.discretisation.moving.EdgeBand` of a scene whose [solver.grid]
    sets ``follow`` (its edges: the contact edge, the outermost node at sigma, and the
    outermost gap at the laws' largest feature gap: the cohesive zone's or the meniscus'
    outer end), else None."""
    g = scene.grid
    if not (g and g.get("follow")) or problem.sigma is None:
        return None
    from ..discretisation.moving import EdgeBand
    from ..discretisation.plan import feature_gap, reach_floor
    from ..elastic import GreenOperator

    def build(grid, first):
        return build_problem(scene, operator=GreenOperator(grid, scene.e_star))
    floor = reach_floor(problem.effects, problem.sigma)
    # the inner edge at sigma itself (a node held at the floor, to round-off): the LJ
    # cohesive zone sigma..10^(1/2) sigma is ~0.8 um wide on the Fig 4 slider, and a band
    # around its outer end alone left the contact edge in the graded part
    band = EdgeBand(problem.grid.radius, g["spacing"], g["follow"], g["grading"], build,
                    feature_gap(problem.effects, floor), floor * (1 + 1e-6))
    band.spans[id(problem)] = (0.0, 0.0)     # the scene's own first member (scene_grid)
    band.centers[id(problem)] = 0.0
    return band


def _regridded(band, sink, problem, state, scene):
    """(new problem, the state carried to it) if the edge left the band's middle, else None.
    The sink and its writer write on the new grid from here on; the states the peak search
    and a branch's restart need are carried to it (their displacements interpolated: the
    search solves fresh states from them)."""
    from ..discretisation.moving import carry_state

    new = band.regrid(problem, state.w, state.d)
    if new is None:
        return None
    st = carry_state(problem, new, state, tol=scene.tolerance, max_iter=scene.max_iter)
    if not (st.converged and st.stable):
        raise ConvergenceError(
            f"grid exchange at d = {state.d * 1e9:.6g} nm (band following the contact edge): "
            "the state carried to the new grid did not converge to a stable state",
            d=state.d, residual=st.residual, n_iter=st.n_iter)
    _exchange(sink, problem, new)
    return new, st


def _exchange(sink, old, new):
    """The sink (and its writer) on ``new``'s grid from here on; the committed states the
    peak search and a branch's restart need carried to it (their displacements interpolated:
    the search solves fresh states from them)."""
    from ..discretisation.moving import interpolate_state

    snaps = ([s for s in sink.peak[2:] if s is not None] if sink.peak else []) + \
        list(sink.last.values())
    for snap in {id(x): x for x in snaps}.values():
        if getattr(snap, "w", None) is not None and np.ndim(snap.w) == 1 and \
                snap.w.size == old.grid.n:
            snap.w, snap.active = interpolate_state(old, new, snap.d, snap.w)
    sink.problem = new
    if sink.writer is not None:
        sink.writer.problem = new
    sink.regrids = getattr(sink, "regrids", 0) + 1


def _widened(band, sink, problem, state, scene):
    """(the static-band problem, ``state`` carried to it): the scene's [0, band] at the
    follow band's spacing and grading (a landing's fallback, :func:`_trace_steps`)."""
    from ..discretisation import GridFamily
    from ..discretisation.moving import carry_state

    g = scene.grid
    wide = band.build(GridFamily(band.radius, g["band"], band.grading).member(band.spacing),
                      False)
    band.spans[id(wide)] = (0.0, g["band"])
    band.centers[id(wide)] = 0.5 * g["band"]
    st = carry_state(problem, wide, state, tol=scene.tolerance, max_iter=scene.max_iter)
    if not (st.converged and st.stable):
        raise ConvergenceError(
            f"grid exchange at d = {state.d * 1e9:.6g} nm (to the static band after a failed "
            "landing): the carried state did not converge to a stable state", d=state.d,
            residual=st.residual, n_iter=st.n_iter)
    _exchange(sink, problem, wide)
    sink.widened = getattr(sink, "widened", 0) + 1
    sink.wide = wide
    return wide, st


def _trace_steps(scene, problem, sink, resume):
    """Stepping continuation of every branch of the scene's plan, from the resume point.

    With a band that follows the contact edge ([solver.grid] ``follow``), the grid is
    exchanged after a committed state or a landing whose edge left the band's middle half
    (:class:`~femadh.discretisation.moving.MovingBand`): the state is carried to the new
    grid at its own separation and the sweep goes on from it. Every committed state is
    written on the grid it was solved on (fields.csv's r column)."""
    start, prev = None, None
    band = _follower(scene, problem)
    for branch, d_vals in _plan(scene):
        done = len(sink.rows.get(branch, []))
        skip_first = False
        if done >= len(d_vals):
            start, prev = None, branch
            continue
        total = len(d_vals)
        if done:                      # resume inside this branch
            start = _restart_state(problem, scene, sink, branch)
            d_vals, skip_first = d_vals[done - 1:], True
        elif start is None and prev is not None:    # resume at the start of this branch
            start = _restart_state(problem, scene, sink, prev)
        sink.plan(branch, len(d_vals) - skip_first, total)
        wide = None                   # where this branch last went to the static band
        while True:
            first = [skip_first]
            seen = [0]
            last = [start]            # the last committed state (on the current grid)
            jumped = [0]              # jumps recorded since it

            def on_state(st, branch=branch, d_vals=d_vals, first=first, seen=seen,
                         last=last, jumped=jumped):
                seen[0] += 1
                if first[0]:          # the resumed (or carried) start state is on disk
                    first[0] = False
                    return
                # the edge left the band's middle: the state is committed on the new grid
                # (every committed state on a grid whose band holds its edges)
                moved = band and _regridded(band, sink, sink.problem, st, scene)
                last[0], jumped[0] = (moved[1] if moved else st), 0
                sink.state(branch, last[0])
                if moved:
                    raise _Regrid(*moved, d_vals[seen[0] - 1:])

            def on_jump(jump, d_vals=d_vals, jumped=jumped):
                sink.jump(jump)
                jumped[0] += 1
                moved = band and _regridded(band, sink, sink.problem, jump.after, scene)
                if moved:
                    # on from the landing: the separations beyond it
                    sign = math.copysign(1.0, d_vals[-1] - d_vals[0])
                    raise _Regrid(*moved, [jump.d_land] + [
                        d for d in d_vals if (d - jump.d_land) * sign > 0])
            try:
                sweep = trace(problem, d_vals, branch=branch, tol=scene.tolerance,
                              start=start, max_iter=scene.max_iter, on_state=on_state,
                              on_jump=on_jump)
            except _Regrid as rg:
                problem, start, d_vals, skip_first = rg.problem, rg.state, rg.remaining, True
                if len(d_vals) > 1:
                    continue
                sweep = None
            except ConvergenceError:
                # a fold whose landing failed on a follow grid (the surface snapped to where
                # the grid is coarse, e.g. the jump-in from no contact): the step once more
                # from the last committed state on the static band [0, band], which holds
                # wherever the edge can go; the next exchange returns to the follow band
                if band is None or jumped[0] or seen[0] == 0 or last[0] is None \
                        or wide == last[0].d or problem is getattr(sink, "wide", None):
                    raise
                wide = last[0].d
                problem, start = _widened(band, sink, problem, last[0], scene)
                d_vals, skip_first = d_vals[seen[0] - 1:], True
                continue
            break
        start, prev = (sweep.states[-1] if sweep is not None else start), branch
    if band is not None:
        sink.result.grid.update(follow_m=band.half, regrids=getattr(sink, "regrids", 0),
                                widened=getattr(sink, "widened", 0),
                                nodes_last=sink.problem.grid.n)
    sink.close()


def _restart_state(problem, scene, sink, branch):
    """The last committed state of a branch, re-solved from its saved surface (resume):
    Newton from the saved w converges in an iteration or two to the same state (to the
    tolerance)."""
    from ..contact import solve_state

    last = sink.last[branch]
    d, w = last.d, last.w
    if sink.writer is not None:
        # stopped by a signal or its time limit: the state was saved whole (bit for bit)
        st = _load_checkpoint(sink.writer.dir, getattr(sink, "last_k", {}).get(branch), d)
        if st is not None:
            return st
    kw = {}
    if problem.contact_model == "hertz-closure":
        kw["r_c0"] = float(sink.result.branches[branch]["r_c_m"][-1]) or None
    elif problem.sigma is not None:
        kw["active0"] = np.abs(problem.contour(d) - w - problem.sigma) <= 1e-9 * problem.sigma
    st = solve_state(problem, d, w, tol=scene.tolerance, max_iter=scene.max_iter, **kw)
    if not (st.converged and st.stable):
        raise ConvergenceError("resume: the last saved state does not re-converge to a stable "
                               "state", d=d, residual=st.residual, n_iter=st.n_iter)
    return st


def _resume_point(folder, scene, problem, run_id, prev, resume_from, res):
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


def _curve_state(problem, d, w, stable):
    """A State for a point of an arclength curve (smooth laws: no contact pressure)."""
    h = problem.contour(d) - w
    n = w.size
    res = float(np.max(np.abs(w - problem.C @ problem.pressure(h))))
    return State(d, w, h, {k: e.pressure(h) for k, e in problem.effects.items()}, np.zeros(n),
                 np.zeros(n, bool), 0.0, 0, res, True, stable)


def _trace_arclength(scene, problem, sink):
    """Trace the scene's equilibrium curve by arclength (every point streamed to
    equilibrium_curve.csv), then its displacement-controlled paths as branches."""
    if problem.sigma is not None:     # the sigma-gap's piecewise curve (its own states)
        from ..contact.sigma_arclength import curve_state as make_state
        from ..contact.sigma_arclength import trace_sigma_curve as trace
    else:
        from ..contact.arclength import trace_curve as trace
        make_state = _curve_state
    d = scene.d_values
    step = abs(d[1] - d[0])
    curve_rows = []

    def on_point(i, point):
        st = make_state(problem, point.d, point.w, point.stable)
        curve_rows.append((i, point, st))
        if sink.writer:
            sink.writer.write_curve_point(i, point, st)
        interrupt.check()
    try:
        curve = trace(problem, d[0], d[-1], tol=scene.tolerance, scale=step, ds=1.0,
                            ds_max=1.0, on_point=on_point)
    finally:
        sink.result.equilibrium_curve = {
            "d_m": np.array([p.d for _, p, _ in curve_rows]),
            "h0_m": np.array([s.h0 for _, _, s in curve_rows]),
            "F_ex_N": np.array([state_forces(problem, s)[2] for _, _, s in curve_rows]),
            "stable": np.array([p.stable for _, p, _ in curve_rows], bool),
            "dd_ds": np.array([p.t_d for _, p, _ in curve_rows])}
    for branch in scene.directions:
        # a sigma-gap event state is on the curve twice (end and start of two pieces of the
        # active set, at one d): it is one state of the path
        path = _once(curve.branch(branch))
        sink.plan(branch, sum(kind != "fold" for kind, _, _ in path))
        before = None
        for kind, dk, wk in path:
            st = make_state(problem, dk, wk, True)
            if kind == "fold":
                before = st
                continue        # the fold state is the jump's 'before', not a grid state
            sink.state(branch, st)
            if kind == "land":
                sink.jump(Jump(branch, dk, dk, 0.0, before, st))
    sink.close()


def _once(path):
    """A path without repeated consecutive points at the same d and w (a sigma-gap event)."""
    out = []
    for e in path:
        if out and e[0] == out[-1][0] == "point" and e[1] == out[-1][1] \
                and np.array_equal(e[2], out[-1][2]):
            continue
        out.append(e)
    return out


#: the last committed state of a sweep stopped by a signal or its time limit, whole (its
#: factorisation included): a resumed sweep continues from it bit for bit
CHECKPOINT = "checkpoint.npz"


def _save_checkpoint(folder, sink):
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
    data.update({f"pe_{name}": v for name, v in st.p_effects.items()})
    lu = st.lu
    if lu is None:
        data["lu_kind"] = np.array("none")
    elif isinstance(lu, TrailingLU):
        data.update(lu_kind=np.array("trailing"), lu=lu.lu, piv=lu.piv,
                    dims=np.array([lu.n, lu.m0, lu.k_valid]))
        if lu.scale is not None:
            data["scale"] = lu.scale
    elif isinstance(lu, TrailingCholesky):
        data.update(lu_kind=np.array("cholesky"), lu=lu.uinv, dims=np.array([lu.n, lu.m0,
                                                                             lu.k_valid]))
    elif isinstance(lu, tuple) and len(lu) == 2 and isinstance(lu[0], tuple):
        data.update(lu_kind=np.array("dense"), lu=lu[0][0], piv=lu[0][1], lu_I=lu[1])
    else:
        return
    def write(path):
        with open(path, "wb") as f:
            np.savez(f, **data)
    save_atomic(folder.path / CHECKPOINT, write)


def _load_checkpoint(folder, k, d):
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
            elif kind == "cholesky":
                lu = TrailingCholesky.from_inverse(z["lu"], *(int(x) for x in z["dims"]))
            elif kind == "dense":
                lu = ((z["lu"], z["piv"]), z["lu_I"])
            else:
                lu = None
            conv, stable = (bool(x) for x in z["flags"])
            return State(float(z["d"]), z["w"], z["h"],
                         {str(n): z[f"pe_{n}"] for n in z["effects"]}, z["p_contact"],
                         z["active"], float(z["r_c"]), int(z["n_iter"]),
                         float(z["residual"]), conv, stable, lu)
    except (OSError, ValueError, KeyError):
        return None
