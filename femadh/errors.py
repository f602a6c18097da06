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
        shown = "(missing)" if value is _MISSING else repr(value)
        super().__init__(f"{where}[{key}] = {shown}: expected {expected}")


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


class MeshResolutionWarning(UserWarning):
    """The discretisation is too coarse for the surface forces' stiffness: single nodes can
    snap on their own (lattice trapping) and results depend on the mesh."""
