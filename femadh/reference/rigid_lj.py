"""Lennard-Jones force between a rigid sphere and a flat (paper 1 eqs 14-15)."""


def rigid_sphere_lj_force(h0, hamaker, z0, radius):
    """F_LJr = A R / (6 h0^2) [1 - z0^6 / (4 h0^6)] (N), eq (14): eq (3) integrated over the
    whole plane under the Derjaguin (paraboloid) approximation, attractive positive."""
    return hamaker * radius / (6.0 * h0**2) * (1.0 - z0**6 / (4.0 * h0**6))


def max_rigid_lj_force(hamaker, z0, radius):
    """Maximum of eq (14), A R / (8 z0^2) (N), reached at h0 = z0; equals 2 pi R Delta gamma."""
    return hamaker * radius / (8.0 * z0**2)


def contact_lj_force_estimate(h0, contact_radius, hamaker, z0, radius):
    """F_LJ* of eq (15) (N): rigid-sphere force at h0 plus P_LJ(h0) over the contact area."""
    inside = hamaker * contact_radius**2 / (6.0 * h0**3) * (1.0 - z0**6 / h0**6)
    return rigid_sphere_lj_force(h0, hamaker, z0, radius) + inside
