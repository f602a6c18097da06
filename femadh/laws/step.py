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

    def edge_softening(self, floor):
        """Secant softening (Pa/m) of the step from the floor gap across its edge:
        P(floor) / (h_c + 2w - floor), the pressure a surface at the floor loses per metre of
        opening until it has passed the edge (S(-2) = 0.12); 0 where h_c + 2w <= floor (a
        step the surfaces cannot reach).

        Why: on a sigma-gap contact a step whose edge lies just above the floor is a
        Dugdale cohesive zone of stress P0 and opening h_c - floor at the contact edge,
        (pi/4) E* (h_c - floor) / P0 long (~34 nm for ethanol at p/psat = 0.15 on
        sigma = 0.489 nm); a band spacing comparable to it unzips the contact node by node
        (lattice trapping, femadh.discretisation.plan.trapping_ratio). Its pointwise
        softening P0/(4w) is the smoothing's, not a length to resolve; the secant is."""
        reach = self._center + 2.0 * self.width - floor
        if not reach > 0:
            return 0.0
        return float(self.pressure(np.array([floor]))[0]) / reach
