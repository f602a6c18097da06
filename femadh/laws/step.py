"""A pressure that switches on below a gap, smoothed so Newton sees a differentiable law.

P(h) = P0 S(x), x = (h_c - h)/w, S(x) = 1/(1 + exp(-x)) (logistic); dP/dh = -P0 S (1 - S)/w;
U(h) = -P0 w softplus(x), so that dU/dh = P and U -> 0 for h >> h_c.
"""
import numpy as np


class SmoothStepLaw:
    """Mixin: subclasses provide ``_amplitude`` (P0, Pa), ``_center`` (h_c, m), ``width`` (m).

    ``SUBGRID``: whether the contact problem integrates the step over the gap field between
    the nodes (:mod:`femadh.contact.subgrid`) rather than collocating it at the nodes. Off by
    default (eq 20's asperity adhesion sits on the sigma-gap and stays as it was); the
    capillary condensate, whose edge is narrower than the gap change across a node, sets it.
    """

    SUBGRID = False

    def _x(self, h):
        return (self._center - np.asarray(h, float)) / self.width

    def pressure(self, h):
        return self._amplitude * 0.5 * (1 + np.tanh(0.5 * self._x(h)))

    def dpressure(self, h):
        s = 0.5 * (1 + np.tanh(0.5 * self._x(h)))
        return -self._amplitude / self.width * s * (1 - s)

    def energy(self, h):
        return -self._amplitude * self.width * np.logaddexp(0.0, self._x(h))
