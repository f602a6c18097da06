"""Far-field data of the truncated half-space: the Boussinesq point-load field (its leading
term at distances much larger than the loaded disk)."""
import math

import numpy as np


def boussinesq(r, z, youngs, nu):
    """Displacement (u_r, u_z) (m per N) of a unit upward point force at the origin of the
    half-space z <= 0 (Johnson 1985 eq 3.21a-b with depth -z; upward pull, u_z up)."""
    G = youngs / (2 * (1 + nu))
    zeta = -np.asarray(z, float)
    r = np.asarray(r, float)
    rho = np.hypot(r, zeta)
    c = 1.0 / (4 * math.pi * G)
    u_z = c * (zeta**2 / rho**3 + 2 * (1 - nu) / rho)
    u_r = -c * (r * zeta / rho**3 - (1 - 2 * nu) * r / (rho * (rho + zeta)))
    return u_r, u_z
