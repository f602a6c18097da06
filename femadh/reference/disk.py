"""Uniform pressure on a disk of an elastic half-space (Johnson, *Contact Mechanics*, 1985,
eq 3.41), in the complete-elliptic-integral form E, K of the parameter m: the judge of the
Green operator (which evaluates the outside with a hypergeometric function instead) and the
homogeneous part of the layered reference."""
import math

import numpy as np
from scipy import special


def uniform_disk_displacement(r, a, e_star, p=1.0):
    """Surface displacement (m) at radius r of a pressure p (Pa) on the disk r < a (m):
    4 p a E((r/a)^2)/(pi E*) inside, 4 p r [E(m) - (1 - m) K(m)]/(pi E*) outside, m = (a/r)^2.
    (Outside, E - (1 - m) K cancels for r >> a: about 1e-13 relative at r = 50 a.)"""
    r, a = np.broadcast_arrays(np.asarray(r, float), np.asarray(a, float))
    out = np.zeros(r.shape)
    inside = (r <= a) & (a > 0)
    out[inside] = 4 * a[inside] / math.pi * special.ellipe((r[inside] / a[inside]) ** 2)
    outside = (r > a) & (a > 0)
    m = (a[outside] / r[outside]) ** 2
    out[outside] = 4 * r[outside] / math.pi * (special.ellipe(m) - (1 - m) * special.ellipk(m))
    return p * out / e_star
