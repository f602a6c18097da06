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
worker (SIGTERM: its temporary files are removed) and the run ends "interrupted" as before
(--resume draws them); a worker that died, could not be reached, or reported an error leaves
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


def draw_figures(res, folder):
    """The run's figures into its folder (:func:`femadh.io.plots.contact_figures`), by the
    figure worker when the command started one; a signal stops them at once (each file is
    written whole or not at all) and the run ends "interrupted" (--resume draws them).
    Their time goes to ``res.timings["figures_s"]``."""
    t0 = time.perf_counter()
    try:
        with interrupt.immediate():
            worker = _WORKER[0]
            left = worker.draw(res, folder.path) if worker is not None else None
            if left is None or left:
                from ..io.plots import contact_figures

                contact_figures(res, folder.path, only=left)
        res.timings["figures_s"] = time.perf_counter() - t0
    except Interrupted as exc:
        res.stop(exc, " while drawing the figures")


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

    def draw(self, res, folder):
        """Have the worker draw ``res``'s figures into ``folder``; returns the names of the
        figures it did not write (to be drawn in-process: empty when it wrote them all),
        None when it could not take the job. A signal (Interrupted) stops the worker and
        is raised again."""
        if self.sent or self.pid is None:
            return None
        try:
            job = pickle.dumps((res, str(folder)), protocol=pickle.HIGHEST_PROTOCOL)
        except Exception:                 # (a result that does not pickle: drawn here)
            return None
        from ..io.plots import figure_names

        names = figure_names(res)
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


def _terminate(signum, frame):
    raise SystemExit(0)


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
        res, folder = _recv(job_r)
    except EOFError:
        return
    names = plots.figure_names(res)
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


def _draw_one(plots, res, folder, name, fd):
    try:
        plots.contact_figures(res, folder, only=[name])
    except Exception as exc:
        _send(fd, ("error", name, f"{type(exc).__name__}: {exc}"))
    else:
        _send(fd, ("done", name))
