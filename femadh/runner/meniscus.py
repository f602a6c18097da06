"""Run a ``[meniscus]`` scene (paper 2): a p/psat sweep for every liquid, tip radius and method;
``meniscus.csv``, ``profiles.csv`` (meridians), ``summary.json``, the force figure and VTK
surfaces of revolution. Same guarantees as a contact run: the folder is claimed first, rows
are written in whole chunks, SIGINT/SIGTERM stop after the current point (the run's life:
:mod:`.lifecycle`)."""
import math
from pathlib import Path
import sys
import time

import numpy as np

from .._threads import blas_threads
from ..errors import Interrupted
from ..meniscus.solve import sweep_points
from .. import interrupt
from .lifecycle import lifecycle
from .result import MENISCUS_NOTE as NOTE  # noqa: F401  (what the columns mean)
from .result import MeniscusRunResult, meniscus_headline

HEADER = ["method", "p_ratio", "film_m", "kelvin_radius_m", "force_N", "force_over_4piRgamma",
          "neck_radius_m", "force_error_N", "liquid", "tip_radius_m"]
COLUMNS = ("p_ratio", "film_m", "kelvin_radius_m", "force_N", "force_over_4piRgamma",
           "neck_radius_m", "force_error_N")
#: observed order of the FE meridian's force in the element count (cG(2) nodal
#: superconvergence: 3.99-4.00 measured, tests/test_meniscus.py)
FE_ORDER = 4.0


def run_meniscus(scene, out_dir=None, *, figures=True, progress=None, overwrite=False):
    """Solve a meniscus scene; writes nothing unless ``out_dir`` is given. Returns a
    MeniscusRunResult (status "failed" when no point of the scene has a meniscus)."""
    from ..scene import scene_id

    if progress is None:
        progress = sys.stderr.isatty()
    with blas_threads():
        if out_dir is None:
            return _run(scene, None, progress)
        from ..io.run_folder import RunFolder

        with RunFolder(out_dir, scene_id(scene), scene.name,
                       "overwrite" if overwrite else "new") as folder:
            res = _run(scene, folder, progress)
            # a stopped run draws no figure (as a contact run; it would report the stop
            # again as one "while drawing the figure")
            if figures and res.status in ("converged", "failed") and any(
                    np.any(np.isfinite(c["force_N"])) for c in res.curves.values()):
                from ..io.plots import meniscus_forces

                t0 = time.perf_counter()
                try:
                    with interrupt.interruptible(), interrupt.immediate():
                        meniscus_forces(res, folder.path / "meniscus_force.png")
                    res.timings["figures_s"] = time.perf_counter() - t0
                except Interrupted as exc:
                    res.stop(exc, " while drawing the figure")
                folder.write_summary(res.summary())
            return res


def _run(scene, folder, progress):
    from ..io.atomic import RowLog

    t0 = time.perf_counter()
    res = MeniscusRunResult(scene.name, scene, out_dir=None if folder is None
                            else str(folder.path))
    combos = [(lq, R, m) for lq in scene.liquids for R in scene.radii for m in scene.methods]

    def write_summary(status=None):
        if folder is not None:
            folder.write_summary(res.summary(status))

    def arrays():
        for cur in res.curves.values():
            for k in cur:
                cur[k] = np.array(cur[k], float)
        res.headline = meniscus_headline(res.curves)
    with lifecycle(res, write_summary, t0=t0) as life:
        if progress:
            from ..io.progress import bar as make_bar

            bar = make_bar(len(combos) * len(scene.p_ratios), scene.name)
            life.cleanup(bar.close)
        logs = None
        if folder is not None:
            logs = (RowLog(folder.path / "meniscus.csv", HEADER),
                    RowLog(folder.path / "profiles.csv",
                           ["liquid", "tip_radius_m", "method", "p_ratio", "r_m", "z_m"]))
            for log in logs:
                life.cleanup(log.close)
        life.cleanup(arrays)
        for lq, R, meth in combos:
            iso = scene.isotherms[lq.name]
            cur = {k: [] for k in COLUMNS}
            res.curves[lq.name, R, meth] = cur
            t1 = time.perf_counter()
            points = []
            for x, r in sweep_points(meth, R, lq, scene.temperature, iso, scene.p_ratios,
                                     scene.separation, elements=scene.elements):
                points.append(r)
                err = _error_estimate(scene, meth, R, lq, r)
                _record(res, cur, lq, R, meth, x, r, logs, err)
                if progress:
                    bar.update(1)
                interrupt.check()
            res.timings[f"{lq.name}/{R:g}/{meth}_s"] = time.perf_counter() - t1
            if folder is not None and scene.vtk and meth == "fe":
                _write_vtk(folder.path, lq.name, R, scene.p_ratios, points)
        if not any(np.any(np.isfinite(c["force_N"])) for c in res.curves.values()):
            res.fail(f"no point of the scene has a meniscus ({len(res.errors)} points failed; "
                     f"first: {res.errors[0]['error'] if res.errors else '-'})")
    return res


def _error_estimate(scene, meth, R, lq, r):
    """Estimated error (N) of an FE meniscus force: the same meniscus on half the elements,
    |F_n - F_n/2| / (2^4 - 1) (order 4). Shooting reports 0 (its ODE tolerance 1e-12: exact
    next to the FE's error; :func:`report_lines` says it is not an estimate), the circular
    approximation nan (its error is the approximation's, see validation), and so does an FE
    meridian of fewer than 4 elements (half of them is too few to solve: no estimate)."""
    if isinstance(r, Exception):
        return math.nan
    if meth == "circular":
        return math.nan
    if meth == "shooting":
        return 0.0
    if scene.elements < 4:
        return math.nan
    from ..errors import ConvergenceError, DomainError
    from ..meniscus.solve import meniscus

    try:
        half = meniscus(meth, R, lq.surface_tension, r.kelvin_radius, r.film, scene.separation,
                        elements=scene.elements // 2)
    except (ConvergenceError, DomainError):
        return math.nan
    return abs(r.force - half.force) / (2.0**FE_ORDER - 1.0)


def _record(res, cur, lq, R, meth, x, r, logs, err=math.nan):
    """One p/psat point (a MeniscusResult or the DomainError/ConvergenceError of a point
    without a meniscus) into the result and the csv files."""
    if isinstance(r, Exception):
        res.errors.append({"liquid": lq.name, "tip_radius_m": R, "method": meth, "p_ratio": x,
                           "error": str(r)})
        vals = [x] + [math.nan] * 6
        row = [meth, repr(x), "", "", "nan", "nan", "nan", "nan", lq.name, repr(R)]
    else:
        vals = [x, r.film, r.kelvin_radius, r.force, r.force_over_4piRgamma, r.neck_radius,
                err]
        row = [meth] + [repr(float(v)) for v in vals] + [lq.name, repr(R)]
    for k, v in zip(COLUMNS, vals):
        cur[k].append(v)
    if logs:
        if not isinstance(r, Exception):
            logs[1].append([[lq.name, repr(R), meth, repr(x), repr(float(rr)), repr(float(zz))]
                            for rr, zz in zip(r.r, r.z)])
        logs[0].append([row])


def _write_vtk(out, liquid, R, p_ratios, res, n_theta=48):
    """Meniscus surface of revolution per p/psat (quads) and a .pvd keyed by p/psat."""
    import meshio

    from ..io.atomic import save_atomic
    from ..io.vtk import write_pvd

    vdir = Path(out) / "vtk"
    vdir.mkdir(exist_ok=True)
    tag = f"{liquid}_R{R * 1e9:g}nm"
    entries = []
    for k, (x, r) in enumerate(zip(p_ratios, res)):
        if isinstance(r, Exception):
            continue
        th = np.linspace(0, 2 * math.pi, n_theta, endpoint=False)
        rr, zz = np.asarray(r.r), np.asarray(r.z)
        pts = np.column_stack([(rr[:, None] * np.cos(th)).ravel(),
                               (rr[:, None] * np.sin(th)).ravel(),
                               np.repeat(zz, n_theta)])
        i = np.arange(rr.size - 1)[:, None] * n_theta
        j = np.arange(n_theta)[None, :]
        jn = (j + 1) % n_theta
        quads = np.stack([i + j, i + jn, i + n_theta + jn, i + n_theta + j], -1).reshape(-1, 4)
        name = f"meniscus_{tag}_{k:03d}.vtu"
        mesh = meshio.Mesh(pts, [("quad", quads)], point_data={"z": pts[:, 2]})
        save_atomic(vdir / name, lambda p, mesh=mesh: meshio.write(p, mesh, file_format="vtu"))
        entries.append((x, f"vtk/{name}", 0))
    write_pvd(Path(out) / f"meniscus_{tag}.pvd", entries)


#: what each method's printed error is (the terminal says it beside every number)
ERROR_BASIS = {
    "fe": f"± the meridian on half the elements, order {FE_ORDER:g}",
    "no-film": f"± the meridian on half the elements, order {FE_ORDER:g}",
    "shooting": "no error estimate: the ODE is solved to 1e-12 relative",
    "circular": "no error estimate: the toroidal approximation",
}


def report_lines(res):
    """The lines a meniscus run prints: what F and F/4πRγ are, then per liquid, tip radius
    and method the largest force over the computed p/psat, each number with its estimated
    error (:func:`_error_estimate`) or a plain "no error estimate" with the reason; the
    circular approximation also with its difference from the exact meniscus (fe, else
    shooting) at the same p/psat when the scene computes one."""
    from ..io.plots import force_unit, value_error_text

    scene = res.scene
    where = ("in contact (D = -2h with the films)" if scene.separation is None else
             f"at solid-solid separation {scene.separation * 1e9:.4g} nm")
    n = len(scene.p_ratios)
    out = [f"F: capillary force on the tip {where}, attractive positive; F/4πRγ: F over "
           "4πRγ (R the solid tip radius, γ the liquid's surface tension); each line the "
           f"largest of its {n} computed p/psat (not located between them)"]
    gamma = {lq.name: lq.surface_tension for lq in scene.liquids}
    for (liq, R, meth), c in res.curves.items():
        f = np.asarray(c["force_N"], float)
        ok = np.isfinite(f)
        if not ok.any():
            continue
        k = int(np.nanargmax(f))
        unit4 = 4 * math.pi * R * gamma[liq]
        s, unit = force_unit([f[k]])
        err = float(np.asarray(c["force_error_N"], float)[k])
        estimated = meth in ("fe", "no-film") and np.isfinite(err)
        # each value to the decimal place of its error (value_error_text)
        F = f"F = {value_error_text(f[k] * s, err * s if estimated else None)} {unit}"
        x = "F/4πRγ = " + value_error_text(c['force_over_4piRgamma'][k],
                                            err / unit4 if estimated else None)
        if estimated:
            basis = ERROR_BASIS[meth]
        elif meth in ("fe", "no-film"):
            basis = ("no error estimate: the half-element meridian failed" if
                     scene.elements >= 4 else "no error estimate: fewer than 4 elements")
        else:
            basis = ERROR_BASIS[meth]
        if meth == "circular":
            basis += _against_exact(res, liq, R, k, unit4)
        line = (f"{liq:10s} R = {R * 1e9:7g} nm {meth:9s}: {x}, {F} (4πRγ = "
                f"{unit4 * s:.4g} {unit}) at p/psat = {c['p_ratio'][k]:.3g}; {basis}")
        if (~ok).any():
            line += f" ({int((~ok).sum())} p/psat without meniscus)"
        out.append(line)
    return out


def _against_exact(res, liq, R, k, unit4):
    """The circular approximation's difference from the exact meniscus at its p/psat point k
    (F/4πRγ), when the run computed one: a measured model error, not an estimate."""
    for exact in ("fe", "shooting"):
        c = res.curves.get((liq, R, exact))
        a = res.curves.get((liq, R, "circular"))
        if c is not None and np.isfinite(c["force_N"][k]):
            dx = (a["force_N"][k] - c["force_N"][k]) / unit4
            return f", {dx:+.2g} from {exact} here"
    return ""
