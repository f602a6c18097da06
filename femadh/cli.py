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
    return p


def main(argv=None):
    args = _parser().parse_args(argv)
    from .runner import run
    from .scene import load_scene

    try:
        scene = load_scene(args.scene)
        if args.command == "check":
            print(f"{args.scene}: ok ({len(scene.d_values)} separations, "
                  f"{', '.join(scene.directions)}, {scene.nodes} nodes)")
            return 0
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
            print(f"jump ({j.branch}): branch folds at d = {j.d_fold * 1e9:.4f} nm "
                  f"(±{j.resolution * 1e9:.1e} nm), h0 {j.before.h0 * 1e9:.3f} -> "
                  f"{j.after.h0 * 1e9:.3f} nm")
        print(f"results in {res.out_dir} ({res.wall_time:.2f} s)")
    if res.status != "converged":
        print(f"femadh: error: {res.error}; states computed before it are kept in "
              f"{res.out_dir}", file=sys.stderr)
        return 3
    return 0


if __name__ == "__main__":
    sys.exit(main())
