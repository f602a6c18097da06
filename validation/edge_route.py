"""The edge route of a sigma-gap run (femadh/runner/edge_route.py) as a user runs it, against the
branch's own refinement study and the present runner.

``python -m validation.edge_route`` writes validation/results/edge_route.md:

1. the three points of validation/sigma_edge.py (the stiction map's scene at sigma = 0.3 nm,
   p/psat 0.95 and 0.05, sigma = 0.489 nm, p/psat 0.15), each run by ``femadh.run`` at the
   scene's defaults with ``[solver] route = "edge"`` (the sweep's outputs: the approach, the
   retract's states, the jump-out landed; the first two take it at "auto" too: their grid
   would follow the edge) and ``"peak"`` (the max adhesion alone): status, max adhesion and
   its estimated error, the members, nodes, the parts' seconds, wall and CPU time; against
   the 5-member extrapolation of sigma_edge.md;
2. the four static-band points of the stiction map that reach its 90-s limit on the sweep
   (sigma/p/psat 0.489/0.15, 0.489/0.25, 0.678/0.25, 0.867/0.35), by ``"edge"`` and
   ``"peak"``: the same columns;
3. the bundled Fig 4 scene (its pilot finds a fold) by its default path (the sweep) and by
   ``"edge"``: the headline numbers with their errors, old against new;
4. the small scene of tests/test_edge_route.py (a 20-um sphere of 10-GPa bodies, sigma =
   0.3 nm, p/psat 0.5, accuracy 1e-2) by the route and by the present runner
   (edge_route.ENABLED = False: its adaptive grid on a band following the edge): values,
   estimates, times.
"""
import math
import os
from pathlib import Path
import time

import femadh
from femadh.runner import edge_route

HERE = Path(__file__).resolve().parent
SCENE = HERE / "scenes" / "paper1_slider_meniscus.toml"
#: (sigma nm, p/psat, the 5-member extrapolation of validation/results/sigma_edge.md (N),
#: the runner's time there)
POINTS = [(0.3, 0.95, 8.079215e-04, "1362 s wall (accuracy 3e-3 asked)"),
          (0.3, 0.05, 3.384265e-04, "1100 s (8.8e-3)"),
          (0.489, 0.15, 1.564850e-04, "1473 s to 8.7e-4")]
SMALL = {"sphere.radius": "20 um", "materials.disk.youngs_modulus": "10 GPa",
         "materials.slider.youngs_modulus": "10 GPa", "effects.asperity_gap.sigma": "0.3 nm",
         "effects.capillary.relative_pressure": 0.5, "sweep.start": "2 nm",
         "sweep.stop": "-3 nm", "solver.accuracy": 1e-2}


#: the stiction map's static-band points that reach its 90-s limit on the sweep
STATIC = [(0.489, 0.15), (0.489, 0.25), (0.678, 0.25), (0.867, 0.35)]


def _row(head, res, wall, cpu):
    """One table row: status, max adhesion, relative error, members (nodes), the parts'
    seconds, jump-in and jump-out, wall / CPU."""
    F = res.headline.get("max_adhesion_N", math.nan)
    E = res.headline.get("max_adhesion_N_error", math.nan)
    g, t, hl = res.grid, res.timings, res.headline
    nodes = g.get("family_nodes", [0])
    parts = " / ".join(f"{t[k]:.1f}" if k in t else "-"
                       for k in ("approach_s", "family_s", "retract_s"))
    jumps = ", ".join(f"{hl[k] * 1e9:.5g}" if k in hl else "-"
                      for k in ("jump_in_d_m", "jump_out_d_m"))
    return (f"| {head} | {res.status} | {F:.7e} | {E / F:.1e} | {len(nodes)} ({nodes[0]}-"
            f"{g.get('nodes')}) | {parts} | {jumps} | {wall:.1f} / {cpu:.1f} |")


def timed(scene):
    t0, c0 = time.perf_counter(), time.process_time()
    res = femadh.run(scene, None, figures=False, progress=False)
    return res, time.perf_counter() - t0, time.process_time() - c0


def main():
    load = os.getloadavg()
    out = ["# The edge route as a user runs it (`python -m validation.edge_route`)", "",
           f"Machine: 2 cores shared with other sessions, load (1/5/15 min) {load[0]:.1f} / "
           f"{load[1]:.1f} / {load[2]:.1f} at the start; one BLAS thread.", "",
           "## The three points of sigma_edge.md, `femadh.run` at the scene's defaults "
           "(accuracy 1e-3), `[solver] route = \"edge\"` (the sweep's outputs) and "
           "`\"peak\"` (the max adhesion alone)", "",
           "| sigma (nm) | p/psat | route | status | max adhesion (N) | estimated error (rel.) "
           "| members (nodes) | approach / family / retract (s) | jump-in, jump-out (nm) | "
           "wall / CPU (s) | 5-member extrapolation (N) | difference (rel.) | the runner "
           "before |", "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    base = femadh.load_scene(SCENE)
    for sigma, rel, ext, before in POINTS:
        for route in ("edge", "peak"):
            scene = base.replace({"effects.asperity_gap.sigma": f"{sigma} nm",
                                  "effects.capillary.relative_pressure": rel,
                                  "sweep.start": "4 nm", "solver.route": route})
            res, wall, cpu = timed(scene)
            F = res.headline.get("max_adhesion_N", math.nan)
            out.append(_row(f"{sigma} | {rel} | {route}", res, wall, cpu)
                       + f" {ext:.6e} | {(F - ext) / ext:+.1e} | {before} |")
            print(out[-1], flush=True)
    out += ["", "## The four static-band points of the stiction map (90-s limit on the "
            "sweep at \"auto\")", "", "| sigma (nm) | p/psat | route | status | max adhesion "
            "(N) | estimated error (rel.) | members (nodes) | approach / family / retract "
            "(s) | jump-in, jump-out (nm) | wall / CPU (s) |", "|---|---|---|---|---|---|---|"
            "---|---|---|"]
    for sigma, rel in STATIC:
        for route in ("edge", "peak"):
            scene = base.replace({"effects.asperity_gap.sigma": f"{sigma} nm",
                                  "effects.capillary.relative_pressure": rel,
                                  "sweep.start": "4 nm", "solver.route": route})
            res, wall, cpu = timed(scene)
            out.append(_row(f"{sigma} | {rel} | {route}", res, wall, cpu))
            print(out[-1], flush=True)
    out += ["", "## The bundled Fig 4 scene: its default path (the sweep) and the route", "",
            "| path | status | max adhesion (N) | jump-out (nm) | jump-in (nm) | hysteresis "
            "(J) | F_ex deepest (N) | wall (s) |", "|---|---|---|---|---|---|---|---|"]
    fig4 = femadh.load_scene(HERE / "scenes" / "paper1_fig4.toml")
    got = []
    for label, sc in (("default (sweep)", fig4), ("route = \"edge\"",
                                                 fig4.replace({"solver.route": "edge"}))):
        res, wall, cpu = timed(sc)
        hl = res.headline
        got.append(hl)

        def pm(k, scale=1.0, fmt=".7g"):
            v, e = hl.get(k, math.nan) * scale, hl.get(k + "_error", math.nan) * scale
            return f"{v:{fmt}} ± {e:.2g}" if k in hl else "-"
        out.append(f"| {label} ({res.grid.get('route', res.grid.get('kind'))}) | {res.status} "
                   f"| {pm('max_adhesion_N')} | {pm('jump_out_d_m', 1e9)} | "
                   f"{pm('jump_in_d_m', 1e9)} | {pm('hysteresis_J')} | "
                   f"{pm('F_ex_deepest_N')} | {wall:.1f} |")
        print(out[-1], flush=True)
    (o, n) = got
    for k in ("max_adhesion_N", "jump_out_d_m", "jump_in_d_m", "hysteresis_J",
              "F_ex_deepest_N"):
        if k in o and k in n:
            e_old = o.get(k + "_error", math.nan)
            out.append(f"- {k}: new - old = {n[k] - o[k]:+.3e} ({(n[k] - o[k]) / o[k]:+.1e} "
                       f"relative); the old's stated error {e_old:.2e}: "
                       + ("within it" if abs(n[k] - o[k]) <= e_old else
                          "OUTSIDE it" if math.isfinite(e_old) else "no error stated"))
    out += ["", "## The small scene of tests/test_edge_route.py (accuracy 1e-2)", "",
            "| path | status | max adhesion (N) | estimated error (N) | d at max (nm) | "
            "nodes | wall / CPU (s) |", "|---|---|---|---|---|---|---|"]
    small = base.replace(SMALL)
    rows = []
    for label, enabled in (("edge route", True), ("present runner", False)):
        edge_route.ENABLED = enabled
        try:
            res, wall, cpu = timed(small)
        finally:
            edge_route.ENABLED = True
        hl = res.headline
        nodes = (res.grid.get("nodes") if enabled else
                 ", ".join(str(s["nodes"]) for s in res.accuracy.get("steps", [])))
        rows.append((hl.get("max_adhesion_N", math.nan), hl.get("max_adhesion_N_error",
                                                                 math.nan)))
        out.append(f"| {label} | {res.status} | {rows[-1][0]:.7e} | {rows[-1][1]:.2e} | "
                   f"{hl.get('d_at_max_adhesion_m', math.nan) * 1e9:.4f} | {nodes} | "
                   f"{wall:.1f} / {cpu:.1f} |")
        print(out[-1], flush=True)
    (a, ea), (b, eb) = rows
    out += ["", f"Difference {a - b:+.3e} N ({(a - b) / b:+.1e} relative); the estimates "
            f"sum to {ea + eb:.3e} N: {'within' if abs(a - b) <= ea + eb else 'OUTSIDE'} "
            "them.", "", f"Load at the end {os.getloadavg()[0]:.1f}."]
    (HERE / "results" / "edge_route.md").write_text("\n".join(out) + "\n")
    print("\n".join(out))


if __name__ == "__main__":
    main()
