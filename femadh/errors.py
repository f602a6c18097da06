"""Exceptions raised by femadh.

Every error says what was wrong with numbers or names, so that a user can act on it without
reading the code.
"""


class FemadhError(Exception):
    """Base class of all femadh errors."""


class SceneError(FemadhError, ValueError):
    """A scene file is malformed: names the file, the key, the value and what was expected."""

    def __init__(self, file, key, value, expected):
        self.file, self.key, self.value, self.expected = file, key, value, expected
        where = f"{file}: " if file else ""
        if key == "(file)":
            # the file itself (unreadable, not TOML): no key to name, its value is the file
            super().__init__(f"{where}expected {expected}")
            return
        super().__init__(f"{where}[{key}] = {_shown(value)}: expected {expected}")


def _shown(value):
    """A scene value as the error line shows it: TOML's true/false, a table by its keys (a
    misspelt table's whole content would bury the line)."""
    if value is _MISSING:
        return "(missing)"
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, dict):
        return "(a table of " + (", ".join(map(str, value)) or "no keys") + ")"
    return repr(value)


class SceneErrors(SceneError):
    """Several things wrong with one scene: all of them, one per line (``errors``)."""

    def __init__(self, errors):
        self.errors = list(errors)
        first = self.errors[0]
        self.file, self.key, self.value, self.expected = (first.file, first.key, first.value,
                                                          first.expected)
        Exception.__init__(self, "\n".join(str(e) for e in self.errors))


def given_by(exc, where, keys):
    """``exc`` (a SceneError, or SceneErrors) with each line about one of ``keys`` named against
    ``where`` instead of the scene file: the value came from a call or an option, and the file
    does not hold it. A line is about a key when its key is that key or lies under it (a table
    given whole: ``{"solver": {"accuracy": -1}}`` is about ``solver.accuracy``); every other
    line keeps its file. ``where``: a label (``"given to Scene.replace"``) or a function of the
    line's key giving one (``"--vary sphere.radius"``)."""
    keys = [k for k in keys if isinstance(k, str)]

    def about(key):
        return isinstance(key, str) and any(key == k or key.startswith(k + ".") for k in keys)

    errs = [SceneError(where(e.key) if callable(where) else where, e.key, e.value, e.expected)
            if about(e.key) else e for e in getattr(exc, "errors", [exc])]
    return errs[0] if len(errs) == 1 else SceneErrors(errs)


class _Missing:
    def __repr__(self):
        return "(missing)"


_MISSING = _Missing()


class ConvergenceError(FemadhError, RuntimeError):
    """A nonlinear solve did not converge; carries the step, residual and iteration count."""

    def __init__(self, message, *, d=None, residual=None, n_iter=None):
        self.d, self.residual, self.n_iter = d, residual, n_iter
        parts = [message]
        if d is not None:
            parts.append(f"d = {d * 1e9:.6g} nm")
        if residual is not None:
            # a non-finite residual is a bug's symptom, not a number to report: the place
            # where the non-finite value arose raises its own error first
            parts.append(f"residual = {residual:.3e} m" if residual == residual
                         and abs(residual) != float("inf") else "no finite residual")
        if n_iter is not None:
            parts.append(f"after {n_iter} iterations")
        super().__init__("; ".join(parts))


class LawError(FemadhError, ValueError):
    """A pressure law is inconsistent (its derivative or energy does not match its value) or
    returned a non-finite value."""


class DomainError(FemadhError, ValueError):
    """A physical model is asked for a state outside its domain of validity."""


class OutputError(FemadhError, OSError):
    """An output file or folder cannot be written (permissions, disk full, a file where a
    folder is needed, a folder in use or holding another run): names the path and why."""


class DependencyError(FemadhError, ImportError):
    """An optional dependency a scene needs is not installed: says which extra to install."""


class Interrupted(FemadhError):
    """A run stopped by SIGINT or SIGTERM at a safe point (completed states are kept)."""

    def __init__(self, signum):
        import signal

        self.signum = signum
        self.exit_code = 128 + signum
        name = signal.Signals(signum).name
        super().__init__(f"interrupted by {name}")

    #: the status a run stopped by this ends with (summary.json)
    status = "interrupted"


#: exit code of a run that reached its time limit (``[solver] time_limit``, ``--time-limit``)
EXIT_TIME_LIMIT = 6


class TimeLimitReached(Interrupted):
    """A run stopped by its time limit at a safe point (completed states kept; status "time
    limit", exit code 6; ``--resume`` continues it)."""

    status = "time limit"

    def __init__(self, limit_s):
        self.signum = None
        self.limit_s = limit_s
        self.exit_code = EXIT_TIME_LIMIT
        FemadhError.__init__(self, f"time limit {_duration(limit_s)} reached")


def _duration(s):
    """'90 s', '10 min', '2 h' for a number of seconds."""
    if s >= 3600 and s % 360 == 0:
        return f"{s / 3600:g} h"
    if s >= 60 and s % 6 == 0:
        return f"{s / 60:g} min"
    return f"{s:g} s"


class MeshResolutionWarning(UserWarning):
    """The discretisation is too coarse for the surface forces' stiffness: single nodes can
    snap on their own (lattice trapping) and results depend on the mesh."""
