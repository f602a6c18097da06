"""Command line: ``femadh run SCENE``, ``femadh check SCENE``."""
import argparse
import sys

from .errors import FemadhError


def _parser():
    p = argparse.ArgumentParser(
        prog="femadh",
        description="Adhesion of a sphere on an elastic flat: Lennard-Jones surface forces, "
                    "the asperity sigma-gap and elasticity (Green function), swept in the "
                    "separation d. Scenes are TOML files; see validation/scenes/ for examples.")
    sub = p.add_subparsers(dest="command", required=True)
    r = sub.add_parser("run", help="solve a scene's force-separation sweep and write results",
                       description="Solve a scene and write curve.csv, diagnostics.csv, "
                                   "fields.csv, summary.json and fig3_panels.png.")
    r.add_argument("scene", help="scene file (TOML)")
    r.add_argument("--out", help="output folder (default: the scene's [output] dir)")
    r.add_argument("--no-figures", action="store_true", help="skip the PNG figures")
    r.add_argument("--quiet", action="store_true", help="no progress bar or summary lines")
    c = sub.add_parser("check", help="validate a scene file without solving it")
    c.add_argument("scene", help="scene file (TOML)")
    m = sub.add_parser("mesh", help="build (or fetch from cache) the FE mesh of a scene",
                       description="Mesh the half-space of a scene with gmsh (cached by a hash "
                                   "of its parameters) and write it as .msh and .vtu.")
    m.add_argument("scene", help="scene file (TOML)")
    m.add_argument("--out", help="output folder (default: the scene's [output] dir)")
    s = sub.add_parser("study", help="convergence and accuracy-vs-time studies",
                       description="convergence: the FE mesh ladder against the Green function "
                                   "on the scene's nodes, and the Green function in N; writes "
                                   "convergence.csv/.md/.png.")
    s.add_argument("kind", choices=["convergence"])
    s.add_argument("scene", help="scene file (TOML)")
    s.add_argument("--levels", type=int, default=3, help="FE mesh levels (1-4, default 3)")
    s.add_argument("--out", help="output folder (default: <scene output dir>/study)")
    g = sub.add_parser(
        "regime", help="smooth-sphere LJ adhesion map vs the Tabor parameter",
        description="Trace the force-separation curve of a smooth elastic sphere with LJ "
                    "surface forces (no sigma-gap) through its folds for a range of Tabor "
                    "parameters mu = (R dg^2/(E*^2 z0^3))^(1/3); writes regime.csv (pull-off / "
                    "pi R dg vs Maugis-Dugdale, jump-in/out d / z0, hysteresis), "
                    "regime_map.png and regime_curves.png.")
    g.add_argument("--mu", type=float, nargs=2, default=(0.1, 5.0), metavar=("FROM", "TO"),
                   help="Tabor parameter range (default 0.1 5)")
    g.add_argument("--points", type=int, default=20, help="log-spaced points (default 20)")
    g.add_argument("--radius", default="1 um", help="sphere radius (default '1 um')")
    g.add_argument("--hamaker", default="1e-19 J", help="Hamaker constant (default '1e-19 J')")
    g.add_argument("--z0", default="0.165 nm", help="LJ equilibrium distance (default "
                                                    "'0.165 nm')")
    g.add_argument("--out", default="out/regime", help="output folder (default out/regime)")
    return p


def _regime(args):
    import numpy as np

    from .errors import SceneError
    from .studies.convergence import default_progress
    from .studies.regime import regime_map, write_regime
    from .units import to_si

    lo, hi = args.mu
    if not (0 < lo < hi) or args.points < 1:
        print("femadh: error: --mu needs 0 < FROM < TO and --points >= 1", file=sys.stderr)
        return 2
    try:
        kw = {k: to_si(getattr(args, a), dim, file="command line", key=f"--{a}")
              for k, a, dim in (("radius", "radius", "length"), ("hamaker", "hamaker", "energy"),
                                ("z0", "z0", "length"))}
    except SceneError as exc:
        print(f"femadh: error: {exc}", file=sys.stderr)
        return 2
    mus = np.geomspace(lo, hi, args.points) if args.points > 1 else [lo]
    say = default_progress()
    pts = regime_map(mus, progress=(lambda i, p: say(
        f"mu = {p.mu:.3g}: pull-off {p.pull_off:.4f} pi R dg ({i + 1}/{len(mus)})"))
        if say else None, **kw)
    path = write_regime(pts, args.out)
    print(path.read_text(), end="")
    print(f"results in {args.out} ({sum(p.wall_time for p in pts):.1f} s)")
    return 0


def main(argv=None):
    args = _parser().parse_args(argv)
    if args.command == "regime":
        return _regime(args)
    from .runner.contact import run
    from .scene import load_scene

    try:
        scene = load_scene(args.scene)
        if args.command == "check":
            if hasattr(scene, "p_ratios"):
                print(f"{args.scene}: ok (meniscus: {len(scene.liquids)} liquids, "
                      f"{len(scene.radii)} radii, {len(scene.p_ratios)} p/psat, "
                      f"methods {', '.join(scene.methods)})")
            else:
                print(f"{args.scene}: ok ({len(scene.d_values)} separations, "
                      f"{', '.join(scene.directions)}, {scene.nodes} nodes, {scene.method})")
            return 0
        if args.command == "mesh":
            return _mesh(scene, args.out)
        if args.command == "study":
            from .studies.convergence import convergence, default_progress, write_convergence

            if not 1 <= args.levels <= 4:
                print("femadh: error: --levels must be 1 to 4", file=sys.stderr)
                return 2
            rows = convergence(scene, levels=args.levels, progress=default_progress())
            path = write_convergence(rows, args.out or f"{scene.output_dir}/study", scene.name)
            print(path.read_text())
            return 0
        if args.command == "run" and hasattr(scene, "p_ratios"):
            return _run_meniscus(scene, args)
        res = run(scene, args.out, figures=not args.no_figures,
                  progress=False if args.quiet else None)
    except FemadhError as exc:
        print(f"femadh: error: {exc}", file=sys.stderr)
        return 2
    if not args.quiet:
        for b, sw in res.sweeps.items():
            c = res.curve(b)
            k = c["F_ex"].argmax()
            print(f"{b}: {len(sw.states)} states, max adhesion F_ex = {c['F_ex'][k] * 1e3:.4g} mN"
                  f" at d = {c['d'][k] * 1e9:.3g} nm, F_LJ(d = {c['d'][-1] * 1e9:.3g} nm) = "
                  f"{c['F_LJ'][-1] * 1e3:.4g} mN")
        for j in res.jumps:
            where = (f"±{j.resolution * 1e9:.1e} nm" if j.resolution > 0 else
                     "traced fold, dd/ds = 0")
            print(f"jump ({j.branch}): branch folds at d = {j.d_fold * 1e9:.4f} nm "
                  f"({where}), h0 {j.before.h0 * 1e9:.3f} -> {j.after.h0 * 1e9:.3f} nm")
        print(f"results in {res.out_dir} ({res.wall_time:.2f} s)")
    if res.status != "converged":
        print(f"femadh: error: {res.error}; states computed before it are kept in "
              f"{res.out_dir}", file=sys.stderr)
        return 3
    return 0


def _run_meniscus(scene, args):
    from .runner.meniscus import run_meniscus

    results, errors, wall = run_meniscus(scene, args.out, figures=not args.no_figures)
    if not args.quiet:
        for (liq, R, meth), res in results.items():
            ok = [r for r in res if not isinstance(r, Exception)]
            if ok:
                best = max(ok, key=lambda r: r.force_over_4piRgamma)
                print(f"{liq:10s} R = {R * 1e9:7g} nm {meth:9s}: max F/4piRgamma = "
                      f"{best.force_over_4piRgamma:.4f} at h = {best.film * 1e9:.3f} nm, "
                      f"r_K = {best.kelvin_radius * 1e9:.3f} nm"
                      + (f"  ({len(res) - len(ok)} p/psat without meniscus)" if len(ok) < len(res)
                         else ""))
        print(f"results in {args.out or scene.output_dir} ({wall:.2f} s)")
    for e in errors[:5]:
        print(f"femadh: note: no meniscus for {e['liquid']} R = {e['tip_radius_m']:g} m "
              f"{e['method']} at p/psat = {e['p_ratio']:g}: {e['error']}", file=sys.stderr)
    return 0


def _mesh(scene, out):
    from pathlib import Path
    import shutil

    import meshio

    from .elastic import RadialGrid
    from .elastic.fe import FESettings, mesh_spec
    from .elastic.fe.mesh import cached_mesh, read_mesh

    st = scene.fe_settings or FESettings()
    grid = RadialGrid.uniform(scene.analysis_radius, scene.nodes)
    spec = mesh_spec(grid, st)
    src = cached_mesh(spec, progress=lambda m: print(m, file=sys.stderr))
    out = Path(out or scene.output_dir)
    out.mkdir(parents=True, exist_ok=True)
    shutil.copy(src, out / "mesh.msh")
    p, tri = read_mesh(src, scale=grid.radius)
    pts = __import__("numpy").column_stack([p, 0 * p[:, 0]])
    meshio.write(out / "mesh.vtu", meshio.Mesh(pts, [("triangle", tri)]))
    print(f"{len(p)} vertices, {len(tri)} triangles (P2: {2 * (len(p) + len(p) + len(tri))} "
          f"DOFs approx.); mesh {spec.key()} -> {out / 'mesh.msh'} (cached at {src})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
