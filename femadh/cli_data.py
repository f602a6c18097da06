"""Command line of measured force curves: ``femadh compare`` and ``femadh fit``.

Registered by :mod:`femadh.cli` (``add_parsers``, ``dispatch``); errors follow its convention
(one ``femadh: error:`` line each; exit 2 bad scene, curve or arguments, 3 a failed run or fit,
4 output not writable, 5 missing dependency).
"""
import json
import sys

from .errors import SceneError

COMMANDS = ("compare", "fit")


def add_parsers(sub):
    """Add the ``compare`` and ``fit`` subcommands to the CLI's subparsers."""
    cp = sub.add_parser(
        "compare", allow_abbrev=False, help="a measured force curve against a run of a scene",
        description="Run the scene (no error estimate) and compare its force curve with a "
                    "measured one (csv: z_m, force_N, branch, or columns with units; JPK, "
                    "Igor, HDF5, tab via afmformats). The force is taken in the AFM sign "
                    "(repulsive > 0, i.e. -F_ex); the contact-point offset z - d is the best "
                    "shift unless --offset is given. Writes compare.png (curves, contact "
                    "points, jumps, residual), compare.csv and compare.json; prints the rms "
                    "residual.")
    cp.add_argument("scene", help="scene file (TOML)")
    cp.add_argument("curve", help="measured curve (.csv, or an afmformats format)")
    cp.add_argument("--out", help="output folder (default: <scene output dir>/compare)")
    cp.add_argument("--offset", help="contact-point offset z - d, e.g. '12.3 nm' (default: "
                                     "the best one)")
    cp.add_argument("--index", type=int, default=0, help="curve of a multi-curve file "
                                                         "(default 0)")
    cp.add_argument("--json", action="store_true", help="print the result as JSON (SI)")
    ft = sub.add_parser(
        "fit", allow_abbrev=False,
        help="least-squares fit of scene keys and the contact point to a curve",
        description="Fit 1-3 scene keys (their scene values are the start) and the "
                    "contact-point offset z_offset_m (d = z - z_offset) to a measured force "
                    "curve; every evaluation is a femadh run. Reports values, standard "
                    "errors (s^2 (J^T J)^-1, s^2 = RSS/(n - p)) and correlations; a parameter "
                    "the data cannot identify is an error saying which and why. Pin the grid "
                    "([solver] nodes) for a smooth finite-difference Jacobian.",
        epilog="e.g. femadh fit scene.toml curve.csv --vary effects.lennard_jones.hamaker "
               "--vary materials.disk.youngs_modulus --workers 2")
    ft.add_argument("scene", help="scene file (TOML)")
    ft.add_argument("curve", help="measured curve (.csv, or an afmformats format)")
    ft.add_argument("--vary", action="append", default=[], metavar="KEY", required=True,
                    help="a dotted scene key to fit (repeatable, 1-3; see `femadh keys`)")
    ft.add_argument("--workers", type=int, help="processes for the runs (default: keys + 1, "
                                                "at most the CPUs)")
    ft.add_argument("--max-evaluations", type=int, default=30,
                    help="budget of residual evaluations (default 30; each Jacobian costs "
                         "one run per key on top)")
    ft.add_argument("--rel-step", type=float, default=1e-3,
                    help="relative finite-difference step of the keys (default 1e-3)")
    ft.add_argument("--offset", help="starting contact-point offset, e.g. '12.3 nm' "
                                     "(default: the best one for the scene's values)")
    ft.add_argument("--index", type=int, default=0, help="curve of a multi-curve file")
    ft.add_argument("--out", help="also write fit.json and fit.png (the curve at the "
                                  "solution) into this folder")
    ft.add_argument("--json", action="store_true",
                    help="print {KEY: {value, stderr}, ..., z_offset_m: {...}, fit: {...}} "
                         "(SI)")


def dispatch(args):
    """Run ``compare`` or ``fit``; returns the exit code (errors raise femadh's exceptions,
    which :func:`femadh.cli.main` turns into one line and the exit code)."""
    import os

    from .io.force_curve import read_force_curve
    from .scene import load_scene
    from .scene.resources import check_resources
    from .units import to_si

    # every input checked before anything runs or is written
    offset = None if args.offset is None else to_si(args.offset, "length",
                                                    file="command line", key="--offset")
    if args.index < 0:
        raise SceneError("command line", "--index", args.index, "an integer >= 0")
    curve = read_force_curve(args.curve, index=args.index)
    scene = load_scene(args.scene)
    check_resources(scene)
    if scene.kind != "contact":
        raise SceneError(scene.path, "meniscus", "(a meniscus scene)",
                         f"a contact scene: `femadh {args.command}` compares force curves")
    if curve.columns.get("z", "").startswith("height (") and scene.instrument is None:
        # afmformats' heights are the piezo's: they include the cantilever's deflection, which
        # only a scene with the spring in series models; the tip position is the separation
        _note(f"the curve's z is its {curve.columns['z']}, compared with the separation d of a "
              "scene without [instrument]: add the cantilever's [instrument] or use the tip "
              "position (height minus deflection)")
    if args.command == "compare":
        return _compare(scene, curve, offset, args)
    if args.workers is not None and args.workers < 1:
        raise SceneError("command line", "--workers", args.workers, "an integer >= 1")
    if args.max_evaluations < 2:
        raise SceneError("command line", "--max-evaluations", args.max_evaluations,
                         "an integer >= 2")
    if not 0 < args.rel_step < 0.5:
        raise SceneError("command line", "--rel-step", args.rel_step, "a number in (0, 0.5)")
    from .fitting.lsq import check_keys

    check_keys(scene, args.vary)
    workers = args.workers or max(1, min(len(args.vary) + 1, os.cpu_count() or 1))
    return _fit(scene, curve, offset, workers, args)


def _note(msg):
    print(f"femadh: note: {msg}", file=sys.stderr)


def _compare(scene, curve, offset, args):
    from .errors import FemadhError
    from .fitting.compare import compare, write_comparison
    from .runner.run import run

    res = run(scene, None, figures=False, progress=False, estimate=False)
    if res.status != "converged":
        raise FemadhError(f"the run of {scene.path} failed: {res.error}")
    cmp = compare(res, curve, offset)
    out = args.out or f"{scene.output_dir}/compare"
    png = write_comparison(cmp, out)
    if cmp.outside:
        _note(f"{cmp.outside} of {len(curve)} measured points lie outside the simulated "
              "separations (the end values are used there): widen the scene's [sweep]")
    if args.json:
        print(json.dumps(cmp.as_json() | {"figure": str(png)}, indent=1))
    else:
        print(f"rms residual {cmp.rms:.4g} N over {len(curve)} points (contact-point offset "
              f"{cmp.offset * 1e9:.6g} nm{' given' if offset is not None else ', best'}); "
              f"figure {png}")
    return 0


def _fit(scene, curve, offset, workers, args):
    from .fitting.compare import compare, write_comparison
    from .fitting.lsq import fit_curve

    if getattr(scene, "adaptive", False):
        _note("the scene has no [solver] nodes: its adaptive grid is planned again for "
              "every parameter value, which makes the finite-difference Jacobian jump; pin "
              "nodes for a fit")
    say = (lambda m: print(f"fit: {m}", file=sys.stderr)) if sys.stderr.isatty() else None
    res = fit_curve(scene, curve, args.vary, workers=workers,
                    max_nfev=args.max_evaluations, rel_step=args.rel_step, offset=offset,
                    progress=say)
    if args.out:
        from .io.atomic import write_atomic

        cmp = compare(res.sim, curve, res.values[-1])
        write_comparison(cmp, args.out, name="fit",
                         title=f"fit: rms residual {res.rms:.3g} N, {res.runs} runs")
        write_atomic(f"{args.out}/fit.json", json.dumps(res.as_json(), indent=1) + "\n")
    if args.json:
        print(json.dumps(res.as_json(), indent=1))
        return 0
    for k, v, s in zip(res.keys, res.values, res.stderr):
        rel = f" ({100 * s / abs(v):.3g} %)" if k != res.keys[-1] and v else ""
        print(f"{k} = {v:.6g} +- {s:.3g}{rel}")
    if len(res.keys) > 1:
        print("correlation: " + "; ".join(
            f"{res.keys[i]} / {res.keys[j]} {res.correlation[i, j]:+.3f}"
            for i in range(len(res.keys)) for j in range(i + 1, len(res.keys))))
    print(f"rms residual {res.rms:.4g} N over {res.n} points; {res.runs} femadh runs "
          f"({res.nfev} residual and {res.njev} Jacobian evaluations) in {res.wall_time:.1f} s "
          f"on {res.workers} process{'es' if res.workers > 1 else ''}")
    return 0
