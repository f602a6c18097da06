"""Parameter studies: one scene, some of its keys varied, every point a validated scene, run in
parallel on this machine (a process pool) or on a Dask cluster, written atomically under the
point's content hash, resumable.

    femadh study sweep SCENE --vary effects.asperity_gap.sigma="0.3 nm..2 nm:10" \\
                             --vary effects.capillary.relative_pressure="0.05..0.95:10" \\
                             --out out/stiction-map [--zip] [--workers N | --scheduler ADDR]

The values' grammar is :mod:`femadh.scene.values` (quantities with their unit, as in a
file); the product of all ``--vary`` by default, paired with ``--zip``. The same in a scene
file::

    [study]
    vary = { "effects.asperity_gap.sigma" = "0.3 nm..2 nm:10", "sphere.radius" = "1 um,2 um" }
    zip = false

Every point goes through the scene's own validation before anything runs (an invalid value
names the point, the key and the value; the same reason at many points is one line). A
point's result is ``points/<id>/`` (its curve and summary, as a single run writes them) and
``points/<id>/record.json``, which says whether the point *finished* (converged, or failed for
a physical reason; see :mod:`femadh.studies.executors`). Running the same study again reuses
the finished points, runs the interrupted or crashed ones again ("redone") and the others
("new"). The study's table ``study.csv`` (:mod:`femadh.io.study_table`) is rewritten as points
finish, its figure at the end. Workers keep the surface operator of each distinct body and
discretisation (:func:`femadh.studies.executors.worker_operator`).
"""
from dataclasses import dataclass, field
import itertools
import json
from pathlib import Path
import time

from .._version import code_id
from ..errors import Interrupted, SceneError
from ..io.atomic import write_atomic
from ..io.progress import StudyProgress
from ..io.study_table import study_figure, write_table
from .executors import (ESTIMATE_NAMES, HEADLINE, OPERATOR_CACHE, _jsonable,  # noqa: F401
                        tune_malloc, _worker_init, driver_signals, execute, finished,
                        run_point, write_record)
from ..scene.values import mask_numbers, parse_values  # noqa: F401  (public here since 1.0)


@dataclass(frozen=True)
class Point:
    """One point of a study: its number, its changes (dotted key -> value as written), the
    validated scene and its content id."""

    index: int
    changes: dict
    scene: object
    id: str


@dataclass
class StudyRun:
    """What :func:`run_study` did: the points, their records (id -> record), and how many
    points it ``reused`` (finished before), ``redone`` (a record that had not finished:
    interrupted, a worker died, a fault) and ran ``new``. Unpacks as ``points, records``."""

    points: list
    records: dict
    reused: int = 0
    redone: int = 0
    new: int = 0
    figure: object = None
    wall_time_s: float = 0.0
    failed: list = field(default_factory=list)
    notes: list = field(default_factory=list)

    def __iter__(self):
        return iter((self.points, self.records))


def study_points(scene, vary, *, zip_=False, source=None):
    """Every point of a study, validated. ``vary`` maps dotted keys to value specs.

    Raises
    ------
    SceneError
        After checking every point: one line per distinct reason (the same reason at many
        points, e.g. a bare number for a length at every value of a range, is one line
        naming the key, the value, what was expected and how many points it concerns). A
        varied key's error names where its values came from, ``source`` (e.g. the command
        line's "--vary"; default: the scene file, whose [study] table gave them).
    """
    if not vary:
        raise SceneError(scene.path, "study.vary", vary, "at least one key to vary: "
                         "--vary KEY=VALUES on the command line (e.g. --vary "
                         "effects.asperity_gap.sigma='0.5 nm,1 nm') or a [study] table with "
                         "vary in the scene")
    keys = list(vary)
    lists = [parse_values(vary[k], k) for k in keys]
    if zip_:
        if len({len(v) for v in lists}) > 1:
            raise SceneError(scene.path, "study.zip", True, "lists of equal length to pair "
                             f"(lengths {[len(v) for v in lists]})")
        combos = list(zip(*lists))
    else:
        combos = list(itertools.product(*lists))
    from ..scene import replace_scene, scene_id

    # a varied value's error names where it came from: ``source`` (the command line), or the
    # scene file whose [study] table gave it
    where = (lambda key: f"{source} {key}") if source else (scene.path or "study")
    points, groups = [], {}
    for i, combo in enumerate(combos):
        changes = dict(zip(keys, combo))
        try:
            sc = replace_scene(scene, changes, {}, False, where)
        except SceneError as exc:
            for e in getattr(exc, "errors", [exc]):
                groups.setdefault((e.key, mask_numbers(e.expected)), []).append((i, e))
            continue
        points.append(Point(i, changes, sc, scene_id(sc)))
    if groups:
        lines = []
        for errs in groups.values():
            idx = [i for i, _ in errs]
            where = (f"point {idx[0]}" if len(idx) == 1 else
                     f"{len(idx)} of {len(combos)} points ({_indices(idx)})")
            lines.append(f"{errs[0][1]} [{where}]")
        first = next(iter(groups.values()))[0][1]
        exc = SceneError(first.file, first.key, first.value, first.expected)
        exc.args = ("\n".join(lines),)         # one line per distinct reason
        raise exc
    return points


def _indices(idx):
    """'0-4, 7' for [0, 1, 2, 3, 4, 7]."""
    out, start = [], idx[0]
    for a, b in zip(idx, idx[1:] + [None]):
        if b != a + 1:
            out.append(f"{start}" if start == a else f"{start}-{a}")
            start = b
    return ", ".join(out)


#: the estimate modes in increasing order of what a point's record holds
_ORDER = ("none", "peak", "errors")


def point_estimate(rec):
    """What a finished point's run estimated: its record's ``estimate`` ("errors", "peak" or
    "none", :data:`~femadh.studies.executors.ESTIMATE_NAMES`). A record of an earlier femadh
    (no such field) counts as "errors" when it holds an estimated error or a meniscus force
    (meniscus runs always estimate it), else as "none": not knowing, it is never taken for
    more than it shows."""
    if rec.get("estimate") in _ORDER:
        return rec["estimate"]
    # (a meniscus run has always estimated its force's error, recorded or not)
    return ("errors" if any(k.endswith("_error") or k.startswith("max_force_N[")
                            for k in rec) else "none")


def serves(rec, estimate):
    """Whether a finished point's record serves a study run with ``estimate`` (True, "peak",
    False): it estimated at least as much (a point with error estimates serves a run that
    asks for none, its errors then shown in the table as computed; never the other way)."""
    return _ORDER.index(point_estimate(rec)) >= _ORDER.index(ESTIMATE_NAMES[estimate])


def _label(changes):
    return ", ".join(f"{k} = {v}" for k, v in changes.items())


def run_study(scene, vary, out_dir, *, zip_=False, workers=None, scheduler=None,
              progress=None, quantity="max_adhesion_N", estimate=True, figures=True,
              source=None):
    """Run a study.

    Parameters
    ----------
    scene : Scene or MeniscusScene
        The base scene.
    vary : dict
        Dotted keys -> value specs (:func:`femadh.scene.values.parse_values`).
    out_dir : str or Path
        The study folder; its finished points are reused.
    workers : int, optional
        Local processes (default: the CPU count).
    scheduler : str, optional
        A dask.distributed address ("tcp://host:port") or "local:N" for a LocalCluster of N
        workers.
    progress : bool, optional
        A bar with the points done / failed / reused (the CLI: only in a terminal).
    estimate : bool or "peak"
        What each point's run estimates (``femadh.run``'s ``estimate``; "peak" is the command
        line's --no-estimate). Each point's record says it; a finished point is reused only
        when it estimated at least as much (:func:`serves`), else it is run again.
    figures : bool
        Draw study.png (False: the command line's --no-figures; its points draw none either
        way).
    source : str, optional
        Where ``vary`` came from, for its values' errors (:func:`study_points`).

    Returns
    -------
    StudyRun
        Unpacks as ``points, records``. A failed point is recorded with its error and never
        stops the study.

    Raises
    ------
    Interrupted
        SIGINT/SIGTERM to this process: the workers are stopped, every finished point is
        kept (and in study.csv); running the study again computes the rest.
    """
    points = study_points(scene, vary, zip_=zip_, source=source)
    out = Path(out_dir)
    from ..io.run_folder import RunFolder

    # the lock: one driver per study folder (a folder of a single run is refused); records are
    # keyed by the points' content hashes, so a folder reused by another study reuses only
    # identical points
    with RunFolder(out, "study", scene.name, "new"):
        _remove_stale_temporaries(out)
        old = _load_records(out)
        ids = {p.id for p in points}
        done = {k: r for k, r in old.items() if finished(r) and k in ids}
        # a point finished by other code (another femadh, or this one edited) is run again:
        # a study never mixes results of two versions of the solver
        other = {k for k, r in done.items() if r.get("femadh") != code_id()}
        # a point finished without the estimates this run asks for is run again with them
        short = {k for k, r in done.items() if k not in other and not serves(r, estimate)}
        done = {k: r for k, r in done.items() if k not in short and k not in other}
        todo = [p for p in points if p.id not in done]
        result = StudyRun(points, dict(done), reused=len(done),
                          redone=sum(p.id in old for p in todo),
                          new=sum(p.id not in old for p in todo))
        if other:
            result.notes.append(f"{len(other)} finished point{'s' * (len(other) > 1)} "
                                f"computed by other femadh code run again (this code: "
                                f"{code_id()})")
        if short:
            old_femadh = any("estimate" not in old[k] for k in short)
            what = ("without error estimates (--no-estimate"
                    f"{' or an earlier femadh' * old_femadh}) run again with them"
                    if estimate is True else "without their peak located run again with it")
            result.notes.append(f"{len(short)} finished point{'s' * (len(short) > 1)} "
                                f"computed {what}")
        write_atomic(out / "study.json", json.dumps(
            {"scene_file": scene.path, "scene": scene.name, "vary": vary, "zip": zip_,
             "estimate": ESTIMATE_NAMES[estimate],
             "points": [{"index": p.index, "id": p.id, "changes": p.changes}
                        for p in points]}, indent=1, default=_jsonable) + "\n")
        bar = StudyProgress(len(points), result.reused, scene.name) if progress else None
        t0 = time.perf_counter()
        try:
            with driver_signals() as stop:
                for rec in execute(todo, out, workers, scheduler, estimate, stop,
                                   result.notes):
                    result.records[rec["id"]] = rec
                    if bar is not None:
                        bar.point(rec)
                    write_table(points, result.records, out)
                if stop:
                    # a signal whose stop found every point finished (the last one as it
                    # came): still a stop, every point kept - it was lost (exit 0, as if
                    # unsent), where a run ends "interrupted" at its last check
                    raise Interrupted(stop[0])
        except (Interrupted, KeyboardInterrupt) as exc:
            # what finished is on disk (records are written by the workers): the table too
            result.records.update({k: r for k, r in _load_records(out).items() if k in ids})
            write_table(points, result.records, out)
            _timing(out, result, t0)
            # the CLI says how many points are kept and how many the next run computes (a
            # finished record of other code, or without the estimates asked for, is run
            # again: not kept)
            result.remaining = sum(
                not (finished(r) and r.get("femadh") == code_id() and serves(r, estimate))
                for r in (result.records.get(p.id, {}) for p in points))
            exc.study = result
            raise
        finally:
            if bar is not None:
                bar.close()
        for p in todo:
            if p.id not in result.records or not _outcome(result.records[p.id]):
                # an executor that ends without a point's outcome is a fault, never a row
                # silently missing from the table: the point fails, unfinished (run again)
                rec = {"id": p.id, "index": p.index, "changes": p.changes,
                       "status": "failed", "finished": False,
                       "error": "the study's executor ended without running this point"}
                write_record(out / "points" / p.id, rec)
                result.records[p.id] = rec
        write_table(points, result.records, out)
        result.figure = (study_figure(points, result.records, out, quantity) if figures
                         else None)
        result.failed = [result.records[p.id] for p in points
                         if result.records.get(p.id, {}).get("status") != "converged"]
        _timing(out, result, t0)
    return result


def _outcome(rec):
    """Whether a record holds an outcome (not a point still "running" or "interrupted"): a
    point stopped by its own time limit has one ("time limit", run again to continue it)."""
    return rec.get("status") in ("converged", "failed", "time limit")


def _timing(out, result, t0):
    result.wall_time_s = time.perf_counter() - t0
    write_atomic(Path(out) / "timing.json", json.dumps(
        {"points": len(result.points), "computed": result.redone + result.new,
         "reused": result.reused, "redone": result.redone, "new": result.new,
         "wall_time_s": result.wall_time_s}) + "\n")


def _remove_stale_temporaries(out):
    """Remove the temporary files a killed worker left in the points' folders (each file is
    written to ``.NAME.XXXX.tmp`` and renamed into place, femadh.io.atomic; a kill -9 between
    the two leaves it). Called with the study's lock held and before any worker starts; a
    point's folder whose run lock is held (a worker orphaned by a killed driver, still
    running its point - found by a review) is left alone."""
    import fcntl
    import os

    from ..io.run_folder import LOCK

    pts = Path(out) / "points"
    if not pts.exists():
        return
    for folder in sorted({f.parent for f in pts.glob("*/.*.tmp")}):
        # a worker orphaned by a killed driver may still be writing in its point's folder:
        # it holds that folder's run lock, and its files are left alone
        fd = None
        try:
            if (folder / LOCK).exists():
                fd = os.open(folder / LOCK, os.O_RDONLY)
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            for f in folder.glob(".*.tmp"):
                f.unlink()
        except OSError:
            pass                # (held by a live writer, or gone already: left as it is)
        finally:
            if fd is not None:
                os.close(fd)


def _load_records(out):
    recs = {}
    pts = Path(out) / "points"
    if pts.exists():
        for f in pts.glob("*/record.json"):
            try:
                rec = json.loads(f.read_text())
            except (OSError, ValueError):
                continue            # a damaged record: the point is run again
            if isinstance(rec, dict) and "id" in rec:
                recs[rec["id"]] = rec
    return recs


def failure_reasons(records):
    """The failed points grouped by reason: ``[(reason, [indices])]``, most frequent first
    (reasons differing only in their numbers, e.g. the separation a solve failed at, are
    one group, shown by its first instance)."""
    groups = {}
    for r in sorted(records, key=lambda r: r.get("index", 0)):
        reason = r.get("error") or r.get("status", "failed")
        groups.setdefault(mask_numbers(reason), [reason, []])[1].append(r.get("index"))
    return sorted(((g[0], g[1]) for g in groups.values()), key=lambda g: -len(g[1]))
