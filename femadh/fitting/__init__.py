"""Measured force curves against femadh: comparison (:mod:`.compare`) and least-squares fits
of scene parameters and the contact-point offset (:mod:`.lsq`); the simulated curve as a
function of the measured position (:mod:`.model`)."""
from .lsq import FitError, FitResult, fit_curve
from .model import SimCurve, sim_curve

__all__ = ["FitError", "FitResult", "fit_curve", "SimCurve", "sim_curve"]
