"""A stiction map as a parameter study, and what parallel studies cost.

``python -m validation.stiction_map`` (``--only map``: the map alone, ~10 min) runs the 2-mm
slider of paper 1 with LJ forces, the
sigma-gap and a condensed ethanol meniscus (validation/scenes/paper1_slider_meniscus.toml) over
sigma = 0.3-2 nm x p/psat = 0.05-0.95 (10 x 10 points, each with its error estimate), exactly
as

    femadh study sweep validation/scenes/paper1_slider_meniscus.toml \\
        --vary effects.asperity_gap.sigma="0.3 nm..2 nm:10" \\
        --vary effects.capillary.relative_pressure="0.05..0.95:10" --out out/stiction-map

does, and then times a 24-point sub-study on one local process, two local processes, and a
two-worker Dask LocalCluster. Writes validation/results/stiction_map.md, stiction_map.png and
study_scaling.md. A few minutes on two cores; run it on a quiet machine: the times are the
numbers.
"""
import math
from pathlib import Path
import shutil
import sys
import tempfile
import time

import numpy as np

import femadh
from femadh.studies.sweep import run_study

HERE = Path(__file__).resolve().parent
RESULTS = HERE / "results"
SCENE = HERE / "scenes" / "paper1_slider_meniscus.toml"
MAP = {"effects.asperity_gap.sigma": "0.3 nm..2 nm:10",
       "effects.capillary.relative_pressure": "0.05..0.95:10",
       # from well above the largest sigma, so that every peak lies inside the sweep
       "sweep.start": "4 nm"}
SCALING = {"effects.asperity_gap.sigma": "0.6 nm..2 nm:6",
           "effects.capillary.relative_pressure": "0.2..0.8:4", "sweep.start": "4 nm"}


#: wall time one point of the map may take (its adaptive runs and estimate included): a
#: point that needs more ends "time limit" and is listed with the failures
POINT_LIMIT = "90 s"


#: the map asks for the max adhesion alone: a point whose pilot finds the retract's pull-off
#: fold takes the edge route for it alone (femadh/runner/edge_route.py; [solver] route =
#: "peak": the family's max adhesion and pull-off, no approach or states at the sweep's
#: separations), the others the adaptive sweep. Not the scene's default "auto": with the
#: sweep's outputs a routed point costs 8.1 and 16.0 CPU-s on the sigma = 0.3 nm column's two
#: points measured (36-41 s wall at load 4-9: the approach by the sweep 8.7-26 s, the
#: retract's states 3.9-26 s; validation/results/edge_route.md) against 1.2-1.5 CPU-s for the
#: max adhesion alone. "auto" (``--route auto``, validation/results/stiction_map_auto.md)
#: pilots where the adaptive grid would follow the edge (the sigma = 0.3 nm column) or its
#: first static member is trapped at the edge by the meniscus step
#: (femadh/runner/edge_route.py edge_trap_ratio: six low-humidity points)
ROUTE = "peak"
#: the routes ``--route`` may ask for: the map's own (ROUTE) or the scene's default ("auto":
#: the map as a user who sets nothing runs it; validation/results/stiction_map_auto.md)
ROUTES = ("peak", "auto")


def stiction_map(out, sigma=None, route=ROUTE):
    """The map at the scene's defaults: the adaptive grid to accuracy 1e-3, the points whose
    retract has a pull-off fold by the edge route (``route``, ROUTE by default; points femadh
    refuses, or that reach POINT_LIMIT, keep their reason); ``sigma`` (e.g. "0.3 nm"): only
    that column."""
    scene = femadh.load_scene(SCENE).replace({"solver.time_limit": POINT_LIMIT,
                                              "solver.route": route})
    t0 = time.perf_counter()
    vary = MAP if sigma is None else {**MAP, "effects.asperity_gap.sigma": [sigma]}
    points, records = run_study(scene, vary, out, workers=2,
                                progress=sys.stderr.isatty())     # quiet in pipes
    wall = time.perf_counter() - t0

    def rel_of(p):
        return float(p.scene.raw["effects"]["capillary"]["relative_pressure"])

    sig = sorted({p.scene.gap.sigma for p in points})
    rel = sorted({rel_of(p) for p in points})
    F = np.full((len(rel), len(sig)), math.nan)
    E = np.full_like(F, math.nan)
    fails = []
    gamma = points[0].scene.effects["capillary"].surface_tension
    for p in points:
        i, j = rel.index(rel_of(p)), sig.index(p.scene.gap.sigma)
        rec = records[p.id]
        if rec.get("status") == "converged":
            F[i, j] = rec["max_adhesion_N"]
            E[i, j] = rec.get("max_adhesion_N_error", math.nan)
        else:
            fails.append((p.scene.gap.sigma, rel_of(p), _reason(out, p, rec)))
    norm = 4 * math.pi * scene.sphere.radius * gamma
    return sig, rel, F, E, norm, wall, fails, len(points), points


def _reason(out, point, rec):
    """Why a point of the map did not converge: its run's own status and error (a point
    stopped by POINT_LIMIT reads "time limit" there; the study's record calls it unfinished)."""
    import json

    summ = Path(out) / "points" / point.id / "summary.json"
    if summ.exists():
        d = json.loads(summ.read_text())
        if d.get("status") not in (None, "converged", "running"):
            return f"{d['status']}: {d.get('error')}"
    return rec.get("error") or rec.get("status")


def figure(sig, rel, F, norm, png):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 4.2), layout="constrained")
    s_nm = np.asarray(sig) * 1e9
    m = a1.pcolormesh(s_nm, rel, F / norm, shading="nearest", cmap="magma")
    fig.colorbar(m, ax=a1, label=r"max adhesion / $4\pi R\gamma$")
    bad = ~np.isfinite(F)
    if bad.any():
        ii, jj = np.nonzero(bad)
        a1.plot(s_nm[jj], np.asarray(rel)[ii], "x", color="0.6", ms=7,
                label="refused or failed (see stiction_map.md)")
        a1.legend(fontsize=7, loc="upper right")
    a1.set_xlabel(r"asperity gap $\sigma$ (nm)")
    a1.set_ylabel(r"$p/p_\mathrm{sat}$")
    a1.set_title("2-mm slider, LJ + sigma-gap + ethanol meniscus")
    shown = [j for j in range(len(sig)) if np.isfinite(F[:, j]).any()]
    for j in shown[::3]:
        a2.plot(rel, F[:, j] / norm, "o-", ms=3, label=rf"$\sigma$ = {s_nm[j]:.2f} nm")
    a2.axhline(1.0, color="k", lw=0.8, ls="--", label=r"$4\pi R\gamma$")
    a2.set_xlabel(r"$p/p_\mathrm{sat}$")
    a2.set_ylabel(r"max adhesion / $4\pi R\gamma$")
    a2.legend(fontsize=8)
    fig.savefig(png, dpi=110)
    plt.close(fig)


def scaling():
    """(label, points, converged, wall) for the pool, femadh's own LocalCluster (start-up
    included) and a running cluster (``--scheduler tcp://...``: start-up excluded)."""
    from distributed import LocalCluster

    scene = femadh.load_scene(SCENE)
    rows = []
    running = LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                           dashboard_address=None)
    for label, kw in (("1 local process", {"workers": 1}),
                      ("2 local processes", {"workers": 2}),
                      ("Dask LocalCluster started by femadh (local:2)", {"scheduler": "local:2"}),
                      ("Dask cluster already running, 2 workers (tcp://)",
                       {"scheduler": running.scheduler_address})):
        tmp = Path(tempfile.mkdtemp(prefix="femadh-scaling-"))
        try:
            t0 = time.perf_counter()
            points, records = run_study(scene, SCALING, tmp / "study", **kw)
            wall = time.perf_counter() - t0
        finally:
            shutil.rmtree(tmp, ignore_errors=True)
        ok = sum(r.get("status") == "converged" for r in records.values())
        rows.append((label, len(points), ok, wall))
    running.close()
    return rows


def main(argv=None):
    import argparse

    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--only", choices=("map", "scaling", "edge"),
                    help="run one of the two parts, or (edge) only the low-humidity points "
                    "whose meniscus edge sits just above sigma (printed, no file written)")
    ap.add_argument("--sigma", help="only the map's column at this asperity gap (e.g. "
                    "'0.3 nm', the map's first): printed, no file written")
    ap.add_argument("--route", choices=ROUTES, default=ROUTE,
                    help=f"[solver] route of the map's points (default {ROUTE!r}, the max "
                    "adhesion alone; 'auto': the scene's default, written to "
                    "stiction_map_auto.md/.png)")
    args = ap.parse_args(argv)
    if args.only == "edge":
        edge_points()
        return
    if args.sigma:
        column(args.sigma, args.route)
        return
    RESULTS.mkdir(exist_ok=True)
    if args.only != "scaling":
        the_map(args.route)
    if args.only != "map":
        scaling_table()


def the_map(route=ROUTE):
    """The map at ``route`` into validation/results/stiction_map.md and .png (ROUTE), or
    stiction_map_<route>.md and .png (another route)."""
    out = Path("out/stiction-map")
    shutil.rmtree(out, ignore_errors=True)
    import os

    stem = "stiction_map" if route == ROUTE else f"stiction_map_{route}"
    load = os.getloadavg()
    sig, rel, F, E, norm, wall, fails, n, points = stiction_map(out, route=route)
    load_end = os.getloadavg()
    figure(sig, rel, F, norm, RESULTS / f"{stem}.png")
    routed = _routed(out)
    lines = ["# Stiction map: the 2-mm slider with LJ, the sigma-gap and an ethanol meniscus",
             "", "(`python -m validation.stiction_map`; scene "
             "`validation/scenes/paper1_slider_meniscus.toml`, bare meniscus, at its "
             "defaults: the adaptive banded grid to accuracy 1e-3, analysis radius planned "
             f"from delta = 50 nm, [solver] route = '{route}' ("
             + ("the map asks for the max adhesion alone: a point whose pilot finds the "
                "retract's pull-off fold is traced in its edge radius, "
                "femadh/runner/edge_route.py; the others by the adaptive sweep"
                if route == "peak" else
                "the scene's default: the edge route with the sweep's outputs where the "
                "runner sends a point to it, femadh/runner/edge_route.py route_for; the "
                "others by the adaptive sweep")
             + f"); at most {POINT_LIMIT} per point. Machine load (1-min "
             f"average) {load[0]:.1f} at the start, {load_end[0]:.1f} at the end, 2 cores.)",
             "",
             f"{n} points on 2 local processes in {wall:.1f} s "
             f"({wall / n:.2f} s per point, each with its error estimate); {len(fails)} "
             "refused or failed (below, with femadh's reasons); largest estimated relative "
             f"error of the max adhesion {np.nanmax(E / F):.1e} (median "
             f"{np.nanmedian(E / F):.1e}). By the edge route: {len(routed)} points "
             f"({sum(x[2] == 'converged' for x in routed)} converged; largest estimated "
             f"relative error {max([x[3] for x in routed] or [math.nan]):.1e}, wall "
             f"{min([x[4] for x in routed] or [math.nan]):.1f}-"
             f"{max([x[4] for x in routed] or [math.nan]):.1f} s per point).", "",
             f"Max adhesion / 4 pi R gamma (4 pi R gamma = {norm * 1e3:.4g} mN):", "",
             "| p/psat \\ sigma (nm) | " + " | ".join(f"{s * 1e9:.2f}" for s in sig) + " |",
             "|---|" + "---|" * len(sig)]
    for i, r in enumerate(rel):
        lines.append(f"| {r:.2f} | " + " | ".join(f"{x:.3f}" for x in F[i] / norm) + " |")
    lines += ["", "Refused or failed points (sigma, p/psat: femadh's message):", ""]
    for sg, r, err in fails:
        lines.append(f"- {sg * 1e9:.3g} nm, {r:.2f}: {err}")
    slow = _slowest(out, points)
    lines += ["", f"The {len(slow)} slowest points (wall s of the point's run, its route):",
              ""]
    lines += [f"- {sg * 1e9:.3g} nm, {r:.2f}: {w:.1f} s, {how}" for sg, r, w, how in slow]
    lines += ["", f"![]({stem}.png)", ""]
    (RESULTS / f"{stem}.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


def _routed(out):
    """(sigma m, Kelvin radius m, status, estimated relative error, wall s) of every point of the
    study folder ``out`` that took the edge route (its summary's grid.route)."""
    import json

    rows = []
    for summ in sorted(Path(out).glob("points/*/summary.json")):
        d = json.loads(summ.read_text())
        if (d.get("grid") or {}).get("route") != "edge-branch":
            continue
        sc = d["scene"]
        rows.append((sc["asperity_gap"]["sigma_m"], sc["effects"]["capillary"]["kelvin_radius"],
                      d["status"], d["accuracy"].get("estimated_rel_error", math.nan),
                      d.get("wall_time_s", math.nan)))
    return rows


def _slowest(out, points, n=8):
    """(sigma m, p/psat, wall s, how) of the ``n`` slowest of the study's ``points`` in its
    folder ``out`` (their summaries' wall time, the adaptive loop's where it ran; how: the
    status and "edge route" or the sweep's nodes, trial by trial)."""
    import json

    rows = []
    for p in points:
        summ = Path(out) / "points" / p.id / "summary.json"
        if not summ.exists():
            continue
        d = json.loads(summ.read_text())
        acc = d.get("accuracy") or {}
        how = ("edge route" if (d.get("grid") or {}).get("route") == "edge-branch" else
               "sweep, " + " -> ".join(str(s["nodes"]) for s in acc.get("steps", []))
               + " nodes")
        # (an adaptive sweep's own wall_time_s is its last trial's: the loop's is the point's)
        rows.append((p.scene.gap.sigma,
                     float(p.scene.raw["effects"]["capillary"]["relative_pressure"]),
                     acc.get("wall_time_s", d.get("wall_time_s", math.nan)),
                     f"{d.get('status')}, {how}"))
    rows.sort(key=lambda x: -x[2])
    return rows[:n]


def column(sigma, route=ROUTE):
    """One sigma column of the map as the map runs it (2 processes, POINT_LIMIT per point):
    per point its status, max adhesion / 4 pi R gamma, estimated relative error and reason;
    the wall time and the machine's load. Printed only."""
    import os

    out = Path("out/stiction-map-column")
    shutil.rmtree(out, ignore_errors=True)
    load = os.getloadavg()[0]
    sig, rel, F, E, norm, wall, fails, n, _ = stiction_map(out, sigma, route)
    print(f"sigma = {sigma}: {n} points in {wall:.1f} s on 2 processes (load "
          f"{load:.1f} -> {os.getloadavg()[0]:.1f}); {n - len(fails)} converged")
    for i, r in enumerate(rel):
        if not np.isfinite(F[i, 0]):
            continue            # listed with the failures below
        print(f"  p/psat {r:.2f}: max adhesion / 4 pi R gamma {F[i, 0] / norm:.5g}, "
              f"estimated relative error {E[i, 0] / F[i, 0]:.2g}")
    for sg, r, err in fails:
        print(f"  failed {sg * 1e9:.3g} nm, {r:.2f}: {err}")


#: the map's points whose meniscus edge lies within ~0.07 nm of sigma (a cohesive zone of
#: 30-60 nm at the contact edge; ended at POINT_LIMIT before the planner resolved it) and
#: their neighbour at 0.26 nm: (sigma, p/psat)
EDGE_POINTS = (("0.489 nm", 0.15), ("0.489 nm", 0.25), ("0.678 nm", 0.25))


def edge_points():
    """Each EDGE_POINTS point of the map on its own, as the map runs it (POINT_LIMIT): status,
    wall and CPU time, the adaptive trials (nodes, estimated relative error), the max adhesion
    and its estimated error. One process; state the machine's load with the numbers."""
    import os

    base = femadh.load_scene(SCENE)
    print(f"load {os.getloadavg()[0]:.1f}")
    for sigma, rel in EDGE_POINTS:
        scene = base.replace({"effects.asperity_gap.sigma": sigma,
                              "effects.capillary.relative_pressure": rel,
                              "sweep.start": MAP["sweep.start"],
                              "solver.time_limit": POINT_LIMIT})
        t0, c0 = time.perf_counter(), time.process_time()
        res = femadh.run(scene, None, figures=False, progress=False)
        wall, cpu = time.perf_counter() - t0, time.process_time() - c0
        trials = ", ".join(f"{s['nodes']} ({s['grid_rel_error'] + s['tail_rel_error']:.2g})"
                           for s in (res.accuracy or {}).get("steps", []))
        F = res.headline.get("max_adhesion_N", math.nan)
        E = res.headline.get("max_adhesion_N_error", math.nan)
        print(f"sigma {sigma}, p/psat {rel}: {res.status} in {wall:.1f} s ({cpu:.1f} s CPU); "
              f"trials {trials}; max adhesion {F * 1e6:.6g} uN, estimated {E / F:.2g}"
              + (f"; {res.error}" if res.error else ""), flush=True)
    print(f"load {os.getloadavg()[0]:.1f}")


def scaling_table():
    rows = scaling()
    base = rows[0][3]
    sl = ["# What a parallel study costs (validation/stiction_map.py)", "",
          f"24 points of the stiction map ({SCALING}), each a full sweep with its error "
          "estimate; wall time from the study's start to its table and figure, this machine "
          "(2 cores).", "", "| executor | points | converged | wall (s) | speed-up | "
          "s per point |", "|---|---|---|---|---|---|"]
    for label, npts, ok, wall in rows:
        sl.append(f"| {label} | {npts} | {ok} | {wall:.1f} | {base / wall:.2f} | "
                  f"{wall / npts:.3f} |")
    over = [(rows[i][3] - rows[1][3]) / rows[i][1] for i in (2, 3)]
    sl += ["", f"Dask over the local pool: {over[0] * 1e3:+.0f} ms per point with the "
           f"cluster's start-up, {over[1] * 1e3:+.0f} ms per point on a running cluster."]
    (RESULTS / "study_scaling.md").write_text("\n".join(sl) + "\n")
    print("\n".join(sl))


if __name__ == "__main__":
    main()
