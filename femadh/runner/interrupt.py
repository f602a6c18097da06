"""SIGINT and SIGTERM during a run: finish or drop the current state, then stop cleanly.

Inside :func:`interruptible` the signals only set a flag; the run calls :func:`check` at safe
points (after each state is committed to disk), which raises :class:`Interrupted` there. A
second signal while the first is pending stops at once (the user insists); the output files
are still consistent (see femadh.io.atomic). Outside the main thread (e.g. a Dask worker) the
handlers cannot be installed and the guard is a no-op.
"""
from contextlib import contextmanager
import signal
import threading

from ..errors import Interrupted

_pending = []


def _handler(signum, frame):
    if _pending:
        raise Interrupted(signum)
    _pending.append(signum)


@contextmanager
def interruptible():
    """Defer SIGINT/SIGTERM to the next :func:`check` while the block runs."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    old = {s: signal.signal(s, _handler) for s in (signal.SIGINT, signal.SIGTERM)}
    _pending.clear()
    try:
        yield
    finally:
        for s, h in old.items():
            signal.signal(s, h)
        _pending.clear()


def check():
    """Raise Interrupted if a signal arrived since the block started."""
    if _pending:
        raise Interrupted(_pending[0])
