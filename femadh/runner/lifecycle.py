"""The life of one run, the same for every scene kind (contact, meniscus).

A run's ``summary.json`` says "running" from the moment its folder is claimed; the run then
ends in exactly one status, written last, atomically:

- the work returns: "converged" [1];
- a solver failure (one of ``failures``): "failed", ``error`` its words, ``failure_kind`` its
  kind by its type (:func:`femadh.estimate.guards.failure_kind`: what the refine loops read);
- SIGINT / SIGTERM (:class:`~femadh.errors.Interrupted`): "interrupted";
- the time limit (:class:`~femadh.errors.TimeLimitReached`): "time limit";
- anything else (a full disk, a bug, a KeyboardInterrupt outside the main thread): "failed",
  ``error`` "Type: message", and the exception is raised again.

[1] unless the work decided otherwise (e.g. no point of a meniscus scene has a meniscus), and
after a last :func:`femadh.interrupt.check`: a signal that arrived after the last safe point
still stops the run (it never ends "converged" once the user asked it to stop).

A stopped run keeps its exit code (130 SIGINT, 143 SIGTERM, 6 time limit) in
``result.exit_code``; every state committed before the end stays on disk whatever the end
(the work streams states as they are computed; the lifecycle only writes the summary).
:func:`raise_if_stopped` is the Python API's ending: an interrupted run reaches a script as
KeyboardInterrupt (SystemExit(143) after SIGTERM), so that one Ctrl-C stops a loop of runs.

    res = ContactResult(scene.name, scene)
    with lifecycle(res, write_summary, failures=(ConvergenceError,)) as life:
        life.cleanup(writer.close)          # run at the end, before the final summary
        ...                                 # the work, calling interrupt.check() often
    return res
"""
from contextlib import contextmanager
import signal
import time

from .. import interrupt
from ..errors import Interrupted
from ..estimate.guards import failure_kind


class Life:
    """The handle of a running run (what :func:`lifecycle` yields).

    Attributes
    ----------
    on_stop : callable or None
        Called after the run was stopped (interrupted or time limit) and its status set,
        before the cleanups (e.g. save the last committed state whole).
    untouched_on : tuple of exception types
        A failure of these types leaves the folder as it was: no summary is written (e.g.
        a resumed folder refused while its record is checked).
    """

    def __init__(self, result, write):
        self.result = result
        self._write = write
        self._cleanups = []
        self.on_stop = None
        self.untouched_on = ()

    def write_summary(self, status=None):
        """Write summary.json (``status`` overriding the result's) if the run has a folder."""
        if self._write is not None:
            self._write(status)

    def cleanup(self, fn):
        """Run ``fn()`` when the run ends (in the order registered), whatever the end, before
        the final summary."""
        self._cleanups.append(fn)


@contextmanager
def lifecycle(result, write=None, *, failures=(), announce=True, t0=None):
    """Run the block as ``result``'s run (see the module docstring).

    Parameters
    ----------
    result : RunResult
        Its ``status``, ``error``, ``exit_code`` and ``timings["total_s"]`` are set here.
    write : callable, optional
        ``write(status=None)`` writes summary.json (None: the run writes nothing).
    failures : tuple of exception types
        The work's failures that end the run "failed" without raising (a solve that does
        not converge, a guard).
    announce : bool
        Write the "running" summary on entry (a resumed run writes it itself once the
        folder's record is checked: ``life.write_summary("running")``).
    t0 : float, optional
        ``time.perf_counter()`` when the run began (default: on entry).

    Yields
    ------
    Life
    """
    t0 = time.perf_counter() if t0 is None else t0
    life = Life(result, write)
    with interrupt.interruptible():
        try:
            if announce:
                try:
                    life.write_summary("running")
                except Interrupted:
                    # a signal while the "running" summary was written (it writes whole
                    # files in an immediate block): it stays pending and the block stops at
                    # its first safe point - a context manager must yield once (returning
                    # here was "generator didn't yield": a study point recorded an internal
                    # error where it had been interrupted)
                    pass
            yield life
            # a signal that arrived after the last safe point is still a stop
            interrupt.check()
            if result.status == "running":
                result.status = "converged"
        except failures as exc:
            result.fail(str(exc), failure_kind(exc))
        except Interrupted as exc:
            result.stop(exc)
            if life.on_stop is not None:
                life.on_stop()
        except BaseException as exc:
            # an output fault, a law error, a bug: the summary must not say "converged"
            result.fail(f"{type(exc).__name__}: {exc}" if str(exc) else type(exc).__name__)
            if isinstance(exc, life.untouched_on):
                life._write = None
            raise
        finally:
            for fn in life._cleanups:
                fn()
            result.timings["total_s"] = time.perf_counter() - t0
            life.write_summary()


def raise_if_stopped(result):
    """``result``, unless it was interrupted: then KeyboardInterrupt (after SIGINT) or
    SystemExit(143) (after SIGTERM), its states kept on disk. A run ended by its time limit
    is returned (status "time limit"): it is the run's own budget, not the user's stop."""
    if result.status != "interrupted":
        return result
    if result.exit_code == 128 + signal.SIGTERM:
        raise SystemExit(result.exit_code)
    raise KeyboardInterrupt(f"{result.error}: the states computed before it are kept in "
                            f"{result.out_dir}" if result.out_dir else
                            f"{result.error} (no output folder: nothing was kept)")
