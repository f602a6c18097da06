"""The figures of a contact run, drawn into its folder as the run's last phase.

Drawing them costs a run about as much as a small solve: importing matplotlib (~0.3-0.5 s on
one core) and rendering (~0.2 s for ``force_curve.png``, ~0.5 s for the paper's panels,
validation/results/benchmark.md). The ``femadh`` program (``femadh run``, in a process of
its own; not :func:`femadh.cli.main` called from a script) therefore forks a **figure
worker** before it solves (:func:`figure_worker`; Linux, two cores or more): the worker
imports matplotlib, warms its fonts and lays out the six-panel figure
(:func:`femadh.io.plots.prepare`) on the other core while the run solves, then draws the
figures of the result handed to it (pickled over a pipe), each in a process of its own,
side by side. The
run waits for them: ``femadh run`` never returns before its figures are on disk, exactly as
when it draws them itself.

Nothing is lost to the worker: each figure is written whole or not at all
(:func:`~femadh.io.atomic.save_atomic`); a signal while the figures are drawn stops the
worker (SIGTERM: its temporary files are removed) and the run ends "interrupted" as before,
its numbers complete (--resume draws the missing figures and solves nothing again:
:func:`resume_figures`); a worker that died, could not be reached, or reported an error leaves
its figures to the run itself, drawn in-process as without a worker (an error then reaches
the run as it always did). Without a worker (the Python API, other platforms, one core,
``--no-figures``) the figures are drawn in-process.
"""
from contextlib import contextmanager
import os
import pickle
import signal
import struct
import sys
import time

from ..errors import Interrupted
from .. import interrupt

#: the worker of the running command (set by :func:`figure_worker`), or None
_WORKER = [None]


def draw_figures(res, folder, only=None):
    """The run's figures into its folder (:func:`femadh.io.plots.contact_figures`; ``only``:
    those of these file names), by the figure worker when the command started one; a signal
    stops them at once (each file is written whole or not at all) and the run ends
    "interrupted", the outcome it had reached kept in ``res.stopped_in_figures``
    (--resume draws the missing figures: :func:`resume_figures`). Their time goes to
    ``res.timings["figures_s"]``."""
    t0 = time.perf_counter()
    try:
        with interrupt.immediate():
            worker = _WORKER[0]
            left = worker.draw(res, folder.path, only) if worker is not None else None
            if left is None or left:
                from ..io.plots import contact_figures

                contact_figures(res, folder.path, only=only if left is None else left)
        res.timings["figures_s"] = time.perf_counter() - t0
    except Interrupted as exc:
        _stopped(res, exc)


def _stopped(res, exc):
    """``res`` stopped by ``exc`` while its figures were drawn: the outcome it had reached
    (its numbers are complete) is kept for --resume, then the stop is recorded."""
    if res.stopped_in_figures is None:
        res.stopped_in_figures = {"status": res.status, "error": res.error,
                                  "failure_kind": res.failure_kind}
    res.stop(exc, " while drawing the figures")


#: summary.json of a run stopped in its figures names the outcome it had reached under this
#: key (:attr:`~femadh.runner.result.ContactResult.stopped_in_figures`)
STOPPED_IN_FIGURES = "stopped_in_figures"


def resume_figures(scene, out_dir, folder_id, figures=True, estimate=True):
    """``--resume`` of a run stopped while its figures were drawn: its sweep, peak search
    and error estimate are complete in its folder (summary.json, curve.csv, fields.csv), so
    nothing is solved again - the result is read back (:func:`_read_result`), the figures
    not on disk are drawn (each file is whole or absent: the ones written before the stop
    are kept), and summary.json ends with the outcome the run had reached, equal to the
    uninterrupted run's but for its timings. Re-solving instead (the checkpoint and the fold
    records are gone once the sweep is complete) made the estimate again: its jump and
    hysteresis errors moved in their last digits (adaptive Fig 4: the jump-out and
    hysteresis grid parts and the members' solve counts).

    Returns the result, or None where this does not apply (the folder holds no such run,
    or a run this reader does not rebuild: an arclength trace, an [instrument], the edge
    route, an accuracy loop on uniform grids whose trial may not have been its last, files
    that do not hold what the summary records; or a resume that asks for the error
    estimate (``estimate`` True) of a run made without one): the caller resumes as any
    stopped run.
    summary.json is rewritten once, at the end: with the outcome once the figures are on
    disk, else (stopped again while drawing) as the first stop left it, the outcome kept; a
    kill while drawing leaves it as it was (each state on disk consistent: resumed alike).
    """
    from pathlib import Path

    from ..io.run_folder import RunFolder, previous_run
    from ..io.progress import phase

    prev = previous_run(Path(out_dir))
    if _pending_outcome(prev, scene) is None or (
            estimate is True and not prev.get("error_estimates")):
        # (a run stopped in its figures without an estimate, resumed asking for one: the
        # normal resume makes it)
        return None
    t0 = time.perf_counter()
    with RunFolder(out_dir, folder_id, scene.name, "resume",
                   given=scene.as_given) as folder:
        prev = folder.previous          # (read again under the folder's lock)
        outcome = _pending_outcome(prev, scene)
        res = None if outcome is None else _read_result(scene, folder.path, prev)
        if res is None:
            return None
        res.status, res.error, res.failure_kind = (outcome.get("status"),
                                                   outcome.get("error"),
                                                   outcome.get("failure_kind"))
        if figures:
            from ..io.plots import figure_names

            missing = [n for n in figure_names(res) if not (folder.path / n).exists()]
            if missing:
                with phase("figures"):
                    draw_figures(res, folder, only=missing)
        if res.stopped_in_figures is None:
            try:
                # a signal after the last figure is still a stop (as a run's lifecycle)
                interrupt.check()
            except Interrupted as exc:
                _stopped(res, exc)
        res.timings["total_s"] = float(prev.get("wall_time_s") or 0.0) + (
            time.perf_counter() - t0)
        data = {**prev, "status": res.status, "error": res.error,
                "failure_kind": res.failure_kind, "timings_s": res.timings,
                "wall_time_s": res.wall_time}
        if res.stopped_in_figures is None:
            data.pop(STOPPED_IN_FIGURES, None)
        else:
            data[STOPPED_IN_FIGURES] = res.stopped_in_figures
        folder.write_summary(data)
    return res


def _pending_outcome(prev, scene):
    """The outcome (dict) recorded by a run stopped in its figures whose result
    :func:`_read_result` can read back, else None."""
    from .result import STOPPED

    out = (prev or {}).get(STOPPED_IN_FIGURES)
    if not isinstance(out, dict) or prev.get("status") not in STOPPED \
            or out.get("status") not in ("converged", "failed"):
        return None
    if (scene.continuation == "arclength" or getattr(scene, "instrument", None) is not None
            or (prev.get("grid") or {}).get("route") == "edge-branch"
            or (getattr(scene, "accuracy", None) and not getattr(scene, "adaptive", False))):
        # (an arclength curve, an instrument's paths: not in the files read here; the edge
        # route starts over; an accuracy loop on uniform grids draws each trial's figures,
        # and one stopped there may have had trials to go)
        return None
    return out


def _read_result(scene, path, prev):
    """The result of a finished contact run as its figures and its report read it, from its
    folder: the curves from curve.csv (repr floats: the same bits), the surface profiles the
    run kept (the same picks as :class:`~femadh.runner.sink.Sink`) and the nodes from
    fields.csv, the rest (headline numbers, estimates, jumps, accuracy, grid, warnings,
    timings) from summary.json; its scene is the one given (an adaptive run's kept trial
    differs from it in its grid alone, which neither reads). None where the files do not
    hold what the summary records:
    a curve.csv row that does not match its checksum (seeded with the run's scene id,
    :func:`~femadh.io.writers.row_crc`) or the summary's record of its branches, a state
    missing from fields.csv."""
    import csv

    import numpy as np

    from ..io.resume_check import plan_rows, row_problem
    from ..io.writers import CRC
    from .result import ContactResult, contact_summary
    from .sink import _picks
    from .tracing import branch_plan

    try:
        lines = (path / "curve.csv").read_text().splitlines()
        head = next(csv.reader([lines[0]]))
        n_crc, run_id, plan = head.index(CRC), prev["run_id"], plan_rows(scene)
        cols = [c for c in head if c not in ("state", "branch", CRC)]
        where = [head.index(c) for c in cols]
        per_branch, table, rows = {}, {}, []
        for k, line in enumerate(lines[1:]):
            # each row as a resume checks it: its checksum, state number and place in the
            # sweep (femadh.io.resume_check, the one home of that check)
            if row_problem(line, k, head, n_crc, plan, run_id):
                return None
            r = next(csv.reader([line]))
            rows.append(r)
            per_branch.setdefault(r[1], []).append(k)
            table.setdefault(r[1], []).append([r[j] for j in where])
        res = ContactResult(scene.name, scene, out_dir=str(path))
        for b, vals in table.items():
            res.branches[b] = {c: np.array([v == "True" for v in x], dtype=bool)
                               if c in ("converged", "stable") else
                               np.array([int(v) for v in x], dtype=int) if c == "n_iter"
                               else np.array([float(v) for v in x], dtype=float)
                               for c, x in zip(cols, zip(*vals))}
        # the profiles the run kept: the picks of each branch's planned length
        total = {b: len(d) for b, d in branch_plan(scene)}
        picks = {b: [ks[j] for j in sorted(_picks(total.get(b, len(ks)))) if j < len(ks)]
                 for b, ks in per_branch.items()}
        fields = _field_states(path, {0} | {k for ks in picks.values() for k in ks})
    except (OSError, ValueError, IndexError, KeyError):
        return None
    if fields is None or 0 not in fields:
        return None
    # fields.csv must hold the states curve.csv records (no checksum of its own): each state
    # at its row's d (repr floats: the same bits), its columns of one length, the first
    # state on the grid the summary names (a torn or edited file: solved again)
    i_d = head.index("d_m")
    for k, (d, *arrs) in fields.items():
        if float(rows[k][i_d]) != d or len({a.size for a in arrs}) != 1:
            return None
    if fields[0][1].size != (prev.get("grid") or {}).get("nodes"):
        return None
    res.nodes = fields[0][1]
    for b, ks in picks.items():
        prof = res.profiles.setdefault(b, {"d_m": [], "w_m": [], "P_LJ_Pa": [],
                                           "P_el_Pa": [], "r_m": []})
        for k in ks:
            d, r, w, p_lj, p_el = fields[k]
            for name, v in zip(("d_m", "r_m", "w_m", "P_LJ_Pa", "P_el_Pa"),
                               (d, r, w, p_lj, p_el)):
                prof[name].append(v)
        for name in list(prof):
            # (profiles on exchanged grids - a band following the edge - differ in length)
            same = len({np.size(x) for x in prof[name]}) <= 1
            prof[name] = np.array(prof[name]) if same else np.array(prof[name], dtype=object)
    res.jumps = list(prev.get("jumps") or [])
    res.headline = dict(prev.get("headline") or {})
    res.estimates = dict(prev.get("error_estimates") or {})
    res.accuracy = dict(prev.get("accuracy") or {})
    res.grid = dict(prev.get("grid") or {})
    res.warnings = list(prev.get("warnings") or [])
    res.timings = dict(prev.get("timings_s") or {})
    # the curves read back are the ones the summary records (a folder changed since: None)
    if contact_summary(res)["branches"] != prev.get("branches"):
        return None
    return res


def _field_states(path, wanted):
    """{state number: (d, r, w, P_LJ, P_el)} of the wanted states from fields.csv, or None
    where one is missing."""
    from ..io.resume_check import field_states

    out = field_states(path, wanted, ("r_m", "w_m", "P_LJ_Pa", "P_el_Pa"))
    return out if set(out) == set(wanted) else None


@contextmanager
def figure_worker(enabled=True):
    """Fork a :class:`FigureWorker` for the block (``enabled``, on Linux with two cores or
    more; else None) and let :func:`draw_figures` use it; it is stopped and reaped when the
    block ends."""
    if (not enabled or not sys.platform.startswith("linux") or _WORKER[0] is not None
            or len(os.sched_getaffinity(0)) < 2):
        # (on one core a worker would only add its start-up to the run's time)
        yield None
        return
    try:
        worker = FigureWorker()
    except OSError:
        yield None          # no fork (process limit, memory): the figures are drawn here
        return
    _WORKER[0] = worker
    try:
        yield worker
    finally:
        _WORKER[0] = None
        worker.close()


def _send(fd, obj):
    _send_blob(fd, pickle.dumps(obj, protocol=pickle.HIGHEST_PROTOCOL))


def _send_blob(fd, blob):
    """One message: its length, then the pickle."""
    data = struct.pack("<Q", len(blob)) + blob
    view = memoryview(data)
    while view:
        view = view[os.write(fd, view):]


def _read(fd, n):
    chunks = []
    while n:
        b = os.read(fd, min(n, 1 << 20))
        if not b:
            raise EOFError
        chunks.append(b)
        n -= len(b)
    return b"".join(chunks)


def _recv(fd):
    (n,) = struct.unpack("<Q", _read(fd, 8))
    return pickle.loads(_read(fd, n))


class FigureWorker:
    """A forked process that draws a contact run's figures (see the module docstring).

    The parent sends one job, ``(result, folder)``; the worker answers ``("done", name)``
    per figure written, ``("error", name, text)`` per figure it could not draw, then
    ``("end",)``. Closing the parent's end (EOF) ends an idle worker.
    """

    def __init__(self):
        for s in (sys.stdout, sys.stderr):
            s.flush()        # (buffered text would be written twice)
        job_r, job_w = os.pipe()
        ans_r, ans_w = os.pipe()
        pid = os.fork()
        if pid == 0:                                   # the worker
            code = 0
            try:
                os.close(job_w)
                os.close(ans_r)
                _serve(job_r, ans_w)
            except BaseException:
                code = 1
                if os.environ.get("FEMADH_DEBUG"):
                    import traceback

                    traceback.print_exc()
            finally:
                os._exit(code)
        os.close(job_r)
        os.close(ans_w)
        self.pid, self._job, self._ans = pid, job_w, ans_r
        self.sent = False

    def draw(self, res, folder, only=None):
        """Have the worker draw ``res``'s figures into ``folder`` (``only``: those of these
        file names); returns the names of the figures it did not write (to be drawn
        in-process: empty when it wrote them all), None when it could not take the job. A
        signal (Interrupted) stops the worker and is raised again."""
        if self.sent or self.pid is None:
            return None
        try:
            job = pickle.dumps((res, str(folder), only), protocol=pickle.HIGHEST_PROTOCOL)
        except Exception:                 # (a result that does not pickle: drawn here)
            return None
        names = _names(res, only)
        done = set()
        self.sent = True
        try:
            _send_blob(self._job, job)
            while True:
                msg = _recv(self._ans)
                if msg[0] == "end":
                    break
                if msg[0] == "done":
                    done.add(msg[1])
        except (OSError, EOFError, pickle.UnpicklingError, struct.error):
            pass                          # the worker died: what it did not write, here
        except BaseException:             # a signal (Interrupted): the worker stops too
            self.stop()
            raise
        return [n for n in names if n not in done]

    def stop(self):
        """End the worker now (SIGTERM: a figure being written is not renamed into place
        and its temporary file is removed) and reap it."""
        if self.pid is None:
            return
        try:
            os.kill(self.pid, signal.SIGTERM)
        except ProcessLookupError:
            pass
        self._reap()

    def close(self):
        """End the worker: an idle one is stopped, a finished one reaped."""
        if self.pid is None:
            return
        if not self.sent:
            self.stop()
        else:
            self._reap()

    def _reap(self):
        for fd in (self._job, self._ans):
            try:
                os.close(fd)
            except OSError:
                pass
        while True:
            try:
                os.waitpid(self.pid, 0)
                break
            except InterruptedError:
                continue
            except ChildProcessError:
                break
        self.pid = None


#: whether the worker has its job (its figure processes to stop on SIGTERM)
_BUSY = [False]


def _terminate(signum, frame):
    if _BUSY[0]:
        raise SystemExit(0)         # (the finally of _serve stops the figure processes)
    # still importing matplotlib or waiting: nothing to clean up, and an exception raised
    # inside an import leaves half-built objects whose __del__ writes "Exception ignored"
    # tracebacks on the run's stderr (a stop caught in the suite: pyparsing's Forward)
    os._exit(0)


def _serve(job_r, ans_w):
    """The worker's life: get ready (import matplotlib, warm its fonts), wait for the job,
    draw its figures side by side (one process each), report, exit."""
    # the run decides: a Ctrl-C reaches the whole process group, and the run stops the
    # worker itself (SIGTERM) if it must
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, _terminate)
    from ..io import plots

    plots.warm_up()
    plots.prepare()         # (the six panels' axes and ticks: ~0.1 s less for the run to wait)
    try:
        res, folder, only = _recv(job_r)
    except EOFError:
        return
    _BUSY[0] = True
    names = _names(res, only)
    if not names:
        _send(ans_w, ("end",))
        return
    kids = {}
    for name in names[1:]:
        # the others, each in its own process (a fork of a warmed worker costs ~ms); a
        # SIGTERM waits until the new process is known, so that it is passed on to it
        old = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGTERM})
        r, w = os.pipe()
        pid = os.fork()
        if pid == 0:
            code = 0
            try:
                signal.pthread_sigmask(signal.SIG_SETMASK, old)
                os.close(r)
                _draw_one(plots, res, folder, name, w)
            except BaseException:
                code = 1
            finally:
                os._exit(code)
        os.close(w)
        kids[name] = (pid, r)
        signal.pthread_sigmask(signal.SIG_SETMASK, old)
    try:
        _draw_one(plots, res, folder, names[0], ans_w)
        for name, (pid, r) in kids.items():
            try:
                _send(ans_w, _recv(r))
            except EOFError:
                _send(ans_w, ("error", name, "the figure's process ended without a word"))
    finally:
        for pid, r in kids.values():
            try:
                os.kill(pid, signal.SIGTERM)
            except ProcessLookupError:
                pass
            os.waitpid(pid, 0)
    _send(ans_w, ("end",))


def _names(res, only):
    """The file names of ``res``'s figures to draw (``only``: those of these names)."""
    from ..io.plots import figure_names

    return [n for n in figure_names(res) if only is None or n in only]


def _draw_one(plots, res, folder, name, fd):
    try:
        plots.contact_figures(res, folder, only=[name])
    except Exception as exc:
        _send(fd, ("error", name, f"{type(exc).__name__}: {exc}"))
    else:
        _send(fd, ("done", name))
