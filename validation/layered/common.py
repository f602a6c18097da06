"""What the layered studies share: the results folder, the error measure, the bodies (paper 1's
slider and disk; a silica tip on a PDMS-like film on glass), the film's LJ law and the
readout of one traced film curve."""
import math
from pathlib import Path
import time

import numpy as np

from femadh.contact import ContactProblem
from femadh.contact.arclength import trace_curve
from femadh.contact.curve import read_curve
from femadh.discretisation.moving import contact_edge
from femadh.elastic import RadialGrid
from femadh.indenter import Sphere
from femadh.materials import IsotropicMaterial, composite_modulus
from femadh.studies.smooth_sphere import lj_force

RESULTS = Path(__file__).resolve().parents[1] / "results"


def rel(w, ref):
    """max |w - ref| / max |ref|."""
    return float(np.max(np.abs(w - ref)) / np.max(np.abs(ref)))


def fmt(x, spec=".3g"):
    """``x`` formatted, "-" for None or NaN."""
    return "-" if x is None or (isinstance(x, float) and math.isnan(x)) else format(x, spec)


def write_result(name, text):
    """Write ``results/<name>`` and echo it."""
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / name).write_text(text)
    print(text)


# ---- paper 1's slider on a magnetic disk ------------------------------------------------
SLIDER_R = 2e-3
DISK = IsotropicMaterial(163e9, 0.3)
SLIDER = IsotropicMaterial(83e9, 0.21)


def slider_grid():
    """N = 200 uniform nodes on a = sqrt(2 R x 10 nm), as the paper's Fig 3/4 scenes."""
    return RadialGrid.uniform(math.sqrt(2 * SLIDER_R * 10e-9), 200)


# ---- a silica tip on a soft polymer film on glass ---------------------------------------
TIP_R = 1e-6
TIP = IsotropicMaterial(73e9, 0.17)           # fused silica
FILM = IsotropicMaterial(2e6, 0.499)          # PDMS-like: E = 2 MPa, nearly incompressible
GLASS = IsotropicMaterial(70e9, 0.22)         # soda-lime glass
#: work of adhesion of paper 1's LJ law (A = 1e-19 J, z0 = 0.165 nm)
FILM_DG = 1e-19 / (16 * math.pi * 0.165e-9**2)
#: Tabor parameter of the film half-space the LJ range is widened to (see layered_film.md)
FILM_MU = 3.0


def film_law():
    """(Hamaker constant J, z0 m) of the LJ law of work of adhesion FILM_DG whose range z0
    gives Tabor mu = FILM_MU on the film's half-space (with the tip's compliance)."""
    es = composite_modulus(FILM, TIP)
    z0 = (TIP_R * FILM_DG**2 / (es**2 * FILM_MU**3)) ** (1 / 3)
    return 16 * math.pi * z0**2 * FILM_DG, z0


def film_point(op, lj, z0, d_min):
    """Trace the equilibrium curve of the tip on ``op`` (pseudo-arclength through its folds)
    and read pull-off, jumps and the zero-load contact radius off it.

    Returns a dict: forces in pi R dg, separations in z0 (``pull``, ``pull_disp``,
    ``jump_in``, ``jump_out``: NaN without that fold, ``curve_d``, ``curve_F``), ``a0`` (m,
    the contact edge h = z0 where the stable loading branch crosses zero force), ``wall``
    (s), ``points``, and the ``problem`` and ``curve`` themselves.
    """
    problem = ContactProblem(op, Sphere(TIP_R), {"lj": lj})
    scale = math.pi * TIP_R * FILM_DG
    t0 = time.perf_counter()
    curve = trace_curve(problem, 12 * z0, d_min, tol=1e-16, scale=z0, ds=0.2, ds_max=0.5)
    wall = time.perf_counter() - t0
    read = read_curve(curve, lambda pb, d, w: lj_force(pb, lj, d, w))
    cf = read.force
    # zero-load contact radius on the stable loading branch
    a0 = math.nan
    pts = curve.points
    for k in range(len(pts) - 1):
        if pts[k].stable and pts[k + 1].stable and cf[k] >= 0 > cf[k + 1]:
            s = cf[k] / (cf[k] - cf[k + 1])
            a0 = ((1 - s) * contact_edge(problem, pts[k].w, pts[k].d, z0)
                  + s * contact_edge(problem, pts[k + 1].w, pts[k + 1].d, z0))
    return {"pull": read.pull_off / scale, "pull_disp": read.pull_off_path / scale,
            "jump_in": math.nan if read.jump_in is None else read.jump_in / z0,
            "jump_out": math.nan if read.jump_out is None else read.jump_out / z0, "a0": a0,
            "curve_d": curve.d / z0, "curve_F": cf / scale, "wall": wall,
            "points": len(pts), "problem": problem, "curve": curve}
