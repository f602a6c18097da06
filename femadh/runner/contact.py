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
import time
import warnings

from .._threads import blas_threads
from ..contact import trace
from ..errors import (ConvergenceError, Interrupted, MeshResolutionWarning,  # noqa: F401
                      OutputError)
from ..scene import build_problem, scene_id
from .. import interrupt
from .estimates import GuardError
from .figures import draw_figures
from .lifecycle import lifecycle
from .result import ContactResult
from ..io.progress import phase
from .checkpoint import CHECKPOINT, resume_point, save_checkpoint
from .sink import Sink
from .tracing import branch_plan, trace_arclength, trace_steps

#: surface-force stiffness over single-node stiffness above which a run warns
STIFFNESS_WARNING = 0.5


def run_contact(scene, out_dir=None, *, run, figures=True, progress=False, overwrite=False,
                resume=False, operator=None, estimate=True, folder_id=None, resume_from=None):
    """Solve a contact scene (called by :func:`femadh.runner.run.run`, which documents the
    arguments, inside the run's signal handling, time limit and progress display): an
    adaptive grid or an accuracy target is refined over several runs, else one run into its
    claimed folder, then its figures. ``run``: the run of every kind
    (:func:`femadh.runner.run.run`), which the trials and the estimate's members go through
    (handed in: this module does not import its caller)."""
    if resume and out_dir is not None and resume_from is None and (
            folder_id is None or folder_id == scene_id(scene)):
        from .figures import resume_figures

        # a run stopped while its figures were drawn: its numbers are complete on disk
        # (every kind of run, before the adaptive or accuracy loop would start its trials
        # over): only the missing figures are drawn. Only the run the user asked for: a
        # loop's trial claims the user's folder under the user's scene id, and the folder
        # may hold another trial's run
        res = resume_figures(scene, out_dir, folder_id or scene_id(scene), figures=figures,
                             estimate=estimate)
        if res is not None:
            return res
    if getattr(scene, "adaptive", False):
        from .adaptive import run_adaptive

        return run_adaptive(scene, out_dir, run=run, figures=figures, progress=progress,
                            overwrite=overwrite, resume=resume, estimate=estimate)
    if getattr(scene, "accuracy", None) and estimate is True:
        from .accuracy import run_to_accuracy

        return run_to_accuracy(scene, out_dir, run=run, figures=figures,
                               progress=progress, overwrite=overwrite, resume=resume)
    if out_dir is None:
        return _run(scene, None, progress=progress, operator=operator, estimate=estimate,
                    run=run)
    from ..io.run_folder import RunFolder

    mode = "resume" if resume else "overwrite" if overwrite else "new"
    with RunFolder(out_dir, folder_id or scene_id(scene), scene.name, mode,
                   given=scene.as_given) as folder:
        res = _run(scene, folder, progress=progress, operator=operator, estimate=estimate,
                   resume_from=resume_from, run=run)
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
        for branch, d_vals in branch_plan(scene):
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


def _run(scene, folder, *, progress, run, operator=None, estimate=True, resume_from=None):
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
            resume = resume_point(folder, scene, problem, run_id, prev, resume_from, res)
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
        life.on_stop = lambda: save_checkpoint(folder, sink)
        if resume:
            sink.load(folder.path, resume)
        t1 = time.perf_counter()
        if scene.continuation == "arclength":
            trace_arclength(scene, problem, sink)
        else:
            trace_steps(scene, problem, sink, resume)
        res.timings["solve_s"] = time.perf_counter() - t1

        def done():
            life.on_stop = None
            if folder is not None and (folder.path / CHECKPOINT).exists():
                (folder.path / CHECKPOINT).unlink()     # the run is complete: not needed
        # a stop in the peak search or the estimate still saves the checkpoint: its fold
        # records are where the resumed run's members start their fold searches (without
        # them a run stopped there resumed with the jump and hysteresis errors moved in
        # their last digits - found by a review)
        try:
            if res.status == "running":
                _finish(scene, res, problem, sink, estimate, run)
                if folder is not None and res.instrument is not None:
                    from ..io.writers import write_instrument

                    write_instrument(folder.path, res)
        except Interrupted:
            raise
        except BaseException:
            done()
            raise
        done()
    return res


def _finish(scene, res, problem, sink, estimate, run):
    """Headline numbers, their error estimates and the bound guard of a finished sweep."""
    from .estimates import (deferred_target, deferring, estimate_errors, guard_bounds,
                            refine_peak)
    from .headline import headline

    problem = sink.problem          # the last grid of a band that follows the edge
    t1 = time.perf_counter()
    res.headline = headline(res, problem)
    res.warnings += _unbracketed_peak(sink)
    if estimate:
        with phase("peak search"):
            half = refine_peak(scene, res, problem, sink)
        if getattr(scene, "instrument", None) is not None and res.instrument is not None:
            from .instrument import refine_instrument

            t2 = time.perf_counter()
            res.instrument["fresh_states"] = refine_instrument(scene, res, problem, sink)
            res.timings["instrument_s"] = time.perf_counter() - t2
        if estimate is True:
            # an adaptive trial's estimate may defer what its loop does not judge
            # (estimates.deferring: set around the trial's run, not its members')
            defer = deferred_target()
            # (one phase of the display: its members are its parts, estimates._part)
            with deferring(None), phase("estimate"):
                res.estimates = estimate_errors(scene, res, problem, sink, half, run=run,
                                                defer=defer)
        guard_bounds(res, problem)      # a BoundError: its kind decides the refinement
    res.timings["estimate_s"] = time.perf_counter() - t1


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


def _unbracketed_peak(sink):
    """A warning when the largest adhesion is a branch's first or last state: the sweep
    stops where the force still grows, so the number is a lower bound of the peak (e.g. a
    2-m sphere where 2 mm was meant: in contact from the sweep's first separation)."""
    if sink.peak is None or sink.peak[1] <= 0 or (sink.peak[2] is not None
                                                 and sink.peak[4] is not None):
        return []
    branch, _, _, best, _ = sink.peak
    return [f"the largest adhesion is at an end of the {branch} sweep (d = {best.d * 1e9:.4g} "
            "nm), not between computed separations: it is only a lower bound of the peak; "
            "extend [sweep] past it"]
