"""Run a ``[meniscus]`` scene: sweeps of every liquid, radius and method; csv, json, figure, VTK."""
import csv
import math
from pathlib import Path
import time

import numpy as np

from .._version import __version__
from ..io.writers import write_json
from ..meniscus.solve import sweep

HEADER = ["method", "p_ratio", "film_m", "kelvin_radius_m", "force_N", "force_over_4piRgamma",
          "neck_radius_m", "liquid", "tip_radius_m"]
NOTE = ("Capillary force on the sphere, attractive positive, normalised by 4 pi R gamma with R "
        "the solid tip radius; the adsorbed film (thickness h from the isotherm) covers sphere "
        "and flat, the film-covered sphere has radius R + h and, in contact, D = -2h "
        "(paper 2 Fig 2b); zero contact angle on the films. 'no-film' is the exact meniscus on "
        "bare solids (h = 0).")


def run_meniscus(scene, out_dir=None, *, write=True, figures=True):
    t0 = time.perf_counter()
    out = Path(out_dir or scene.output_dir)
    results = {}
    errors = []
    if write:
        out.mkdir(parents=True, exist_ok=True)
        fcsv = open(out / "meniscus.csv", "w", newline="")
        w = csv.writer(fcsv)
        w.writerow(HEADER)
        fprof = open(out / "profiles.csv", "w", newline="")
        wp = csv.writer(fprof)
        wp.writerow(["liquid", "tip_radius_m", "method", "p_ratio", "r_m", "z_m"])
    timings = {}
    for lq in scene.liquids:
        iso = scene.isotherms[lq.name]
        for R in scene.radii:
            for meth in scene.methods:
                t1 = time.perf_counter()
                res = sweep(meth, R, lq, scene.temperature, iso, scene.p_ratios,
                            scene.separation, elements=scene.elements)
                timings[f"{lq.name}/{R:g}/{meth}"] = time.perf_counter() - t1
                results[lq.name, R, meth] = res
                for x, r in zip(scene.p_ratios, res):
                    if isinstance(r, Exception):
                        errors.append({"liquid": lq.name, "tip_radius_m": R, "method": meth,
                                       "p_ratio": x, "error": str(r)})
                        row = [meth, x, "", "", "nan", "nan", "nan", lq.name, R]
                    else:
                        row = [meth, x, r.film, r.kelvin_radius, r.force,
                               r.force_over_4piRgamma, r.neck_radius, lq.name, R]
                        if write:
                            for rr, zz in zip(r.r, r.z):
                                wp.writerow([lq.name, R, meth, x, repr(float(rr)),
                                             repr(float(zz))])
                    if write:
                        w.writerow([repr(v) if isinstance(v, float) else v for v in row])
                if write:
                    fcsv.flush()
                    if scene.vtk and meth == "fe":
                        _write_vtk(out, lq.name, R, scene.p_ratios, res)
    wall = time.perf_counter() - t0
    if write:
        fcsv.close()
        fprof.close()
        write_json(out / "summary.json", {
            "femadh_version": __version__, "scene_file": scene.path, "note": NOTE,
            "scene": scene.resolved, "domain_errors": errors, "timings_s": timings,
            "wall_time_s": wall})
        if figures:
            from ..io.plots import meniscus_forces

            meniscus_forces(scene, results, out / "meniscus_force.png")
    return results, errors, wall


def _write_vtk(out, liquid, R, p_ratios, res, n_theta=48):
    """Meniscus surface of revolution per p/psat (quads) and a .pvd keyed by p/psat."""
    import meshio

    from ..io.vtk import write_pvd

    vdir = out / "vtk"
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
        meshio.write(vdir / name, meshio.Mesh(pts, [("quad", quads)],
                                              point_data={"z": pts[:, 2]}))
        entries.append((x, f"vtk/{name}", 0))
    write_pvd(out / f"meniscus_{tag}.pvd", entries)
