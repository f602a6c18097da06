"""SIGINT and SIGTERM during a run, and its time limit: stop cleanly at the next safe point.

Inside :func:`interruptible` the signals only set a flag; the run calls :func:`check` at safe
points, which raises :class:`Interrupted` there. The safe points are cheap (a list test and a
clock read) and frequent: every Newton / complementarity / arclength-corrector iteration
(nothing is written inside a solve: a state reaches the files only once it has converged),
every committed state, every estimate member's iterations, and between the figures. So a
signal ends the run within one iteration (milliseconds to ~1 s on the largest grids), not one
state or one phase. Inside :func:`immediate` (phases that write nothing but whole files
atomically: the operator build, the figures) the handler raises at once.

A second signal while the first is pending stops at once (the user insists); the output files
are still consistent (see femadh.io.atomic). Outside the main thread (e.g. a Dask worker) the
handlers cannot be installed and the guard is a no-op. A signal the parent process set to
be ignored (``nohup``, a background job started with SIGINT ignored, a pool worker that
leaves Ctrl-C to its driver) stays ignored: its SIG_IGN is left in place, not replaced by the
run's handler, so the run goes on as its parent asked.

The blocks nest: a run inside a run (an estimate's coarser members) shares the outer run's
flag, so a signal that arrives during a member stops the whole run (it is never consumed by
the member and turned into a warning).

A deadline (``[solver] time_limit``, ``--time-limit``) is checked at the same safe points and
raises :class:`TimeLimitReached`.

Outside a run's blocks the ``femadh`` program takes SIGTERM as Python takes SIGINT:
:func:`raise_terminated` raises :class:`Terminated`, a KeyboardInterrupt, wherever the program
is (its start: parsing, the scene's checks, the lazy imports, a study claiming its folder; or
the report after the run), so that every ``finally`` and ``with`` on the way out runs (a lock
released, a temporary file removed: nothing half-written) and the command ends in one line,
exit 143 (:mod:`femadh.cli`), as a run stopped by SIGTERM does.
"""
from contextlib import contextmanager
import signal
import threading
import time

from .errors import Interrupted, TimeLimitReached


class Terminated(KeyboardInterrupt):
    """SIGTERM raised at once, as Python raises KeyboardInterrupt for SIGINT (see the module
    docstring): whatever catches a Ctrl-C catches it; ``signum`` / ``exit_code`` say which
    signal it was (SIGINT's KeyboardInterrupt has neither: 2 / 130)."""

    signum = signal.SIGTERM
    exit_code = 128 + signal.SIGTERM


def raise_terminated(signum, frame):
    """The femadh program's SIGTERM outside a run's blocks (set by :func:`femadh.cli.main`;
    a run's :func:`interruptible` replaces it and puts it back)."""
    raise Terminated("SIGTERM")


_pending = []
#: nesting depth of interruptible() blocks (only the outermost installs and restores)
_depth = [0]
#: nesting depth of immediate() blocks
_immediate = [0]
#: (monotonic deadline, limit in s) of the outermost run, or None
_deadline = [None]


def _handler(signum, frame):
    if _pending or _immediate[0]:
        if not _pending:
            _pending.append(signum)
        raise Interrupted(_pending[0] if _pending[0] == signum else signum)
    _pending.append(signum)


@contextmanager
def interruptible(time_limit=None):
    """Defer SIGINT/SIGTERM to the next :func:`check` while the block runs; ``time_limit``
    (s, outermost block only) makes :func:`check` raise TimeLimitReached after it."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    if _depth[0]:
        # nested (an estimate member inside a run): the outer block's handlers and flag
        _depth[0] += 1
        try:
            yield
        finally:
            _depth[0] -= 1
        return
    # (a signal the parent set to SIG_IGN stays ignored: that was its parent's request)
    old = {s: signal.signal(s, _handler) for s in (signal.SIGINT, signal.SIGTERM)
           if signal.getsignal(s) is not signal.SIG_IGN}
    _pending.clear()
    _depth[0] = 1
    _deadline[0] = (time.monotonic() + time_limit, time_limit) if time_limit else None
    try:
        yield
    finally:
        for s, h in old.items():
            signal.signal(s, h)
        _pending.clear()
        _depth[0] = 0
        _deadline[0] = None


@contextmanager
def immediate():
    """Inside an interruptible block: a signal raises Interrupted at once (for phases that
    write only whole files atomically, or nothing); a signal already pending raises on
    entry."""
    check()
    _immediate[0] += 1
    try:
        yield
    finally:
        _immediate[0] -= 1


def check():
    """Raise Interrupted if a signal arrived since the block started, TimeLimitReached if the
    run's time limit has passed."""
    if _pending:
        raise Interrupted(_pending[0])
    if _deadline[0] is not None and time.monotonic() > _deadline[0][0]:
        raise TimeLimitReached(_deadline[0][1])


def time_limit():
    """The running block's time limit (s), or None."""
    return _deadline[0][1] if _deadline[0] else None


def pending():
    """The signal number waiting for the next check, or None."""
    return _pending[0] if _pending else None
