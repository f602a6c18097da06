"""Analytic reference solutions: the independent judges of the numerical solvers.

Pure functions of SI floats/arrays. Nothing here imports a solver, and no solver imports
them: they judge the solvers in tests and validation, and the figures draw them beside the
results.
"""
from .disk import uniform_disk_displacement
from .hertz import hertz_contact_radius, hertz_load, hertz_pressure, hertz_displacement
from .rigid_lj import rigid_sphere_lj_force, contact_lj_force_estimate, max_rigid_lj_force
from .adhesion import (surface_energy_from_hamaker, jkr_contact_radius, dmt_contact_radius,
                       jkr_pull_off, dmt_pull_off, tabor_parameter)

__all__ = [
    "uniform_disk_displacement",
    "hertz_contact_radius", "hertz_load", "hertz_pressure", "hertz_displacement",
    "rigid_sphere_lj_force", "contact_lj_force_estimate", "max_rigid_lj_force",
    "surface_energy_from_hamaker", "jkr_contact_radius", "dmt_contact_radius",
    "jkr_pull_off", "dmt_pull_off", "tabor_parameter",
]
