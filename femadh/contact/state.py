"""An equilibrium of the surface at one separation, as the solvers produce it."""
from dataclasses import dataclass, field

import numpy as np


@dataclass(eq=False)
class State:
    """A converged (or failed) equilibrium at one separation d.

    Attributes
    ----------
    d : float
        Separation of the sphere tip from the undeformed mean plane (m).
    w, h : ndarray
        Surface displacement (m, up positive) and gap h = b - w (m) at the nodes.
    p_effects : dict[str, ndarray]
        Each effect's pressure (Pa, attractive positive).
    p_contact : ndarray
        Contact (asperity elastic) pressure, repulsive positive (Pa): the complementarity
        multiplier or the paper's Hertz closure, eq (9).
    active : ndarray of bool
        Nodes held at h = sigma (complementarity) or inside r_c (Hertz closure).
    r_c : float
        Contact radius (m): area-equivalent radius of the active set (complementarity) or the
        closure's own r_c with h(r_c) = sigma (Hertz closure).
    n_iter : int
        Newton iterations of the final corrector.
    residual : float
        max_k |w - C (P - p_c)| (m): the residual of eq (6)/(10) itself.
    converged, stable : bool
        Newton met the tolerance; the state is a local energy minimum (see newton.py).
    """

    d: float
    w: np.ndarray
    h: np.ndarray
    p_effects: dict
    p_contact: np.ndarray
    active: np.ndarray
    r_c: float
    n_iter: int
    residual: float
    converged: bool
    stable: bool
    lu: object = None  # factorisation of the reduced Jacobian (tangent predictor), transient
    #: (d (m), contact nodes) of the accepted state before this one on its piece of the
    #: branch (None: the first, or after a landing): the edge predictor's second point
    #: (:func:`femadh.contact.stepping.edge_set`)
    edge_from: tuple = None
    diagnostics: dict = field(default_factory=dict)
    #: the stepping's expectation of the next lattice snap as this grid state left it
    #: (:meth:`femadh.contact.snap.SnapRhythm.snapshot`; None: none recorded): a trace of
    #: the same branch started from this state goes on with it (a checkpoint keeps it)
    snap_rhythm: tuple = None

    @property
    def h0(self):
        """Gap at the axis, h(0) = d - w(0) (m)."""
        return float(self.h[0])

    @property
    def p_total(self):
        """Net attractive surface pressure (Pa): sum of effects minus contact pressure."""
        return net_pressure(self.p_effects, self.p_contact)


def net_pressure(p_effects, p_contact):
    """Net attractive surface pressure (Pa) at the nodes: the sum of the laws' pressures
    ``p_effects`` (name -> array) minus the contact pressure ``p_contact``."""
    p = -np.array(p_contact, dtype=float)
    for v in p_effects.values():
        p += v
    return p
