"""Consistency of a pressure law: value, derivative and energy must belong together.

Newton's method uses ``dpressure`` as the Jacobian of ``pressure`` and the landing after a fold
descends ``energy``; a law whose three parts disagree makes the solvers crawl or land in the
wrong place instead of failing. :func:`check_law` compares each with a central finite
difference of the other over the gaps a contact can reach, and names the first disagreement.
"""
import numpy as np

from ..errors import LawError

#: gaps sampled (m): 0.05 nm to 1 um, 60 per decade
GAPS = np.geomspace(0.05e-9, 1e-6, 60 * 5 + 1)
#: relative step of the central differences (truncation ~1e-12, round-off ~1e-10)
FD_STEP = 1e-6
#: allowed disagreement relative to the largest |value| within half a decade of the gap
RTOL = 1e-4


def _window_max(x, half):
    pad = np.pad(np.abs(x), half, mode="edge")
    return np.lib.stride_tricks.sliding_window_view(pad, 2 * half + 1).max(axis=1)


def check_law(name, law, gaps=GAPS, rtol=RTOL):
    """Raise LawError unless ``law.dpressure`` is the derivative of ``law.pressure`` and
    ``law.pressure`` that of ``law.energy`` (both within ``rtol`` of the local scale) and all
    three are finite at ``gaps`` (m)."""
    h = np.asarray(gaps, float)
    eps = FD_STEP * h
    vals = {}
    for part in ("pressure", "dpressure", "energy"):
        v = np.asarray(getattr(law, part)(h), float)
        bad = ~np.isfinite(v)
        if bad.any():
            k = int(np.flatnonzero(bad)[0])
            raise LawError(f"law {name!r}: {part}(h) is not finite at h = {h[k]:.4g} m")
        vals[part] = v
    for part, of in (("dpressure", "pressure"), ("pressure", "energy")):
        f = getattr(law, of)
        fp, fm = np.asarray(f(h + eps)), np.asarray(f(h - eps))
        fd = (fp - fm) / (2 * eps)
        # the difference quotient's own round-off, |f| eps_machine / eps: where a smoothed
        # step has saturated it dominates the (tiny) true derivative
        noise = 10 * np.finfo(float).eps * (np.abs(fp) + np.abs(fm)) / (2 * eps)
        # local scale, floored at 1e-9 of the global one
        scale = _window_max(fd, 15) + 1e-9 * np.max(np.abs(fd)) + 1e-300
        err = np.maximum(np.abs(vals[part] - fd) - noise, 0.0) / scale
        if np.any(err > rtol):
            k = int(np.argmax(err))
            raise LawError(f"law {name!r}: {part} is not the derivative of {of}: at h = "
                           f"{h[k]:.4g} m it is {vals[part][k]:.6g}, the finite difference "
                           f"{fd[k]:.6g} ({err[k]:.2g} of the local scale, allowed {rtol:g})")
