"""Parameter studies: one scene, some of its keys varied, every point a validated scene, run in
parallel on this machine (a process pool) or on a Dask cluster, written atomically under the
point's content hash, resumable.

    femadh study sweep SCENE --vary effects.asperity_gap.sigma="0.3 nm..2 nm:10" \\
                             --vary effects.capillary.relative_pressure="0.05..0.95:10" \\
                             --out out/stiction-map [--zip] [--workers N | --scheduler ADDR]

Values: a comma list with units (``"0.5 nm,1 nm,2 nm"``), a linear range ``"lo..hi:n"``, or a
log range ``"lo..hi:n:log"`` (the unit of ``lo`` applies to ``hi`` when ``hi`` has none). The
product of all ``--vary`` by default, paired with ``--zip``. The same in a scene file::

    [study]
    vary = { "effects.asperity_gap.sigma" = "0.3 nm..2 nm:10", "sphere.radius" = "1 um,2 um" }
    zip = false

Every point goes through the scene's own validation before anything runs (an invalid value
names the point, the key and the value). A point's result is ``points/<id>/`` (its curve and
summary, as a single run writes them) and ``points/<id>/record.json`` (written last and
atomically: a point with a record is done); the study's table ``study.csv`` (and
``study.parquet`` with pyarrow) and its figure are rewritten as points finish. Running the same
study again computes only the points without a record. Workers keep the surface operator of
each distinct grid/mesh (an FE factorisation is built once per worker, not once per point).
"""
from dataclasses import dataclass
import itertools
import json
import math
import os
from pathlib import Path
import re
import time

import numpy as np

from ..errors import SceneError
from ..io.atomic import write_atomic

#: headline numbers a study's table carries (when the scene kind has them)
HEADLINE = ("max_adhesion_N", "d_at_max_adhesion_m", "jump_in_d_m", "jump_out_d_m",
            "hysteresis_J", "F_LJ_deepest_N", "F_ex_deepest_N", "work_of_adhesion_J_per_m2",
            "instrument_pull_off_N", "instrument_snap_off_N", "instrument_jump_out_z_m",
            "instrument_stuck", "instrument_release_margin_m")
_RANGE = re.compile(r"^\s*(?P<lo>[^.:]+(?:\.\d+)?(?:[eE][-+]?\d+)?[^.:]*?)\s*\.\.\s*"
                    r"(?P<hi>[^:]+?)\s*:\s*(?P<n>\d+)\s*(?::\s*(?P<log>log|lin))?\s*$")


@dataclass(frozen=True)
class Point:
    """One point of a study: its number, its changes (dotted key -> value as written), the
    validated scene and its content id."""

    index: int
    changes: dict
    scene: object
    id: str


def parse_values(spec, key="(value)"):
    """The list of values of one ``--vary`` spec (see the module docstring): strings with
    their unit, or floats for unitless values."""
    if isinstance(spec, list):
        return list(spec)
    if not isinstance(spec, str) or not spec.strip():
        raise SceneError("study", key, spec, "a comma list of values or a range 'lo..hi:n'")
    m = _RANGE.match(spec)
    if m and ".." in spec:
        lo_txt, hi_txt, n = m.group("lo").strip(), m.group("hi").strip(), int(m.group("n"))
        if n < 1:
            raise SceneError("study", key, spec, "a range with at least 1 point")
        lo_v, lo_u = _split(lo_txt, key, spec)
        hi_v, hi_u = _split(hi_txt, key, spec)
        unit = lo_u or hi_u
        if lo_u and hi_u and lo_u != hi_u:
            raise SceneError("study", key, spec, "a range whose ends have the same unit")
        if m.group("log") == "log":
            if lo_v <= 0 or hi_v <= 0:
                raise SceneError("study", key, spec, "a log range of positive values")
            vals = np.geomspace(lo_v, hi_v, n)
        else:
            vals = np.linspace(lo_v, hi_v, n)
        if not unit and _is_int(lo_txt) and _is_int(hi_txt) and m.group("log") != "log" \
                and np.all(vals == np.round(vals)):
            return [int(v) for v in vals]          # an integer key (e.g. solver.nodes)
        # 12 significant digits: 0.45, not linspace's 0.44999999999999996 (a value a user
        # reads in the table and types again)
        return [f"{v:.12g} {unit}" if unit else float(f"{v:.12g}") for v in vals]
    out = []
    for item in spec.split(","):
        item = item.strip()
        if not item:
            continue
        for cast in (int, float):
            try:
                out.append(cast(item))
                break
            except ValueError:
                continue
        else:
            out.append(item)
    if not out:
        raise SceneError("study", key, spec, "at least one value")
    return out


def _is_int(text):
    return re.fullmatch(r"[-+]?\d+", text.strip()) is not None


def _split(text, key, spec):
    m = re.match(r"^\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*(.*)$", text)
    if not m:
        raise SceneError("study", key, spec, "a range of numbers with an optional unit, "
                         "e.g. '0.2 nm..2 nm:10'")
    return float(m.group(1)), m.group(2).strip()


def study_points(scene, vary, *, zip_=False):
    """Every point of a study, validated. ``vary`` maps dotted keys to value specs.

    Raises SceneError naming the point, the key and the value of the first invalid point
    (after checking them all, every invalid point is listed).
    """
    if not vary:
        raise SceneError(scene.path, "study.vary", vary, "at least one key to vary")
    keys = list(vary)
    lists = [parse_values(vary[k], k) for k in keys]
    if zip_:
        if len({len(v) for v in lists}) > 1:
            raise SceneError(scene.path, "study.zip", True, "lists of equal length to pair "
                             f"(lengths {[len(v) for v in lists]})")
        combos = list(zip(*lists))
    else:
        combos = list(itertools.product(*lists))
    from ..scene import scene_id

    points, errors = [], []
    for i, combo in enumerate(combos):
        changes = dict(zip(keys, combo))
        try:
            sc = scene.replace(changes)
        except SceneError as exc:
            errors.append(f"point {i} ({_label(changes)}): {exc}")
            continue
        points.append(Point(i, changes, sc, scene_id(sc)))
    if errors:
        raise SceneError(scene.path, "study", f"{len(errors)} invalid points",
                         "valid values at every point:\n" + "\n".join(errors))
    return points


def _label(changes):
    return ", ".join(f"{k} = {v}" for k, v in changes.items())


# --------------------------------------------------------------------------- workers

_OPERATORS = {}


def _operator_key(sc):
    """Everything :func:`femadh.scene.build_operator` reads, as a string (FESettings and the
    material records are not hashable; repr of a float is exact)."""
    if sc.kind != "contact" or sc.adaptive:
        return None                 # an adaptive run builds the members it chooses
    fe = None
    if sc.method == "fe":
        fe = (sc.fe_settings, sc.fe_poisson_ratio)
        if sc.layers:
            fe += (tuple(sc.layers), sc.disk, sc.slider)
    grid = None if sc.grid is None else sorted(sc.grid.items())
    return repr((sc.method, sc.nodes, grid, sc.analysis_radius, sc.e_star, fe))


def run_point(point, root, estimate=True):
    """Run one point into ``root/points/<id>/`` and return its record (a small dict). Runs in
    a worker: the surface operator of each distinct grid/mesh is built once per process and
    reused. Never raises for a failed solve: the record says what happened."""
    from .._threads import blas_threads
    from ..errors import FemadhError
    from ..runner.contact import run
    from ..scene import build_operator

    _tune_malloc()
    t0 = time.perf_counter()
    folder = Path(root) / "points" / point.id
    rec = {"id": point.id, "index": point.index, "changes": point.changes,
           "status": "failed", "error": None, "operator_reused": False, "pid": os.getpid()}
    import warnings

    from ..errors import MeshResolutionWarning

    try:
        # a point's resolution warnings go into its record (and summary.json), not the
        # terminal of the study
        with blas_threads(), warnings.catch_warnings():
            warnings.simplefilter("ignore", MeshResolutionWarning)
            key = _operator_key(point.scene)
            if key is not None:
                if key in _OPERATORS:
                    rec["operator_reused"] = True
                else:
                    _OPERATORS.clear()          # one operator per worker: bounded memory
                    _OPERATORS[key] = build_operator(point.scene)
                res = run(point.scene, folder, figures=False, progress=False, overwrite=True,
                          operator=_OPERATORS[key], estimate=estimate)
            else:
                res = run(point.scene, folder, figures=False, progress=False, overwrite=True,
                          estimate=estimate)
        rec["status"], rec["error"] = res.status, res.error
        rec["warnings"] = list(getattr(res, "warnings", []))
        rec.update(_numbers(res))
    except FemadhError as exc:
        rec["error"] = f"{type(exc).__name__}: {exc}"
    rec["wall_time_s"] = time.perf_counter() - t0
    folder.mkdir(parents=True, exist_ok=True)
    write_atomic(folder / "record.json", json.dumps(rec, indent=1, default=_jsonable) + "\n")
    return rec


def _numbers(res):
    if res.kind == "meniscus":
        out = {}
        for (liq, R, meth), c in res.curves.items():
            f = c["force_N"]
            if np.any(np.isfinite(f)):
                out[f"max_force_N[{liq},{R:g},{meth}]"] = float(np.nanmax(f))
        return out
    return {k: res.headline[k] for k in HEADLINE if k in res.headline} | {
        f"{k}_error": res.headline[f"{k}_error"] for k in HEADLINE
        if f"{k}_error" in res.headline}


def _jsonable(o):
    if isinstance(o, (np.floating, np.integer)):
        return o.item()
    return str(o)


# --------------------------------------------------------------------------- the study

def run_study(scene, vary, out_dir, *, zip_=False, workers=None, scheduler=None,
              progress=None, quantity="max_adhesion_N", estimate=True):
    """Run a study; returns (points, records). Points with a record in ``out_dir`` are not
    computed again. ``workers``: local processes (default: the CPU count); ``scheduler``:
    a dask.distributed address ("tcp://host:port") or "local:N" for a LocalCluster of N
    workers. A failed point is recorded with its error and never stops the study."""
    points = study_points(scene, vary, zip_=zip_)
    out = Path(out_dir)
    from ..io.run_folder import RunFolder

    # the lock: one driver per study folder (a folder of a single run is refused); records are
    # keyed by the points' content hashes, so a folder reused by another study reuses only
    # identical points
    with RunFolder(out, "study", scene.name, "new"):
        done = _load_records(out)
        todo = [p for p in points if p.id not in done]
        records = dict(done)
        write_atomic(out / "study.json", json.dumps(
            {"scene_file": scene.path, "scene": scene.name, "vary": vary, "zip": zip_,
             "points": [{"index": p.index, "id": p.id, "changes": p.changes}
                        for p in points]}, indent=1, default=_jsonable) + "\n")
        bar = None
        if progress:
            from ..io.progress import bar as make_bar

            bar = make_bar(len(todo), f"study {scene.name}", unit="point")
        t0 = time.perf_counter()
        try:
            for rec in _execute(todo, out, workers, scheduler, estimate):
                records[rec["id"]] = rec
                if bar is not None:
                    bar.update(1)
                write_table(points, records, out)
        finally:
            if bar is not None:
                bar.close()
        write_table(points, records, out)
        study_figure(points, records, out, quantity)
        (out / "timing.json").write_text(json.dumps(
            {"points": len(points), "computed": len(todo),
             "wall_time_s": time.perf_counter() - t0}) + "\n")
    return points, records


def _load_records(out):
    recs = {}
    pts = Path(out) / "points"
    if pts.exists():
        for f in pts.glob("*/record.json"):
            try:
                rec = json.loads(f.read_text())
            except (OSError, ValueError):
                continue
            recs[rec["id"]] = rec
    return recs


def _execute(todo, out, workers, scheduler, estimate=True):
    """Yield the records of the points as they finish, on the chosen executor."""
    if not todo:
        return
    if scheduler:
        yield from _execute_dask(todo, out, scheduler, estimate)
        return
    workers = workers or os.cpu_count() or 1
    if workers == 1:
        for p in todo:
            yield run_point(p, out, estimate)
        return
    from concurrent.futures import ProcessPoolExecutor, as_completed
    import multiprocessing as mp

    from concurrent.futures.process import BrokenProcessPool

    with ProcessPoolExecutor(max_workers=workers, mp_context=mp.get_context("spawn"),
                             initializer=_worker_init) as ex:
        futures = [ex.submit(run_point, p, out, estimate) for p in todo]
        try:
            for f in as_completed(futures):
                yield f.result()
        except BrokenProcessPool:
            from ..errors import FemadhError

            raise FemadhError("a study worker died (killed, or out of memory); every "
                              "completed point is kept: run the study again to compute the "
                              "missing ones") from None


def _worker_init():
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    os.environ.setdefault("OMP_NUM_THREADS", "1")


_MALLOC_TUNED = False


def _tune_malloc():
    """Undo dask's MALLOC_TRIM_THRESHOLD_ for femadh's allocation pattern (once per process).

    A dask nanny starts its workers with MALLOC_TRIM_THRESHOLD_=65536, which also switches
    off glibc's dynamic mmap threshold: every numpy temporary above 128 KiB is then mmap'ed
    and unmapped afresh, page faults included. A stiction-map point ran 45 % slower in a Dask
    worker than in a process of the local pool for that reason (6.0 s -> 8.7-9.4 s with the
    variable set, 6.1 s with the thresholds below). Raising both thresholds by mallopt works
    on any worker, also on a cluster femadh did not start. No-op off glibc."""
    global _MALLOC_TUNED
    if _MALLOC_TUNED:
        return
    _MALLOC_TUNED = True
    if not os.environ.get("MALLOC_TRIM_THRESHOLD_"):
        return                      # glibc's dynamic thresholds are in force: keep them
    try:
        import ctypes

        libc = ctypes.CDLL("libc.so.6")
    except OSError:
        return
    M_TRIM_THRESHOLD, M_MMAP_THRESHOLD = -1, -3
    libc.mallopt(M_MMAP_THRESHOLD, 32 * 1024 * 1024)     # glibc's largest
    libc.mallopt(M_TRIM_THRESHOLD, 256 * 1024 * 1024)


def _execute_dask(todo, out, scheduler, estimate=True):
    try:
        from distributed import Client, LocalCluster, as_completed
    except ImportError:
        from ..errors import DependencyError

        raise DependencyError("a Dask study needs dask.distributed: pip install "
                              "'femadh[study]'") from None
    cluster = None
    if scheduler.startswith("local:"):
        n = int(scheduler.split(":", 1)[1])
        cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                               dashboard_address=None)
        client = Client(cluster)
    else:
        client = Client(scheduler)
    try:
        client.run(_worker_init)
        futures = [client.submit(run_point, p, str(out), estimate, pure=False) for p in todo]
        for f in as_completed(futures):
            yield f.result()
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


def write_table(points, records, out):
    """study.csv (and study.parquet with pyarrow): one row per point, tidy."""
    import csv
    import io

    keys = list(points[0].changes) if points else []
    numbers = sorted({k for r in records.values() for k, v in r.items()
                      if isinstance(v, (int, float)) and not isinstance(v, bool)
                      and k not in ("index", "pid")})
    header = ["index", "id"] + keys + ["status", "error", "operator_reused"] + numbers
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(header)
    rows = []
    for p in points:
        r = records.get(p.id)
        if r is None:
            continue
        row = ([p.index, p.id] + [p.changes[k] for k in keys]
               + [r["status"], r["error"] or "", r.get("operator_reused", "")])
        row += [r.get(k, "") for k in numbers]
        rows.append(row)
        w.writerow(row)
    write_atomic(Path(out) / "study.csv", buf.getvalue())
    try:
        import pyarrow as pa
        import pyarrow.parquet as pq
    except ImportError:
        return
    cols = list(zip(*rows)) if rows else [[] for _ in header]
    table = pa.table({h: [str(v) if i < 2 + len(keys) + 3 else v for v in col]
                      for i, (h, col) in enumerate(zip(header, cols))})
    from ..io.atomic import save_atomic

    save_atomic(Path(out) / "study.parquet", lambda p: pq.write_table(table, p))


def study_figure(points, records, out, quantity="max_adhesion_N"):
    """One varied key: the quantity against it; two: a heat map over both."""
    from ..io.plots import _pyplot, force_unit, length_unit
    from ..io.atomic import save_atomic
    from ..units import to_si

    keys = list(points[0].changes) if points else []
    vals = [(p, records[p.id].get(quantity, math.nan)) for p in points if p.id in records]
    if not vals or len(keys) not in (1, 2):
        return None

    si_unit = {"pressure": "Pa", "energy": "J", "surface_energy": "J/m²",
               "temperature": "K", "areal_density": "1/m²"}

    def parsed(v):
        """(SI value, dimension or None) of a study value."""
        if isinstance(v, (int, float)):
            return float(v), None
        for dim in ("length", "pressure", "energy", "surface_energy", "temperature",
                    "areal_density"):
            try:
                return to_si(v, dim), dim
            except SceneError:
                continue
        return math.nan, None

    def axis(key):
        """{study value: plotted number} and the axis label, in a unit fitting the values."""
        raw = {repr(p.changes[key]): parsed(p.changes[key]) for p, _ in vals}
        dims = {d for _, d in raw.values()}
        scale, unit = 1.0, ""
        if dims == {"length"}:
            scale, unit = length_unit([x for x, _ in raw.values()])
        elif len(dims) == 1 and None not in dims:
            unit = si_unit[dims.pop()]
        label = key.split(".")[-1].replace("_", " ") + (f" ({unit})" if unit else "")
        return {k: x * scale for k, (x, _) in raw.items()}, f"{label}  [{key}]"

    plt = _pyplot()
    y = np.array([v for _, v in vals], float)
    fs, fl = force_unit(y[np.isfinite(y)]) if quantity.endswith("_N") else (1.0, "")
    qlabel = quantity.removesuffix("_N").replace("_", " ") + (f" ({fl})" if fl else "")
    fig, ax = plt.subplots(figsize=(7, 5))
    if len(keys) == 1:
        xmap, xl = axis(keys[0])
        x = np.array([xmap[repr(p.changes[keys[0]])] for p, _ in vals])
        order = np.argsort(x)
        ax.plot(x[order], y[order] * fs, "o-")
        ax.set(xlabel=xl, ylabel=qlabel)
        _verdicts(ax, [(xv, yv * fs, records[p.id].get("instrument_stuck"))
                       for (p, _), xv, yv in zip(vals, x, y)])
        ax.grid(alpha=0.3)
    else:
        (xmap, xl), (ymap, yl) = axis(keys[0]), axis(keys[1])
        xs, ys = sorted(set(xmap.values())), sorted(set(ymap.values()))
        Z = np.full((len(ys), len(xs)), np.nan)
        for (p, v) in vals:
            Z[ys.index(ymap[repr(p.changes[keys[1]])]),
              xs.index(xmap[repr(p.changes[keys[0]])])] = v * fs
        im = ax.pcolormesh(_edges(xs), _edges(ys), Z, shading="flat", cmap="viridis")
        fig.colorbar(im, ax=ax, label=qlabel)
        ax.set(xlabel=xl, ylabel=yl)
        _verdicts(ax, [(xmap[repr(p.changes[keys[0]])], ymap[repr(p.changes[keys[1]])],
                        records[p.id].get("instrument_stuck")) for p, _ in vals])
    ax.set_title("study: " + quantity.removesuffix("_N").replace("_", " "))
    fig.tight_layout()
    path = Path(out) / "study.png"
    save_atomic(path, lambda p: fig.savefig(p, dpi=110))
    plt.close(fig)
    return path


def _verdicts(ax, points):
    """The MEMS verdict of each point (scenes with [instrument] rest_gap): a red cross where
    the part stays stuck, a white circle where its suspension frees it."""
    stuck = [(x, y) for x, y, v in points if v == 1.0]
    free = [(x, y) for x, y, v in points if v == 0.0]
    if stuck:
        ax.plot(*zip(*stuck), "x", color="tab:red", ms=9, mew=2, ls="", label="stuck")
    if free:
        ax.plot(*zip(*free), "o", mfc="white", mec="k", ms=7, ls="", label="frees itself")
    if stuck or free:
        ax.legend(loc="best", fontsize=8)


def _edges(c):
    c = np.asarray(c, float)
    if c.size == 1:
        return np.array([c[0] * 0.9, c[0] * 1.1]) if c[0] else np.array([-0.5, 0.5])
    mid = 0.5 * (c[1:] + c[:-1])
    return np.concatenate([[c[0] - (mid[0] - c[0])], mid, [c[-1] + (c[-1] - mid[-1])]])
