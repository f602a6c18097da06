"""Command line: ``femadh run SCENE``, ``check``, ``keys``, ``mesh``, ``render``, ``study``,
``regime``.

Every user mistake or fault ends in one ``femadh: error:`` line per problem, never a
traceback. Exit codes: 0 done; 2 the scene or the command line is wrong; 3 a solve failed
(the states computed before it are kept); 4 an output cannot be written or the output
folder holds another run (use --resume or --overwrite); 5 an optional
dependency is missing; 6 the run reached its time limit (``[solver] time_limit``,
``--time-limit``: completed states kept, ``--resume`` continues); 130 / 143 interrupted by
SIGINT / SIGTERM (completed states kept, ``--resume`` continues); 141 the reader of its
output went away (``femadh keys | head``: quiet, as a program ended by SIGPIPE; what a run
wrote to its folder is whole); 1 an internal error (a bug: set FEMADH_DEBUG=1 for its
traceback).
"""
import os
import signal
import sys


def _as_program():
    """Whether this process is the ``femadh`` program (its script or ``python -m femadh``),
    not a script that calls :func:`main`; a coverage run keeps its teardown (its data is
    written at exit)."""
    prog = os.path.normpath(sys.argv[0]) if sys.argv and sys.argv[0] else ""
    # a worker that multiprocessing spawned for a study or a fit has the program's argv
    # and, spawned by the ``femadh`` script, imports this module while it re-runs that
    # script as its "__mp_main__": it is not the program (its signals are its pool's,
    # femadh.studies.executors). It is renamed from "MainProcess" before that import (its
    # parent_process() is set only after it)
    mp = sys.modules.get("multiprocessing.process")
    return (not os.environ.get("COVERAGE_PROCESS_START")
            and (mp is None or (mp.current_process().name == "MainProcess"
                                and mp.parent_process() is None))
            and (os.path.basename(prog).removesuffix(".exe") == "femadh"
                 or prog.endswith(os.path.join("femadh", "__main__.py"))))


#: what a signal outside :func:`main`'s guard says after its name (:func:`_stop_at_once`)
_STOP_WHEN = [b"while starting; nothing was written"]
#: its exit code: None while starting (the signal's own: 130 SIGINT, 143 SIGTERM, as a run
#: stopped by it); the command's own code once it has ended
_STOP_CODE = [None]


def _stop_at_once(signum, frame):
    """SIGINT or SIGTERM to the program outside :func:`main`'s guard - while it imports itself
    (before :func:`main` runs) or after the command has ended: one line naming the signal, at
    once, exit 128 + its number (130, 143; or the ended command's own code). Nothing is being
    written then (the line says what stands), and a KeyboardInterrupt raised in the middle of
    an import would end in a traceback of the import machinery instead (SIGTERM's default
    action: a silent death, exit -15, no line)."""
    name = b"SIGTERM" if signum == signal.SIGTERM else b"SIGINT"
    try:
        os.write(2, b"femadh: error: interrupted by " + name + b" " + _STOP_WHEN[0] + b"\n")
    except OSError:
        pass                        # (no stderr: the exit code still says it)
    os._exit(128 + signum if _STOP_CODE[0] is None else _STOP_CODE[0])


# First thing, before the imports below: the program's Ctrl-C and SIGTERM are one line from
# here on. Not when imported by a script or a test (their signals are theirs), nor in a
# study's or a fit's worker process (see _as_program), nor when the parent set the signal to
# be ignored (nohup, a background job: it stays ignored).
if _as_program() and signal.getsignal(signal.SIGINT) is signal.default_int_handler:
    signal.signal(signal.SIGINT, _stop_at_once)
if _as_program() and signal.getsignal(signal.SIGTERM) is signal.SIG_DFL:
    signal.signal(signal.SIGTERM, _stop_at_once)

import argparse  # noqa: E402  (after the handler: a Ctrl-C during these imports is one line)

from ._version import __version__  # noqa: E402
from .errors import (DependencyError, FemadhError, Interrupted, OutputError,  # noqa: E402
                     SceneError)

EXIT_SCENE, EXIT_SOLVE, EXIT_OUTPUT, EXIT_DEPENDENCY, EXIT_BUG = 2, 3, 4, 5, 1
#: the shell's code of a program ended by SIGPIPE (128 + 13)
EXIT_PIPE = 141


def _parser():
    # allow_abbrev=False on every parser (subparsers do not inherit it): an abbreviation
    # such as --overwrit is refused, never taken for the destructive --overwrite
    p = argparse.ArgumentParser(
        prog="femadh", allow_abbrev=False,
        description="Adhesion of a sphere on an elastic flat (MEMS/NEMS stiction): "
                    "Lennard-Jones surface forces, the asperity sigma-gap, capillary menisci "
                    "and the elastic half-space (Green function or finite elements), swept in "
                    "the separation d. Scenes are TOML files; see validation/scenes/ for "
                    "examples and `femadh keys` for every key.",
        epilog="exit codes: 0 done, 2 bad scene/arguments, 3 solve failed (states kept), "
               "4 output not writable or folder holds a previous run, 5 missing dependency, "
               "6 time limit reached (states kept), 130/143 interrupted, 1 an internal "
               "error (a bug in femadh: please report it).")
    p.add_argument("--version", action="version", version=f"femadh {__version__}")
    sub = p.add_subparsers(dest="command", required=True, metavar="COMMAND")
    r = sub.add_parser("run", allow_abbrev=False,
                       help="solve a scene and write its results and figures",
                       description="Solve a scene; write curve.csv, diagnostics.csv, "
                                   "fields.csv, jumps.csv, summary.json and its figures "
                                   "(meniscus scenes: meniscus.csv, profiles.csv).")
    r.add_argument("scene", help="scene file (TOML)")
    r.add_argument("--out", help="output folder (default: the scene's [output] dir)")
    g = r.add_mutually_exclusive_group()
    g.add_argument("--overwrite", action="store_true",
                   help="replace the results of a previous run in the output folder")
    g.add_argument("--resume", action="store_true",
                   help="continue an interrupted, failed or time-limited run in the output "
                        "folder (every committed row is checked first)")
    g.add_argument("--resume-from", type=int, metavar="K",
                   help="continue keeping only the first K committed states (a folder whose "
                        "later rows do not match their record)")
    r.add_argument("--time-limit", metavar="DURATION",
                   help="stop cleanly after this long, e.g. '10 min' (exit 6, states kept; "
                        "default: the scene's [solver] time_limit)")
    r.add_argument("--force", action="store_true",
                   help="run a scene whose estimated time or memory is beyond reason")
    r.add_argument("--no-figures", action="store_true", help="skip the PNG figures")
    r.add_argument("--no-estimate", action="store_true",
                   help="skip the error estimates of the headline numbers (they solve the "
                        "scene again on two coarser grids)")
    r.add_argument("--quiet", action="store_true", help="no progress bar or summary lines")
    c = sub.add_parser("check", allow_abbrev=False, help="validate a scene without solving it",
                       description="Validate every key, the optional dependencies the scene "
                                   "needs, and estimate its memory and run time (rates "
                                   "measured on a 2-core CI machine).")
    c.add_argument("scene", help="scene file (TOML)")
    c.add_argument("--force", action="store_true",
                   help="pass a scene whose estimated time is beyond reason")
    sub.add_parser("keys", allow_abbrev=False,
                   help="print every scene key (markdown reference page)",
                   description="Print every scene key - its unit, range, default and "
                               "meaning - as a markdown page (the scene file's reference; "
                               "`femadh keys > keys.md`).")
    m = sub.add_parser("mesh", allow_abbrev=False,
                       help="build (or fetch from cache) the FE mesh of a scene",
                       description="Mesh the half-space of a scene with gmsh (cached by a hash "
                                   "of its parameters) and write it as .msh and .vtu.")
    m.add_argument("scene", help="scene file (TOML)")
    m.add_argument("--out", help="output folder (default: the scene's [output] dir)")
    rd = sub.add_parser("render", allow_abbrev=False,
                        help="PNG of an FE run's deformed zone (PyVista)",
                        description="Render a state of an FE run off-screen: the deformed "
                                    "near-contact zone coloured by a stress or displacement "
                                    "field, and the surface pressure.")
    rd.add_argument("run_dir", help="output folder of an FE run (with approach.pvd)")
    rd.add_argument("--state", type=int, default=-1,
                    help="state number (default: the last of the approach)")
    rd.add_argument("--field", default="von_mises", help="field to colour by "
                    "(default von_mises; e.g. sigma_zz, displacement)")
    rd.add_argument("--png", help="output PNG (default RUN_DIR/render.png)")
    s = sub.add_parser("study", allow_abbrev=False,
                       help="parameter studies (sweep) and convergence studies",
                       description="sweep: many variants of a scene in parallel (local "
                                   "processes or a Dask cluster), resumable; convergence: the "
                                   "FE mesh ladder against the Green function and the Green "
                                   "function in N.")
    ss = s.add_subparsers(dest="kind", required=True, metavar="KIND")
    sw = ss.add_parser("sweep", allow_abbrev=False,
                       help="vary scene keys over values, one run per point",
                       description="Run every combination of the --vary values (or the "
                                   "scene's [study] table) and write study.csv, study.png and "
                                   "points/<id>/ (one run folder and record per point). "
                                   "Running it again reuses the finished points and runs the "
                                   "interrupted, crashed and missing ones. Exit 3 when points "
                                   "failed (one line per reason); 130/143 on SIGINT/SIGTERM "
                                   "(finished points kept).",
                       epilog="VALUES: '0.5 nm,1 nm,2 nm' | 'lo..hi:n' | 'lo..hi:n:log', with "
                              "units as in a scene file (a bare number is refused for a "
                              "dimensional key), e.g. --vary "
                              "effects.asperity_gap.sigma='0.3 nm..2 nm:10'")
    sw.add_argument("scene", help="scene file (TOML)")
    sw.add_argument("--vary", action="append", default=[], metavar="KEY=VALUES",
                    help="a dotted scene key and its values (repeatable)")
    sw.add_argument("--zip", action="store_true", help="pair the lists instead of their "
                    "product")
    sw.add_argument("--out", help="study folder (default: <scene output dir>/study)")
    g2 = sw.add_mutually_exclusive_group()
    g2.add_argument("--workers", type=int, help="local worker processes (default: CPUs)")
    g2.add_argument("--scheduler", help="a dask.distributed scheduler address "
                    "(tcp://host:8786) or local:N for a LocalCluster of N workers")
    sw.add_argument("--no-estimate", action="store_true",
                    help="skip each point's error estimates (as `femadh run --no-estimate`); "
                         "a later run with estimates runs such points again")
    sw.add_argument("--quantity", default="max_adhesion_N",
                    help="the number the figure shows (default max_adhesion_N)")
    sw.add_argument("--no-figures", action="store_true", help="skip study.png")
    sw.add_argument("--quiet", action="store_true", help="no progress bar")
    cv = ss.add_parser("convergence", allow_abbrev=False,
                       help="FE mesh ladder vs Green, Green in N",
                       description="The FE mesh ladder against the Green function on the "
                                   "scene's nodes, and the Green function in N; writes "
                                   "convergence.csv/.md/.png.")
    cv.add_argument("scene", help="scene file (TOML)")
    cv.add_argument("--levels", type=int, default=3, help="FE mesh levels (1-4, default 3)")
    cv.add_argument("--out", help="output folder (default: <scene output dir>/study)")
    rg = sub.add_parser(
        "regime", allow_abbrev=False, help="smooth-sphere LJ adhesion map vs the Tabor parameter",
        description="Trace the force-separation curve of a smooth elastic sphere with LJ "
                    "surface forces (no sigma-gap) through its folds for a range of Tabor "
                    "parameters mu = (R dg^2/(E*^2 z0^3))^(1/3); writes regime.csv (pull-off / "
                    "pi R dg vs Maugis-Dugdale, jump-in/out d / z0, hysteresis), "
                    "regime_map.png and regime_curves.png.")
    rg.add_argument("--mu", type=float, nargs=2, default=(0.01, 5.0), metavar=("FROM", "TO"),
                    help="Tabor parameter range (default 0.01 5: under a minute; up to 20 works, "
                         "the points above 5 take minutes each)")
    rg.add_argument("--accuracy", type=float, default=1e-3,
                    help="relative accuracy of every point's pull-offs, jumps and hysteresis "
                         "(default 1e-3; 0: the fixed default spacing, whose error estimates "
                         "are unreliable for mu >= 2)")
    rg.add_argument("--points", type=int, default=20, help="log-spaced points (default 20)")
    rg.add_argument("--radius", default="1 um", help="sphere radius (default '1 um')")
    rg.add_argument("--hamaker", default="1e-19 J", help="Hamaker constant (default '1e-19 J')")
    rg.add_argument("--z0", default="0.165 nm", help="LJ equilibrium distance (default "
                                                     "'0.165 nm')")
    rg.add_argument("--out", default="out/regime", help="output folder (default out/regime)")
    from .cli_data import add_parsers   # compare, fit: measured force curves
    add_parsers(sub)
    from . import cli_topography

    cli_topography.add_parser(sub)
    return p


def _error(msg):
    for line in str(msg).splitlines() or [""]:
        print(f"femadh: error: {line}", file=sys.stderr)


def main(argv=None):
    """Entry point; returns the exit code.

    Run as the ``femadh`` program (``python -m femadh``, the ``femadh`` script: no ``argv``
    given), the process is femadh's own: ``femadh run`` draws its figures in a worker process
    (:mod:`femadh.runner.figures`) and ends the process as soon as it is done, without the
    interpreter's teardown of every module and array (~0.1 s of CPU after a run, ~10 % of a
    Fig 3 run without figures): every file is closed by then (the csv logs are unbuffered,
    the rest written whole and renamed), the figure worker reaped, stdout and stderr
    flushed. Called with ``argv`` (a script, a test) it forks nothing and returns."""
    program = argv is None and _as_program()
    code = _main(argv, program)
    if program:
        # the command has ended: a Ctrl-C or SIGTERM now (the interpreter's teardown) is one
        # line too, with the command's own exit code
        _STOP_WHEN[0] = f"while exiting; the command had ended (exit code {code})".encode()
        _STOP_CODE[0] = code
        if signal.getsignal(signal.SIGINT) is signal.default_int_handler:
            signal.signal(signal.SIGINT, _stop_at_once)
        # (_main set it from femadh.interrupt, imported then: no import here, whose time
        # would be one more moment for a SIGTERM to escape as a Terminated)
        if signal.getsignal(signal.SIGTERM) is getattr(sys.modules.get("femadh.interrupt"),
                                                       "raise_terminated", _stop_at_once):
            signal.signal(signal.SIGTERM, _stop_at_once)
    if program and sys.argv[1:2] == ["run"]:
        _exit_now(code)
    return code


def _exit_now(code):
    """End the process with ``code`` at once (see :func:`main`)."""
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError):
            pass
    if "logging" in sys.modules:
        sys.modules["logging"].shutdown()       # (what its atexit hook would do)
    os._exit(code if isinstance(code, int) else 0 if code is None else 1)


def _main(argv, program=False):
    try:
        if signal.getsignal(signal.SIGINT) is _stop_at_once:
            # from here a Ctrl-C is a KeyboardInterrupt, taken below (or, in a run, deferred
            # to its next safe point by femadh.interrupt)
            signal.signal(signal.SIGINT, signal.default_int_handler)
        if signal.getsignal(signal.SIGTERM) is _stop_at_once:
            # SIGTERM likewise: raised as a KeyboardInterrupt (Terminated), taken below, so
            # that what the command has begun (a study's folder claimed) is undone on the way
            # out; a run's own handlers replace it while it runs
            from .interrupt import raise_terminated

            signal.signal(signal.SIGTERM, raise_terminated)
        args = _parser().parse_args(argv)
        args.program = program
        from ._threads import blas_threads

        with blas_threads():
            return _dispatch(args)
    except SceneError as exc:
        _error(exc)
        return EXIT_SCENE
    except DependencyError as exc:
        _error(exc)
        return EXIT_DEPENDENCY
    except OutputError as exc:
        _error(exc)
        return EXIT_OUTPUT
    except Interrupted as exc:
        _error(f"{exc}; nothing was being written")
        return exc.exit_code
    except KeyboardInterrupt as exc:
        # (outside a run's safe points: its imports, the scene's checks, another command; a
        # SIGTERM there is a KeyboardInterrupt too: femadh.interrupt.Terminated)
        if os.environ.get("FEMADH_DEBUG"):
            raise
        _error(f"interrupted by {_signal_name(exc)}")
        return _signal_code(exc)
    except FemadhError as exc:
        _error(exc)
        return EXIT_SOLVE
    except MemoryError:
        _error("out of memory: reduce [solver] nodes or the sweep (femadh check estimates the "
               "memory a scene needs)")
        return EXIT_SCENE
    except BrokenPipeError:
        # the reader of stdout went away (``| head``): nothing more to say to it; stdout is
        # pointed at /dev/null so that the last flush at exit does not fail again
        try:
            devnull = os.open(os.devnull, os.O_WRONLY)
            os.dup2(devnull, sys.stdout.fileno())
        except (OSError, ValueError):
            pass
        return EXIT_PIPE
    except Exception as exc:     # a bug: one line, the traceback on request
        if os.environ.get("FEMADH_DEBUG"):
            raise
        _error(f"internal error {type(exc).__name__}: {exc} (a bug in femadh; run with "
               "FEMADH_DEBUG=1 for the traceback and please report it)")
        return EXIT_BUG


def _signal_name(exc):
    """The signal behind a KeyboardInterrupt: SIGTERM for femadh.interrupt.Terminated."""
    return "SIGTERM" if getattr(exc, "signum", signal.SIGINT) == signal.SIGTERM else "SIGINT"


def _signal_code(exc):
    """Its exit code: 130 SIGINT, 143 SIGTERM (as a run stopped by it)."""
    return getattr(exc, "exit_code", 128 + signal.SIGINT)


def _dispatch(args):
    if args.command in ("compare", "fit"):
        from .cli_data import dispatch
        return dispatch(args)
    if args.command == "keys":
        from .scene import reference_page

        print(reference_page())
        return 0
    if args.command == "regime":
        return _regime(args)
    if args.command == "render":
        return _render(args)
    if args.command == "topography":
        from . import cli_topography

        return cli_topography.main(args)
    from .scene import load_scene
    from .scene.resources import check_resources

    scene = load_scene(args.scene)
    check_resources(scene)
    first = None
    if args.command in ("check", "run"):
        from .scene.resources import check_cost

        if scene.kind == "contact" and getattr(scene, "adaptive", False):
            from .runner.adaptive import planned_first_nodes

            first = planned_first_nodes(scene)
        # a scene whose cost is beyond reason is refused before it starts
        check_cost(scene, force=args.force, first_nodes=first)
    if args.command == "check":
        return _check(scene, args.scene, first)
    if args.command == "mesh":
        _require_contact(scene, "mesh")
        return _mesh(scene, args.out)
    if args.command == "study" and args.kind == "sweep":
        return _sweep(scene, args)
    if args.command == "study":
        _require_contact(scene, "study convergence")
        return _study(scene, args)
    return _run(scene, args)


def _require_contact(scene, what):
    if scene.kind != "contact":
        raise SceneError(scene.path, "meniscus", "(a meniscus scene)",
                         f"a contact scene: `femadh {what}` works on the elastic half-space "
                         "of a contact scene")


def _check(scene, path, first=None):
    if scene.kind == "meniscus":
        from .scene.resources import _hms, meniscus_time

        n = len(scene.liquids) * len(scene.radii) * len(scene.methods) * len(scene.p_ratios)
        print(f"{path}: ok (meniscus: {len(scene.liquids)} liquids, {len(scene.radii)} radii, "
              f"{len(scene.p_ratios)} p/psat, methods {', '.join(scene.methods)}: {n} solves, "
              f"about {_hms(meniscus_time(scene)[0])} at rates measured on a 2-core machine)")
        return 0
    from .scene.resources import _hms, memory_estimate, time_estimate

    mem, _ = memory_estimate(scene)
    t, what = time_estimate(scene, first and first[0])
    # an adaptive scene's node count is femadh's to choose: its default 'nodes' is not run
    grid = (f"adaptive grid to accuracy {scene.target_accuracy:g}" if scene.adaptive else
            "banded grid" if scene.grid is not None else f"{scene.nodes} nodes")
    print(f"{path}: ok ({len(scene.d_values)} separations, {', '.join(scene.directions)}, "
          f"{grid}, {scene.method}, ~{mem / 2**20:.0f} MiB, "
          f"{'' if t < 1 else '~'}{_hms(t)} with "
          f"its error estimate: {what}, at rates measured on a 2-core machine; folds and "
          "jumps can take up to ~10x more)")
    return 0


def _run(scene, args):
    import shlex

    from .runner.run import run

    out = args.out or scene.output_dir
    if args.resume_from is not None and args.resume_from < 0:
        raise SceneError("command line", "--resume-from", args.resume_from, "an integer >= 0")
    limit = None
    if args.time_limit is not None:
        from .units import to_si

        limit = to_si(args.time_limit, "time", file="command line", key="--time-limit")
        if not limit > 0:
            raise SceneError("command line", "--time-limit", args.time_limit,
                             "a positive duration such as '10 min'")
    from .runner.figures import figure_worker

    # a contact run's figures are drawn by a worker that gets ready while the run solves
    with figure_worker(enabled=getattr(args, "program", False) and not args.no_figures
                       and scene.kind == "contact"):
        res = run(scene, out, figures=not args.no_figures,
                  progress=False if args.quiet else None, overwrite=args.overwrite,
                  resume=args.resume, estimate="peak" if args.no_estimate else True,
                  time_limit=limit, resume_from=args.resume_from)
    for w in getattr(res, "warnings", ()):
        if w.startswith("resume: "):
            print(f"femadh: note: {w}", file=sys.stderr)
    if not args.quiet:
        try:
            _report(res)
        except KeyboardInterrupt as exc:
            # the run has ended: say so, not just "interrupted" (a stopped run goes on to
            # say how to continue it)
            if res.status not in ("interrupted", "time limit"):
                where = f" and its results are in {res.out_dir}" if res.out_dir else ""
                _error(f"interrupted by {_signal_name(exc)} while printing the report; the "
                       f"run had ended ({res.status}){where}")
                return _signal_code(exc)
    if res.status in ("interrupted", "time limit"):
        # the command that continues it, as typed (pasted, it resumes this very folder)
        again = ["femadh", "run", args.scene, "--out", str(out), "--resume"] + [
            f for f, on in (("--no-figures", args.no_figures),
                            ("--no-estimate", args.no_estimate), ("--quiet", args.quiet),
                            ("--force", args.force)) if on]
        _error(f"{res.error}: the states computed before it are kept in {res.out_dir}; "
               f"`{shlex.join(again)}` continues the run")
        return res.exit_code
    if res.status != "converged":
        _error(f"{res.error}; " + (f"what was computed before it is kept in {res.out_dir}"
                                   if res.out_dir else "nothing was computed"))
        return EXIT_SOLVE
    return 0


def _report(res):
    if res.kind == "meniscus":
        from .runner.meniscus import report_lines

        for line in report_lines(res):
            print(line)
        for e in res.errors[:5]:
            print(f"femadh: note: no meniscus for {e['liquid']} R = {e['tip_radius_m']:g} m "
                  f"{e['method']} at p/psat = {e['p_ratio']:g}: {e['error']}", file=sys.stderr)
        print(f"results in {res.out_dir} ({res.wall_time:.2f} s)")
        return
    from .runner.report import headline_lines

    for line in headline_lines(res):
        print(line)
    figs = res.timings.get("figures_s")
    if res.out_dir is None:
        return                      # refused before its first grid: the error says why
    print(f"results in {res.out_dir} (run {res.wall_time:.2f} s"
          + (f", figures {figs:.2f} s)" if figs is not None else ")"))


def _study(scene, args):
    from .studies.convergence import convergence, default_progress, write_convergence

    if not 1 <= args.levels <= 4:
        raise SceneError("command line", "--levels", args.levels, "an integer from 1 to 4")
    rows = convergence(scene, levels=args.levels, progress=default_progress())
    path = write_convergence(rows, args.out or f"{scene.output_dir}/study", scene.name)
    print(path.read_text())
    return 0


def _sweep(scene, args):
    from .studies.sweep import _indices, failure_reasons, finished, run_study

    vary = {}
    for item in args.vary:
        if "=" not in item:
            raise SceneError("command line", "--vary", item, "KEY=VALUES, e.g. "
                             "effects.asperity_gap.sigma='0.5 nm,1 nm'")
        k, v = item.split("=", 1)
        vary[k.strip()] = v
    zip_ = args.zip
    if not vary and scene.study:
        vary, zip_ = scene.study["vary"], scene.study["zip"] or args.zip
    if args.workers is not None and args.workers < 1:
        raise SceneError("command line", "--workers", args.workers, "an integer >= 1")
    out = args.out or f"{scene.output_dir}/study"
    try:
        study = run_study(scene, vary, out, zip_=zip_, workers=args.workers,
                          scheduler=args.scheduler,
                          progress=not args.quiet and sys.stderr.isatty(),
                          quantity=args.quantity,
                          estimate="peak" if args.no_estimate else True,
                          figures=not args.no_figures,
                          source="--vary" if args.vary else None)
    except Interrupted as exc:
        st = exc.study
        kept = sum(finished(r) for r in st.records.values())
        left = getattr(st, "remaining", len(st.points) - kept)
        _error(f"study {exc}: {len(st.points) - left} of {len(st.points)} points finished and "
               f"kept in {out} (study.csv); "
               + (f"run the same command again to compute the other {left}" if left else
                  "none is left to compute" + ("" if args.no_figures else
                                               " (the same command again draws study.png)")))
        return exc.exit_code
    n, failed = len(study.points), study.failed
    for note in study.notes:
        print(f"femadh: note: {note}", file=sys.stderr)
    print(f"{n} points ({n - len(failed)} converged, {len(failed)} failed; reused "
          f"{study.reused}, redone {study.redone}, new {study.new}) in {out}: study.csv"
          + (", study.png" if study.figure else "") + ", points/<id>/")
    if failed:
        _error(f"{len(failed)} of {n} points failed:")
        for reason, idx in failure_reasons(failed):
            _error(f"  {len(idx)} point{'s' if len(idx) > 1 else ''} ({_indices(idx)}): "
                   f"{reason}")
        if study.figure is None and len(failed) == n and not args.no_figures:
            _error("no figure: every point failed (study.csv has each point's reason)")
        return EXIT_SOLVE
    return 0


def _regime(args):
    import numpy as np

    from .studies.convergence import default_progress
    from .studies.regime import regime_map, write_regime
    from .units import to_si

    lo, hi = args.mu
    if not (0 < lo < hi):
        raise SceneError("command line", "--mu", list(args.mu), "0 < FROM < TO")
    if args.points < 1:
        raise SceneError("command line", "--points", args.points, "an integer >= 1")
    if not (0 <= args.accuracy <= 0.1):
        raise SceneError("command line", "--accuracy", args.accuracy, "a number in [0, 0.1]")
    kw = {k: to_si(getattr(args, a), dim, file="command line", key=f"--{a}")
          for k, a, dim in (("radius", "radius", "length"), ("hamaker", "hamaker", "energy"),
                            ("z0", "z0", "length"))}
    from .io.run_folder import RunFolder

    # claim the folder first: a read-only or occupied --out fails before the map is computed
    with RunFolder(args.out, "regime", "regime", "overwrite"):
        mus = np.geomspace(lo, hi, args.points) if args.points > 1 else [lo]
        say = default_progress()
        pts = regime_map(mus, progress=(lambda i, p: say(
            f"mu = {p.mu:.3g}: pull-off {p.pull_off:.4f} pi R dg ({i + 1}/{len(mus)})"))
            if say else None, accuracy=args.accuracy or None, **kw)
        path = write_regime(pts, args.out)
    from .studies.regime import regime_table

    # people get the short table; every column (errors, grids, timings) is in the csv
    print(regime_table(pts))
    print(f"results in {args.out}: {path.name} (every column), regime_map.png, "
          f"regime_curves.png ({sum(p.wall_time for p in pts):.1f} s)")
    return 0


def _render(args):
    from .io.render import render_run

    png = render_run(args.run_dir, state=args.state, field=args.field, png=args.png)
    print(f"rendered {png}")
    return 0


def _mesh(scene, out):
    from pathlib import Path

    import numpy as np

    from .elastic import RadialGrid
    from .elastic.fe import FESettings, mesh_spec
    from .elastic.fe.mesh import cached_mesh, read_mesh
    from .io.atomic import save_atomic

    import meshio
    import shutil

    st = scene.fe_settings or FESettings()
    grid = RadialGrid.uniform(scene.analysis_radius, scene.nodes)
    spec = mesh_spec(grid, st)
    out = Path(out or scene.output_dir)
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise OutputError(f"cannot create the output folder {out}: {exc.strerror}") from None
    if not os.access(out, os.W_OK):
        raise OutputError(f"output folder {out} is not writable")
    src = cached_mesh(spec, progress=lambda m: print(m, file=sys.stderr))
    save_atomic(out / "mesh.msh", lambda p: shutil.copy(src, p))
    p, tri = read_mesh(src, scale=grid.radius)
    pts = np.column_stack([p, 0 * p[:, 0]])
    save_atomic(out / "mesh.vtu",
                lambda f: meshio.write(f, meshio.Mesh(pts, [("triangle", tri)]),
                                       file_format="vtu"))
    print(f"{len(p)} vertices, {len(tri)} triangles; mesh {spec.key()} -> {out / 'mesh.msh'} "
          f"(cached at {src})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
