"""Analytic reference solutions: the independent judges of the numerical solvers.

Pure functions of SI floats/arrays; nothing here imports a solver.
"""
from .hertz import (hertz_contact_radius, hertz_load, hertz_pressure, hertz_displacement,
                    hertz_annulus_force, hertz_annulus_force_drc)
from .rigid_lj import rigid_sphere_lj_force, contact_lj_force_estimate, max_rigid_lj_force
from .adhesion import (surface_energy_from_hamaker, jkr_contact_radius, dmt_contact_radius,
                       jkr_pull_off, dmt_pull_off, tabor_parameter)

__all__ = [
    "hertz_contact_radius", "hertz_load", "hertz_pressure", "hertz_displacement",
    "hertz_annulus_force", "hertz_annulus_force_drc",
    "rigid_sphere_lj_force", "contact_lj_force_estimate", "max_rigid_lj_force",
    "surface_energy_from_hamaker", "jkr_contact_radius", "dmt_contact_radius",
    "jkr_pull_off", "dmt_pull_off", "tabor_parameter",
]
