import os
from pathlib import Path
import sys

# The suite's many processes (xdist workers, the runs and studies the tests start) each
# import femadh: where the environment sets PYTHONDONTWRITEBYTECODE (this CI image does) a
# fresh checkout has no bytecode and every process compiled the package again (~25 CPU-s a
# suite, measured: a fresh clone's suite 218-241 user-s against 192 where the bytecode
# existed). The suite's own processes write it once; the rest read it. Not under the
# seeded-defect harness (tests/seeded_defects.py): it mutates and restores sources within a
# second, and a .pyc of a mutated module of the same size would outlive its restore.
if not os.environ.get("FEMADH_SEEDED_DEFECT"):
    sys.dont_write_bytecode = False

# Small dense solves: threaded BLAS only adds overhead on the CI machine's 2 cores.
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
# the tests run on the committed FE mesh ladder (fixed meshes whatever gmsh is installed)
os.environ.setdefault("FEMADH_MESH_PATH", str(Path(__file__).resolve().parents[1] / "meshes"))
# condensed FE operators cached per test run, not in the user's ~/.cache; the process that
# made the folder removes it at exit (its workers and children inherit the variable and use
# it; it was left behind before: ~8800 folders in /tmp after a day of runs)
if not os.environ.get("FEMADH_OPERATOR_CACHE"):
    import atexit  # noqa: E402
    import shutil  # noqa: E402
    import tempfile  # noqa: E402

    os.environ["FEMADH_OPERATOR_CACHE"] = tempfile.mkdtemp(prefix="femadh-operators-")
    atexit.register(shutil.rmtree, os.environ["FEMADH_OPERATOR_CACHE"], ignore_errors=True)
# The signal tests send SIGINT to the runs they start, which must take it. A suite started
# with SIGINT ignored (a non-interactive shell's background job, nohup'ed CI) would pass that
# SIG_IGN to every child, and femadh keeps an ignored SIGINT ignored (as a user's background
# job wants): the suite's own processes take SIGINT as a terminal would (a Python handler is
# reset to the default at exec, so the children start with Python's KeyboardInterrupt).
import signal  # noqa: E402

if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
    signal.signal(signal.SIGINT, signal.default_int_handler)

import numpy as np
import pytest

from femadh.materials import IsotropicMaterial, composite_modulus

E_STAR = composite_modulus(IsotropicMaterial(163e9, 0.3), IsotropicMaterial(83e9, 0.21))
HAMAKER, Z0 = 1e-19, 0.165e-9


#: the Fig 4 slider (R = 2 mm, sigma = 0.5 nm) on the uniform disk of delta = 10 nm, and
#: separations through its jump-in (~1.11 nm) and pull-off (~1.18 nm) in 0.2 nm steps
FIG4_RADIUS, FIG4_TOL = 2e-3, 1e-19
FIG4_D_VALUES = np.round(np.arange(1.6, 0.59, -0.2), 10) * 1e-9


def fig4_problem(n):
    """The Fig 4 contact problem (LJ with the sigma = 0.5 nm gap) on n uniform nodes."""
    import math

    from femadh.contact import AsperityGap, ContactProblem
    from femadh.elastic import GreenOperator, RadialGrid
    from femadh.indenter import Sphere
    from femadh.laws import LennardJones

    a = math.sqrt(2 * FIG4_RADIUS * 10e-9)
    return ContactProblem(GreenOperator(RadialGrid.uniform(a, n), E_STAR), Sphere(FIG4_RADIUS),
                          {"lj": LennardJones(HAMAKER, Z0)}, AsperityGap(0.5e-9))


def fig4_sweeps(p):
    """(approach, retract) of ``p`` stepped through FIG4_D_VALUES."""
    from femadh.contact import trace

    ap = trace(p, FIG4_D_VALUES, branch="approach", tol=FIG4_TOL)
    re = trace(p, FIG4_D_VALUES[::-1], branch="retract", tol=FIG4_TOL, start=ap.states[-1])
    return ap, re


@pytest.fixture(scope="session")
def fig4_jump150():
    """(problem, jump): the Fig 4 disk (sigma = 0.5 nm) on 150 uniform nodes and its
    approach's jump-in, whose landing follows a fold (test_fold, test_fig4solve_landing)."""
    from femadh.contact import trace

    p = fig4_problem(150)
    return p, trace(p, FIG4_D_VALUES, branch="approach", tol=FIG4_TOL).jumps[0]


@pytest.fixture
def cholesky_count(monkeypatch):
    """A one-element list counting the landing's Cholesky factorisations
    (``landing.cho_factor``, femadh.contact.linalg's direct LAPACK call, the name the
    descent calls) from here on; reset it by assigning ``count[0] = 0``."""
    from femadh.contact import landing

    count = [0]
    real = landing.cho_factor

    def counted(*a, **k):
        count[0] += 1
        return real(*a, **k)
    monkeypatch.setattr(landing, "cho_factor", counted)
    return count


def hertz_annulus_averages(edges, a, radius, e_star):
    """Annulus averages (Pa) of the Hertz pressure (paper 1 eq 9, p_m = 2 E* a/(pi R)) by
    adaptive quadrature of the judge's pointwise pressure (a test-side load, independent of
    the closure's closed-form annulus integrals)."""
    from scipy import integrate

    from femadh.reference import hertz_pressure

    out = np.zeros(len(edges) - 1)
    for k, (lo, hi) in enumerate(zip(edges[:-1], edges[1:])):
        if lo < a:
            top = min(hi, a)
            f = integrate.quad(lambda r: hertz_pressure(r, a, radius, e_star) * 2 * np.pi * r,
                               lo, top, epsabs=0.0, epsrel=1e-13, limit=200)[0]
            out[k] = f / (np.pi * (hi * hi - lo * lo))
    return out


def observed_order(h, err):
    """Slope of log(err) vs log(h): the observed convergence order."""
    return np.polyfit(np.log(h), np.log(err), 1)[0]


@pytest.fixture
def e_star():
    return E_STAR


def check_curve_against_fields(out_dir, rel=1e-12):
    """curve.csv's forces equal the pressures of fields.csv integrated over the annuli (edges
    half-way between the nodes, the last at the analysis radius of summary.json), state by
    state; and F_ex is their signed sum (paper 1 eqs 11-13 with area weights). The csv holds
    repr() floats, so only the summation order separates them: measured <= 3e-16 relative.
    Returns the number of states checked."""
    import csv
    import json
    from pathlib import Path

    out = Path(out_dir)
    a = json.loads((out / "summary.json").read_text())["scene"]["solver"]["analysis_radius_m"]
    curve = list(csv.DictReader(open(out / "curve.csv")))
    fields = list(csv.DictReader(open(out / "fields.csv")))
    groups, order = {}, []
    for r in fields:
        key = (r["state"], r["branch"], r["d_m"])
        if key not in groups:
            groups[key] = []
            order.append(key)
        groups[key].append(r)
    assert len(order) == len(curve)       # a state is in both files or in neither
    signs = {"F_LJ_N": ("P_LJ_Pa", 1.0), "F_el_N": ("P_el_Pa", 1.0),
             "F_cap_N": ("P_cap_Pa", 1.0), "F_LJa_N": ("P_LJa_Pa", 1.0),
             "F_ela_N": ("P_ela_Pa", -1.0)}
    for row, key in zip(curve, order):
        assert (row["state"], row["branch"], row["d_m"]) == key
        rows = groups[key]
        r = np.array([float(x["r_m"]) for x in rows])
        edges = np.concatenate([[0.0], 0.5 * (r[1:] + r[:-1]), [a]])
        areas = np.pi * np.diff(edges**2)
        total = 0.0
        scale = 0.0
        for col, (fcol, sign) in signs.items():
            if col not in row:
                continue
            f = sign * float(areas @ np.array([float(x[fcol]) for x in rows]))
            scale = max(scale, abs(f))
            assert float(row[col]) == pytest.approx(f, rel=rel, abs=rel * scale)
            total += -f if col in ("F_el_N", "F_ela_N") else f
        assert float(row["F_ex_N"]) == pytest.approx(total, rel=rel, abs=rel * scale)
    return len(curve)


def fig3_uniform_text():
    """The Fig 3 scene file's text with explicit uniform nodes (N = 200, its former default):
    tests of scene text, faults and resume that need a fixed, fast discretisation."""
    text = (Path(__file__).resolve().parents[1] / "validation" / "scenes"
            / "paper1_fig3.toml").read_text()
    return text.replace("[solver]\n", "[solver]\nnodes = 200\n", 1)


def tiny_fe_text():
    """The Fig 3 FE scene on 40 nodes, swept from 2 to -1 nm in 1-nm steps: an FE run of a
    few states for the render and VTK tests (fields, not accuracy)."""
    text = (Path(__file__).resolve().parents[1] / "validation" / "scenes"
            / "paper1_fig3_fe.toml").read_text()
    text = text.replace("nodes = 200", "nodes = 40").replace('stop = "-5 nm"', 'stop = "-1 nm"')
    return text.replace('step = "0.2 nm"', 'step = "1 nm"')


@pytest.fixture(scope="session")
def tiny_fe_run(tmp_path_factory):
    """A copier of one ``femadh run`` of tiny_fe_text (--no-figures --no-estimate): the render
    and VTK tests each draw from a copy (render writes into the folder), the FE run done once
    a test process. Call it with a folder; returns the copy's path."""
    import shutil

    from femadh.cli import main

    tmp = tmp_path_factory.mktemp("tiny_fe")
    (tmp / "fe.toml").write_text(tiny_fe_text())
    assert main(["run", str(tmp / "fe.toml"), "--out", str(tmp / "run"), "--quiet",
                 "--no-figures", "--no-estimate"]) == 0

    def copy(folder):
        out = Path(folder) / "run"
        shutil.copytree(tmp / "run", out)
        return out
    return copy


def adaptive_scene(path="validation/scenes/paper1_fig3.toml", **solver):
    """A bundled scene (default Fig 3) without its ``[solver] nodes``: the adaptive grid,
    with ``solver`` entries (e.g. ``accuracy=1e-2``) set."""
    import copy

    import femadh
    from femadh.scene import scene_from_dict

    sc = femadh.load_scene(path)
    raw = copy.deepcopy(sc.raw)
    raw["solver"].pop("nodes", None)
    raw["solver"].update(solver)
    return scene_from_dict(raw, sc.path, bare_numbers=False)


def fig4_banded(start, stop, step="0.2 nm", directions=None):
    """The Fig 4 slider (sigma = 0.5 nm) on an explicit banded grid (30 nm in a 5.9-um band,
    a = 12.6 um), swept from ``start`` to ``stop`` (strings with units) in ``step`` and back
    (``directions``: the sweep's, where given)."""
    import copy

    import femadh
    from femadh.scene import scene_from_dict

    base = femadh.load_scene("validation/scenes/paper1_fig4.toml")
    raw = copy.deepcopy(base.raw)
    raw["solver"].pop("accuracy", None)
    raw["solver"]["analysis_radius"] = "12.6e-6 m"
    raw["solver"]["grid"] = {"spacing": "30e-9 m", "band": "5.9e-6 m",
                             "grading": "0.295e-6 m"}
    raw["sweep"].update(start=start, stop=stop, step=step)
    if directions is not None:
        raw["sweep"]["directions"] = directions
    return scene_from_dict(raw, base.path, bare_numbers=False)


def fields_by_state(out):
    """{state: (r, h) arrays in m} read from a run folder's fields.csv (the grid each state
    was written on)."""
    import csv

    rows = {}
    with open(Path(out) / "fields.csv", newline="") as f:
        for row in csv.DictReader(f):
            rows.setdefault(row["state"], []).append((float(row["r_m"]), float(row["h_m"])))
    return {k: tuple(np.array(v).T) for k, v in rows.items()}


@pytest.fixture(scope="session")
def regime_run(tmp_path_factory):
    """(exit code, stdout, folder) of one ``femadh regime --mu 0.5 1.0 --points 2``: the
    printed table (test_output) and the files (test_roughness) of the same command, run once
    a test process (~0.5 CPU-s, most of it its two figures)."""
    import contextlib
    import io

    from femadh.cli import main

    out = tmp_path_factory.mktemp("regime") / "reg"
    text = io.StringIO()
    with contextlib.redirect_stdout(text):
        code = main(["regime", "--mu", "0.5", "1.0", "--points", "2", "--out", str(out)])
    return code, text.getvalue(), out
