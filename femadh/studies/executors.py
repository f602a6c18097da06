"""Where a study's points run: the worker's set-up and its record, the local process pool and
Dask, and what a signal to the driver or a dead worker does to them.

A point's ``record.json`` says whether it *finished*: converged, or failed for a physical
reason (a solve that does not converge, a guard). A point interrupted by a signal, whose
worker died, or that met a fault outside the physics (a full disk, a missing dependency, a
bug) is not finished and runs again when the study is run again. The record is written
first with status "running" (and the worker's pid, so that a dead worker's point is known)
and last with the outcome, atomically both times.

Signals: the driver turns SIGINT/SIGTERM into a flag its wait loop checks every
:data:`POLL_S`; it then cancels the points not started, sends SIGTERM to the pool's workers
(the run in each stops at its next safe point and records "interrupted"), waits
:data:`GRACE_S` for them and kills the rest, and raises :class:`~femadh.errors.Interrupted`
(exit 130 / 143). A Dask LocalCluster femadh started is closed (its worker processes end);
on a cluster femadh did not start the futures are cancelled (a running task finishes there:
Dask cannot interrupt it). A worker killed (kill -9, out of memory) breaks the local pool:
the points it ran are re-queued once on a fresh pool, a second death fails the point with
that reason; Dask re-runs a dead worker's task itself and reports KilledWorker after its
retries, recorded the same way.
"""
from concurrent.futures import FIRST_COMPLETED
from contextlib import contextmanager
import json
import os
from pathlib import Path
import signal
import threading
import time

import numpy as np

from .._version import code_id
from ..errors import (DependencyError, FemadhError, Interrupted, MeshResolutionWarning,
                      OutputError)
from ..interrupt import raise_terminated
from ..io.atomic import write_atomic

#: headline numbers a study's table carries (when the scene kind has them)
HEADLINE = ("max_adhesion_N", "d_at_max_adhesion_m", "jump_in_d_m", "jump_out_d_m",
            "hysteresis_J", "F_LJ_deepest_N", "F_ex_deepest_N", "work_of_adhesion_J_per_m2",
            "instrument_pull_off_N", "instrument_snap_off_N", "instrument_jump_out_z_m",
            "instrument_stuck", "instrument_release_margin_m")
#: how often the driver's wait loop looks at the signal flag (s)
POLL_S = 0.2
#: how long stopped workers get to record their point before they are killed (s)
GRACE_S = 5.0
#: deaths of the worker running a point before the point is failed (re-queued once)
MAX_DEATHS = 2
#: errors that are no property of the point's physics: the point runs again
NOT_PHYSICAL = (OutputError, DependencyError, Interrupted)


# --------------------------------------------------------------------------- the worker

#: the surface operator a worker keeps: {operator key: operator}, one at a time
OPERATOR_CACHE = {}
_IN_POOL = False


def study_operator_key(sc):
    """The key under which a worker keeps a point's surface operator: the content hash of the
    pair it is built from, ``(scene.body, scene.discretisation)``
    (:func:`femadh.scene.operator_key`), so that no field the operator reads can be left out.
    None when no operator is kept: a meniscus scene, or an adaptive run (it builds the grid
    members it chooses)."""
    if sc.kind != "contact" or sc.adaptive:
        return None
    from ..scene import operator_key

    return operator_key(*sc.operator_inputs)


def worker_operator(sc):
    """``(operator, reused)``: the surface operator of a point's scene, the one kept in this
    process when its key matches (``reused``), else built and kept instead (one operator per
    worker: bounded memory); ``(None, False)`` when the scene keeps none
    (:func:`study_operator_key`)."""
    from ..scene import build_operator

    key = study_operator_key(sc)
    if key is None:
        return None, False
    if key in OPERATOR_CACHE:
        return OPERATOR_CACHE[key], True
    OPERATOR_CACHE.clear()
    OPERATOR_CACHE[key] = build_operator(sc)
    return OPERATOR_CACHE[key], False


#: what a point's run estimated, as its record says it (``estimate`` of femadh.run): the
#: error estimates of the headline numbers ("errors"), only the located peak ("peak", the
#: command line's --no-estimate), neither ("none"); in increasing order of what it holds
ESTIMATE_NAMES = {True: "errors", "peak": "peak", False: "none"}


def finished(rec):
    """Whether a point's record is final: converged, or failed for a physical reason."""
    if "finished" in rec:
        return bool(rec["finished"])
    # a record of an earlier femadh (no "finished"): only its converged or failed outcome
    return rec.get("status") in ("converged", "failed")


def write_record(folder, rec):
    """Write a point's record.json atomically (the folder is created)."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    write_atomic(folder / "record.json", json.dumps(rec, indent=1, default=_jsonable) + "\n")


def run_point(point, root, estimate=True):
    """Run one point into ``root/points/<id>/`` and return its record (a small dict).

    Runs in a worker: the surface operator of each distinct body and discretisation is built
    once per process and reused (:func:`worker_operator`). Never raises for a failed solve or
    a fault of the point: the record says what happened and whether it is final
    (``finished``). A signal that stops the point's run is recorded ("interrupted") and then
    ends a pool worker with that signal, so that the driver's shutdown does not wait for it."""
    from .._threads import blas_threads
    from ..runner.run import run
    import warnings

    tune_malloc()
    t0 = time.perf_counter()
    folder = Path(root) / "points" / point.id
    rec = {"id": point.id, "index": point.index, "changes": point.changes,
           "status": "running", "finished": False, "error": None, "operator_reused": False,
           "estimate": ESTIMATE_NAMES[estimate], "femadh": code_id(), "pid": os.getpid()}
    write_record(folder, rec)       # a dead worker's point is known by this record's pid
    signum = None
    try:
        # a point's resolution warnings go into its record (and summary.json), not the
        # terminal of the study
        with blas_threads(), warnings.catch_warnings():
            warnings.simplefilter("ignore", MeshResolutionWarning)
            op, rec["operator_reused"] = worker_operator(point.scene)
            res = run(point.scene, folder, figures=False, progress=False, overwrite=True,
                      operator=op, estimate=estimate)
        rec["status"], rec["error"] = res.status, res.error
        rec["finished"] = res.status in ("converged", "failed")
        if res.status == "interrupted":
            signum = rec["signum"] = getattr(res, "exit_code", 130) - 128
        rec["warnings"] = list(getattr(res, "warnings", []))
        if res.kind == "meniscus":
            # a meniscus run estimates its force's error whatever it is asked (run_meniscus
            # takes no ``estimate``): the record says what the run did
            rec["estimate"] = "errors"
        rec.update(_numbers(res))
    except NOT_PHYSICAL as exc:
        rec["status"], rec["error"] = "failed", f"{type(exc).__name__}: {exc}"
        if isinstance(exc, Interrupted):
            rec["status"], signum = "interrupted", exc.signum
            rec["signum"] = signum
    except FemadhError as exc:
        # a SceneError or a law's domain at run time: the same point fails the same way again
        rec["status"], rec["error"], rec["finished"] = ("failed",
                                                        f"{type(exc).__name__}: {exc}", True)
    except (KeyboardInterrupt, SystemExit) as exc:
        rec["status"], rec["error"] = "interrupted", type(exc).__name__
        rec["wall_time_s"] = time.perf_counter() - t0
        write_record(folder, rec)
        raise
    except Exception as exc:        # a bug: recorded, not final (a fixed femadh redoes it)
        rec["status"], rec["error"] = "failed", f"internal error {type(exc).__name__}: {exc}"
    rec["wall_time_s"] = time.perf_counter() - t0
    write_record(folder, rec)
    if signum is not None and _IN_POOL:
        # the run kept the signal for us: end this pool worker with it now (its point is
        # recorded), instead of taking the next point or keeping the driver waiting
        signal.signal(signum, signal.SIG_DFL)
        os.kill(os.getpid(), signum)
    return rec


def _numbers(res):
    if res.kind == "meniscus":
        out = {}
        for (liq, R, meth), c in res.curves.items():
            f = c["force_N"]
            if np.any(np.isfinite(f)):
                out[f"max_force_N[{liq},{R:g},{meth}]"] = float(np.nanmax(f))
        return out
    return {k: res.headline[k] for k in HEADLINE if k in res.headline} | {
        f"{k}_error": res.headline[f"{k}_error"] for k in HEADLINE
        if f"{k}_error" in res.headline}


def _jsonable(o):
    if isinstance(o, (np.floating, np.integer)):
        return o.item()
    return str(o)


def _worker_init():
    """Set-up of a pool or Dask worker: one BLAS thread (the points are the parallelism).

    Its SIGTERM is the default (an idle worker the driver stops dies of it, exit -15, which
    the driver reads as its own stop, not as a death), or a run's while one runs: the
    ``femadh`` program's own start-up handler (:mod:`femadh.cli`: one line and exit 143) is
    never a worker's. femadh.cli does not install it in a multiprocessing child; should a
    launcher still have left it (a worker of the ``femadh`` script imports femadh.cli), it
    is taken out here. Any other handler (a ``dask worker`` of a cluster femadh did not
    start closes itself on SIGTERM) is left alone."""
    global _IN_POOL
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    _IN_POOL = threading.current_thread() is threading.main_thread()
    if _IN_POOL:
        h = signal.getsignal(signal.SIGTERM)
        if h is raise_terminated or getattr(h, "__module__", None) == "femadh.cli":
            signal.signal(signal.SIGTERM, signal.SIG_DFL)


def _pool_init():
    """Set-up of a local pool worker: a Ctrl-C in the terminal reaches every process of the
    group; an idle worker ignores it (the driver stops it with SIGTERM, without a
    KeyboardInterrupt traceback), while a run in progress takes it at its next safe point
    (the run installs its own handlers and restores this one: a handler that does nothing,
    not SIG_IGN, which a run leaves in place as its parent's wish)."""
    _worker_init()
    if signal.getsignal(signal.SIGINT) is not signal.SIG_IGN:   # (a nohup'ed study's stays)
        signal.signal(signal.SIGINT, _idle_sigint)


def _idle_sigint(signum, frame):
    """An idle pool worker's SIGINT: nothing (the driver decides, see :func:`_pool_init`)."""


_MALLOC_TUNED = False


def tune_malloc():
    """Undo dask's MALLOC_TRIM_THRESHOLD_ for femadh's allocation pattern (once per process).

    A dask nanny starts its workers with MALLOC_TRIM_THRESHOLD_=65536, which also switches
    off glibc's dynamic mmap threshold: every numpy temporary above 128 KiB is then mmap'ed
    and unmapped afresh, page faults included. A stiction-map point ran 45 % slower in a Dask
    worker than in a process of the local pool for that reason (6.0 s -> 8.7-9.4 s with the
    variable set, 6.1 s with the thresholds below). Raising both thresholds by mallopt works
    on any worker, also on a cluster femadh did not start. No-op off glibc."""
    global _MALLOC_TUNED
    if _MALLOC_TUNED:
        return
    _MALLOC_TUNED = True
    if not os.environ.get("MALLOC_TRIM_THRESHOLD_"):
        return                      # glibc's dynamic thresholds are in force: keep them
    try:
        import ctypes

        libc = ctypes.CDLL("libc.so.6")
    except OSError:
        return
    M_TRIM_THRESHOLD, M_MMAP_THRESHOLD = -1, -3
    libc.mallopt(M_MMAP_THRESHOLD, 32 * 1024 * 1024)     # glibc's largest
    libc.mallopt(M_TRIM_THRESHOLD, 256 * 1024 * 1024)


# --------------------------------------------------------------------------- the driver

@contextmanager
def driver_signals():
    """SIGINT/SIGTERM to the study's driver set a flag (a list holding the signal number)
    that the executors' wait loops check; outside the main thread: no handlers, no flag."""
    flag = []
    if threading.current_thread() is not threading.main_thread():
        yield flag
        return

    def handler(signum, frame):
        if flag:                    # a second signal: the user insists, stop waiting now
            raise Interrupted(flag[0])
        flag.append(signum)

    # (a signal the parent set to SIG_IGN stays ignored, as in femadh.interrupt)
    old = {s: signal.signal(s, handler) for s in (signal.SIGINT, signal.SIGTERM)
           if signal.getsignal(s) is not signal.SIG_IGN}
    try:
        yield flag
    finally:
        for s, h in old.items():
            signal.signal(s, h)


def execute(todo, out, workers=None, scheduler=None, estimate=True, stop=None, notes=None):
    """Yield the records of the points as they finish, on the chosen executor.

    ``stop``: the flag of :func:`driver_signals` (a list; a signal number in it stops the
    executor, which then raises Interrupted). ``notes``: a list the executor appends a line
    to for what a user should hear of (a worker that died, a point re-queued)."""
    stop = [] if stop is None else stop
    notes = [] if notes is None else notes
    if not todo:
        return
    if scheduler:
        yield from _execute_dask(todo, out, scheduler, estimate, stop)
        return
    workers = workers or os.cpu_count() or 1
    if workers == 1:
        for p in todo:
            if stop:
                raise Interrupted(stop[0])
            # in this process the run's own handlers take the signal at a safe point
            rec = run_point(p, out, estimate)
            yield rec
            if rec["status"] == "interrupted":
                raise Interrupted(_signum(rec, stop))
        return
    yield from _execute_pool(todo, out, workers, estimate, stop, notes)


def _signum(rec, stop):
    """The signal that stopped a point (the driver's first, else the point's own)."""
    if stop:
        return stop[0]
    return rec.get("signum", signal.SIGINT)


def _execute_pool(todo, out, workers, estimate, stop, notes):
    """The local process pool; a broken pool (a worker killed) is replaced and its points
    re-queued, at most ``len(todo) + 1`` pools in all (each break either costs a point one
    of its lives or, without a known culprit, happens at most that often)."""
    from concurrent.futures import ProcessPoolExecutor, wait
    from concurrent.futures.process import BrokenProcessPool
    import multiprocessing as mp

    queue, deaths = list(todo), {}
    for _ in range(len(todo) + 1):
        if not queue:
            return
        ex = ProcessPoolExecutor(max_workers=min(workers, len(queue)),
                                 mp_context=mp.get_context("spawn"), initializer=_pool_init)
        futures = {ex.submit(run_point, p, out, estimate): p for p in queue}
        procs, yielded = {}, set()
        queue, broken = [], False
        try:
            pending = set(futures)
            # no iteration budget: each pass waits POLL_S at most and every future ends
            # (a result, or BrokenProcessPool when a worker dies)
            while pending:
                procs.update(getattr(ex, "_processes", None) or {})
                if stop:
                    _stop_pool(ex, procs, out)
                    raise Interrupted(stop[0])
                done, pending = wait(pending, timeout=POLL_S, return_when=FIRST_COMPLETED)
                for f in done:
                    try:
                        rec = f.result()
                    except BrokenProcessPool:
                        broken = True
                        continue
                    yielded.add(futures[f].id)
                    yield rec
                if broken:
                    break
        except BaseException:
            _stop_pool(ex, procs, out)
            raise
        if not broken:
            ex.shutdown(wait=True)
            return
        # the pool broke: which worker died, which point it ran, what finished anyway
        procs.update(getattr(ex, "_processes", None) or {})
        _stop_pool(ex, procs, out)
        # the pool terminated the other workers (SIGTERM) when one died: a point that
        # finished in such a worker after its result could no longer be sent is not trusted
        # (a run may take the signal in a phase that cannot stop, e.g. an error estimate,
        # and finish with a degraded estimate), so it is run again
        _distrust(out, [p.id for p in futures.values() if p.id not in yielded],
                  {pid for pid, pr in procs.items() if pr.exitcode == -signal.SIGTERM})
        if stop:
            # a Ctrl-C in the terminal reaches the workers too: they record their points
            # and end, which breaks the pool; the driver's own signal decides
            raise Interrupted(stop[0])
        dead = {pid for pid, pr in procs.items() if pr.exitcode is not None
                and pr.exitcode not in (0, -signal.SIGTERM, -signal.SIGINT)}
        for p in futures.values():
            if p.id in yielded:
                continue
            rec = _read_record(out, p.id)
            if rec is not None and finished(rec):
                yield rec                       # finished just before the break
                continue
            if rec is not None and rec.get("status") == "running" and rec.get("pid") in dead:
                deaths[p.id] = deaths.get(p.id, 0) + 1
                code = procs[rec["pid"]].exitcode
                notes.append(f"point {p.index}: its worker (pid {rec['pid']}) died "
                             f"({'signal ' + str(-code) if code < 0 else 'exit ' + str(code)})"
                             + ("; re-queued" if deaths[p.id] < MAX_DEATHS else "; failed"))
                if deaths[p.id] >= MAX_DEATHS:
                    rec.update(status="failed", finished=False, error=(
                        f"the worker running this point died {deaths[p.id]} times (killed, "
                        "or out of memory); run the study again to retry it"))
                    write_record(Path(out) / "points" / p.id, rec)
                    yield rec
                    continue
            queue.append(p)
    for p in queue:                              # the budget of pools is spent
        rec = {"id": p.id, "index": p.index, "changes": p.changes, "status": "failed",
               "finished": False, "error": "the study's workers kept dying (killed, or out "
               "of memory); run the study again to retry this point"}
        write_record(Path(out) / "points" / p.id, rec)
        yield rec


def _stop_pool(ex, procs, out):
    """Cancel what has not started; SIGTERM the workers (a run stops at its next safe point
    and records its point), wait GRACE_S for them, then kill the rest. No process is left.
    The points the workers were running are not trusted afterwards (:func:`_distrust`)."""
    ex.shutdown(wait=False, cancel_futures=True)
    alive = [p for p in procs.values() if p.exitcode is None]
    running = [rec["id"] for rec in map(lambda f: _read_record(out, f.parent.name),
                                        Path(out).glob("points/*/record.json"))
               if rec is not None and rec.get("status") == "running"]
    for p in alive:
        try:
            os.kill(p.pid, signal.SIGTERM)
        except (ProcessLookupError, TypeError):
            pass
    deadline = time.monotonic() + GRACE_S
    for p in alive:
        p.join(max(0.0, deadline - time.monotonic()))
    for p in alive:
        if p.exitcode is None:
            p.kill()
            p.join(1.0)
    _distrust(out, running, {p.pid for p in alive})


def _distrust(out, ids, pids):
    """Records of the points ``ids`` written by the processes ``pids`` after those were
    signalled: a "finished" one becomes "interrupted" (not finished), so that the next run
    of the study computes the point again. A run that takes the signal where it cannot stop
    (an error estimate's member) may end "converged" with a degraded estimate; a point
    recomputed needlessly costs only its time."""
    for pid_ in ids:
        rec = _read_record(out, pid_)
        if rec is not None and rec.get("pid") in pids and finished(rec):
            rec.update(status="interrupted", finished=False,
                       error="stopped by the study's signal while it ran")
            write_record(Path(out) / "points" / pid_, rec)


def _read_record(out, pid):
    try:
        return json.loads((Path(out) / "points" / pid / "record.json").read_text())
    except (OSError, ValueError):
        return None


@contextmanager
def _children_ignore_sigint():
    """Processes started in this block ignore SIGINT (an ignored signal stays ignored across
    exec, and Python then installs no KeyboardInterrupt handler): a Ctrl-C in the terminal,
    which reaches the whole process group, is the driver's to act on; Dask's nannies and
    workers would otherwise each die with a KeyboardInterrupt traceback."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    old = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, old)


def _execute_dask(todo, out, scheduler, estimate, stop):
    try:
        from distributed import Client, LocalCluster, as_completed
    except ImportError:
        raise DependencyError("a Dask study needs dask.distributed: pip install "
                              "'femadh[study]'") from None
    cluster = None
    if scheduler.startswith("local:"):
        n = int(scheduler.split(":", 1)[1])
        import logging

        # silence_logs: the workers' warnings about the futures a signal cancels are no
        # news to the user (the study says what it kept); errors still show
        with _children_ignore_sigint():
            cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                                   dashboard_address=None, silence_logs=logging.ERROR)
        client = Client(cluster)
    else:
        client = Client(scheduler)
    futures = []
    try:
        client.run(_worker_init)
        futures = [client.submit(run_point, p, str(out), estimate, pure=False) for p in todo]
        by_key = {f.key: p for f, p in zip(futures, todo)}
        ac = as_completed(futures)
        left = len(futures)
        # no iteration budget: each pass either takes finished futures or sleeps POLL_S,
        # and every future ends (a result, an error, KilledWorker after Dask's retries)
        while left:
            if stop:
                client.cancel(futures)
                raise Interrupted(stop[0])
            batch = ac.next_batch(block=False)
            if not batch:
                time.sleep(POLL_S)
                continue
            for f in batch:
                left -= 1
                try:
                    yield f.result()
                except Exception as exc:    # KilledWorker after Dask's own retries, ...
                    p = by_key[f.key]
                    rec = _read_record(out, p.id) or {"id": p.id, "index": p.index,
                                                       "changes": p.changes}
                    rec.update(status="failed", finished=False, error=(
                        f"{type(exc).__name__}: the Dask worker running this point failed "
                        f"({exc}); run the study again to retry it"))
                    write_record(Path(out) / "points" / p.id, rec)
                    yield rec
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
