"""A fine band that follows the contact edge during a stepping sweep, against the static band,
and why the low-humidity corner of the stiction map is lattice-trapped at any affordable
spacing.

``python -m validation.follow_band`` writes validation/results/follow_band.md:

1. The Fig 4 scene (2-mm slider, sigma = 0.5 nm) on the static band [0, 5.9 um] and on a
   follow band ([solver.grid] follow = 1 um, grading 1 um) at the same band spacing: nodes,
   grid exchanges, the largest adhesion, wall time.
2. The sigma = 0.3 nm, p/psat = 0.05 corner: the meniscus step's softening P0 / (4 w) (its
   smoothing width w is 0.04 |r_K|) against LJ's at sigma and a band node's own stiffness
   K_kk, and the band spacing at which a node at the meniscus edge would stop snapping on
   its own.
"""
from pathlib import Path
import math
import os
import time
import warnings

import numpy as np

import femadh
from femadh.discretisation import GridFamily
from femadh.elastic import GreenOperator
from femadh.runner.run import run
from femadh.runner.estimates import variant
from femadh.scene import build_problem

HERE = Path(__file__).resolve().parent
FIG4 = HERE / "scenes" / "paper1_fig4.toml"
SLIDER = HERE / "scenes" / "paper1_slider_meniscus.toml"
BAND, RADIUS, HALF = 5.9e-6, 2.53e-5, 1e-6


def fig4_rows(spacings=(39e-9, 20e-9)):
    sc = femadh.load_scene(FIG4)
    rows = []
    for h in spacings:
        for follow in (None, HALF):
            grid = {"spacing": h, "band": BAND, "grading": HALF}
            if follow:
                grid["follow"] = follow
            t0 = time.perf_counter()
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                r = run(variant(sc, grid=grid, radius=RADIUS), None, figures=False,
                        progress=False, estimate="peak")
            rows.append((h, follow, r.grid.get("nodes"), r.grid.get("nodes_last"),
                         r.grid.get("regrids", 0), r.grid.get("widened", 0), r.status,
                         (r.headline or {}).get("max_adhesion_N", math.nan),
                         time.perf_counter() - t0))
    return rows


def meniscus_corner(sigma="0.3 nm", rel=0.05, spacings=(3.5e-9, 1e-9, 0.5e-9)):
    """The corner's meniscus against a band node's stiffness, and the widths in r of the
    meniscus annulus (sigma < h < fill gap) and of the LJ zone (h < 10^(1/2) sigma) at the
    edge of a state just after the jump-in (a follow band of 3.5 nm)."""
    sc = femadh.load_scene(SLIDER).replace({"effects.asperity_gap.sigma": sigma,
                                            "effects.capillary.relative_pressure": rel})
    cap, lj = sc.effects["capillary"], sc.effects["lj"]
    s = sc.gap.sigma
    p0 = cap.surface_tension / abs(cap.kelvin_radius)
    h = np.linspace(s, 3 * s, 20001)
    soft_cap = float(np.max(-cap.dpressure(h)))
    soft_lj = float(-lj.dpressure(np.array([s]))[0])
    out = {"P0": p0, "w": cap.width, "fill_gap": 2 * abs(cap.kelvin_radius),
           "soft_cap": soft_cap, "soft_lj": soft_lj, "nodes": []}
    for dx in spacings:
        fam = GridFamily(1.4e-5, 4.2e-6, 5e-8, inner=4e-6)    # a 200-nm band at 4 um
        pb = build_problem(sc, operator=GreenOperator(fam.member(dx), sc.e_star))
        k = float(np.min(np.diag(pb.K)[pb.finest_nodes]))
        out["nodes"].append((dx, k, (soft_cap + soft_lj) / k))
    short = sc.replace({"sweep.start": "1.2 nm", "sweep.stop": "0.6 nm",
                        "sweep.directions": ["approach"]})
    grid = {"spacing": 3.5e-9, "band": 5.6e-6, "grading": 1e-7, "follow": 3e-7}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = run(variant(short, grid=grid, radius=1.4142e-5), None, figures=False,
                progress=False, estimate=False)
    prof = r.profiles["approach"]
    rr, w, d = np.asarray(prof["r_m"][-1], float), np.asarray(prof["w_m"][-1]), prof["d_m"][-1]
    gap = d + sc.sphere.shape(rr) - w
    k = int(np.flatnonzero(gap <= s * (1 + 1e-9))[-1])
    beyond = rr[k:], gap[k:]

    def where(g):
        return float(np.interp(g, beyond[1], beyond[0]))
    out.update(d=d, r_c=float(rr[k]), meniscus_width=where(out["fill_gap"]) - float(rr[k]),
               lj_width=where(10**0.5 * s) - float(rr[k]), status=r.status)
    return out


def main():
    load = os.getloadavg()
    rows = fig4_rows()
    corner = meniscus_corner()
    lines = ["# A band that follows the contact edge (validation/follow_band.py)", "",
             f"Machine load (1-min average) {load[0]:.1f} at the start, "
             f"{os.getloadavg()[0]:.1f} at the end (2 cores): the wall times are relative.", "",
             "## Fig 4 scene: static band against a follow band of the same spacing", "",
             "| band spacing (nm) | grid | nodes (first..last) | exchanges (to static) | "
             "status | max adhesion (uN) | wall (s) |", "|---|---|---|---|---|---|---|"]
    for h, follow, n0, n1, rg, wide, st, F, t in rows:
        kind = "static [0, 5.9 um]" if not follow else f"follow {follow * 1e6:g} um"
        lines.append(f"| {h * 1e9:g} | {kind} | {n0}{'..' + str(n1) if n1 else ''} | "
                     f"{rg} ({wide}) | {st} | {F * 1e6:.4f} | {t:.1f} |")
    c = corner
    lines += ["", "## The sigma = 0.3 nm, p/psat = 0.05 corner", "",
              f"Meniscus: Laplace pressure P0 = {c['P0'] / 1e6:.4g} MPa over gaps up to "
              f"{c['fill_gap'] * 1e9:.4g} nm (sigma 0.3 nm), step smoothed over w = "
              f"{c['w'] * 1e12:.3g} pm: softening up to {c['soft_cap']:.3g} Pa/m, LJ's at "
              f"sigma {c['soft_lj']:.3g} Pa/m.", "",
              "| band spacing (nm) | node stiffness K_kk (Pa/m) | (meniscus + LJ) / K_kk |",
              "|---|---|---|"]
    for dx, k, ratio in c["nodes"]:
        lines.append(f"| {dx * 1e9:g} | {k:.3g} | {ratio:.2f} |")
    lines += ["", f"On a state just after the jump-in (d = {c['d'] * 1e9:.3g} nm, follow band "
              f"of 3.5 nm, {c['status']}): contact radius {c['r_c'] * 1e6:.4g} um; the "
              f"meniscus annulus sigma < h < {c['fill_gap'] * 1e9:.3g} nm is "
              f"{c['meniscus_width'] * 1e9:.3g} nm wide in r, the LJ zone up to 10^(1/2) "
              f"sigma {c['lj_width'] * 1e9:.3g} nm.", "",
              "A single node never snaps on its own at 3.5 nm (ratio below 1), yet the "
              "contact joins and leaves node by node (measured: on the retract from -5 nm a "
              "fold every 0.0135 nm of d, one node of 3.5 nm each, 11-12 per 0.2-nm step, "
              "the stepping's solve budget per step until each fold brought its own): the "
              "meniscus annulus, where 127 MPa act, spans only a few spacings, so the edge "
              "moves between nodes in jumps (lattice trapping of the edge, not of a single "
              "node). Resolving it smoothly needs spacings well below its width where the "
              "edge travels."]
    (HERE / "results" / "follow_band.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
