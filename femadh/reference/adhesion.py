"""Adhesive-contact theories: JKR, DMT and the Hamaker/surface-energy relations (paper 1)."""
import math


def surface_energy_from_hamaker(hamaker, spacing, z0):
    """Delta gamma = A/(12 pi s^2) [1 - z0^6/(4 s^6)] (J/m^2), paper 1 eq (17).

    With s = z0 it reduces to eq (19), A/(16 pi z0^2).
    """
    return hamaker / (12.0 * math.pi * spacing**2) * (1.0 - z0**6 / (4.0 * spacing**6))


def jkr_contact_radius(load, radius, e_star, work_of_adhesion):
    """JKR contact radius (m) for a compressive load F (N, negative = tensile); paper 1 sec 4:

    r_c^3 = 3R/(4E*) [F + 3 pi dg R + sqrt(6 pi dg R F + (3 pi dg R)^2)].
    Returns nan where the root does not exist (F below the pull-off -1.5 pi R dg).
    """
    q = 3.0 * math.pi * work_of_adhesion * radius
    disc = 6.0 * math.pi * work_of_adhesion * radius * load + q * q
    if disc < 0:
        return math.nan
    return (3.0 * radius / (4.0 * e_star) * (load + q + math.sqrt(disc))) ** (1.0 / 3.0)


def dmt_contact_radius(load, radius, e_star, work_of_adhesion):
    """DMT contact radius (m): r_c^3 = 3R/(4E*) (F + 2 pi R dg); nan below pull-off."""
    v = load + 2.0 * math.pi * radius * work_of_adhesion
    return (3.0 * radius / (4.0 * e_star) * v) ** (1.0 / 3.0) if v >= 0 else math.nan


def jkr_pull_off(radius, work_of_adhesion):
    """JKR pull-off force 1.5 pi R dg (N)."""
    return 1.5 * math.pi * radius * work_of_adhesion


def dmt_pull_off(radius, work_of_adhesion):
    """DMT (Derjaguin) pull-off force 2 pi R dg (N), paper 1 eq (16)."""
    return 2.0 * math.pi * radius * work_of_adhesion


def tabor_parameter(radius, work_of_adhesion, e_star, z0):
    """Tabor parameter mu = (R dg^2 / (E*^2 z0^3))^(1/3)."""
    return (radius * work_of_adhesion**2 / (e_star**2 * z0**3)) ** (1.0 / 3.0)
