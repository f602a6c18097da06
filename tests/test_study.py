"""Parameter studies: values, validation before anything runs, the local pool and a Dask
LocalCluster give the same records, resume after a kill, light results, the mesh-cache race."""
import json
import os
from pathlib import Path
import pickle
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

import femadh
from conftest import fig3_uniform_text
from femadh.cli import main
from femadh.errors import SceneError
from femadh.studies.sweep import parse_values, run_study, study_points

ROOT = Path(__file__).resolve().parents[1]
FIG3 = ROOT / "validation" / "scenes" / "paper1_fig3.toml"
ENV = dict(os.environ, OPENBLAS_NUM_THREADS="1", PYTHONPATH=str(ROOT))


def _records(out):
    """{point id: finished?} of the point records a study folder holds so far."""
    recs = {}
    for f in Path(out).glob("points/*/record.json"):
        try:
            rec = json.loads(f.read_text())
        except ValueError:
            continue            # (records are written atomically; a race with the glob)
        recs[rec["id"]] = bool(rec.get("finished"))
    return recs


def _running(out):
    """The ids of the points whose record exists but says they have not finished."""
    return {k for k, done in _records(out).items() if not done}


def _finished(out):
    """The ids of the points whose record says they finished."""
    return {k for k, done in _records(out).items() if done}


def study_text():
    """The Fig 3 scene on 60 uniform nodes swept in 0.5-nm steps (15 states a direction):
    the kill and signal tests need points that run and converge, not accuracy; every point
    of their sigma ranges converges (was 0.2-nm steps: each point ~1.7x the cost)."""
    return fig3_uniform_text().replace("nodes = 200", "nodes = 60").replace(
        'step = "0.2 nm"', 'step = "0.5 nm"')


def small():
    return femadh.load_scene(FIG3).replace({"solver.nodes": 60, "sweep.step": "0.5 nm",
                                            "sweep.stop": "-3 nm"})


def test_values_and_points_are_validated_before_anything_runs(tmp_path, capsys):
    assert parse_values("0.2 nm..2 nm:4") == ["0.2 nm", "0.8 nm", "1.4 nm", "2 nm"]
    assert parse_values("1e-3..1e-1:3:log") == pytest.approx([1e-3, 1e-2, 1e-1], rel=1e-12, abs=0)
    assert parse_values("100,200") == [100, 200]
    # a quantity needs its unit on the command line as in a file: bare numbers for a length
    # are refused with the file's error (never 0.8 m), one line for the whole range
    with pytest.raises(SceneError) as exc:
        study_points(small(), {"effects.asperity_gap.sigma": "0.8..1.2:3"})
    assert len(str(exc.value).splitlines()) == 1
    assert "bare number has no unit" in str(exc.value) and "3 of 3 points" in str(exc.value)
    pts = study_points(small(), {"effects.asperity_gap.sigma": "0.5 nm,1 nm",
                                 "sphere.radius": "1 mm,2 mm"})
    assert len(pts) == 4 and len({p.id for p in pts}) == 4
    assert pts[1].scene.sphere.radius == 2e-3 and pts[2].scene.gap.sigma == 1e-9
    # an invalid value names the point, the key and the value; nothing is computed
    assert main(["study", "sweep", str(FIG3), "--vary",
                 "effects.asperity_gap.sigma=1 nm,-2 nm", "--out", str(tmp_path / "s")]) == 2
    err = capsys.readouterr().err
    assert "point 1" in err and "effects.asperity_gap.sigma" in err and "-2 nm" in err
    # ... and where the value came from: the command line, not the scene file (which holds
    # no such value: the newcomer trial was sent to look for it there)
    assert err.startswith("femadh: error: --vary effects.asperity_gap.sigma: ")
    assert not (tmp_path / "s" / "points").exists()
    # nothing to vary (no --vary, no [study] table): the line says how to give it
    assert main(["study", "sweep", str(FIG3), "--out", str(tmp_path / "s")]) == 2
    err = capsys.readouterr().err
    assert "study.vary" in err and "--vary KEY=VALUES" in err and err.count("\n") == 1


def test_two_varied_keys_make_one_point_each_and_a_rerun_computes_nothing(tmp_path):
    """4 points of two varied keys: each converged, its values in SI in study.csv; a rerun
    computes nothing. (That a Dask LocalCluster's and the local pool's workers give the
    numbers of this process to the last digit is the signal tests' check: their study.csv
    equals the in-process reference's cell by cell; this test used to start a LocalCluster
    of its own for it.)"""
    sc, vary = small(), {"effects.asperity_gap.sigma": "0.5 nm,1 nm",
                         "sphere.radius": "1 mm,2 mm"}
    _, here = run_study(sc, vary, tmp_path / "here", workers=1, estimate=False,
                        figures=False)
    assert len(here) == 4 and {r["status"] for r in here.values()} == {"converged"}
    assert not (tmp_path / "here" / "study.png").exists()      # (--no-figures)
    t0 = time.perf_counter()
    run_study(sc, vary, tmp_path / "here", workers=1, estimate=False, figures=False)
    assert json.loads((tmp_path / "here" / "timing.json").read_text())["computed"] == 0
    assert time.perf_counter() - t0 < 5
    rows = _table(tmp_path / "here")
    # the varied values in SI, the unit in the header; the text in the label
    assert len(rows) == 5 and rows[0][:7] == ["index", "id", "label",
                                              "effects.asperity_gap.sigma_m", "sphere.radius_m",
                                              "status", "error"]
    assert rows[1][2:5] == ["effects.asperity_gap.sigma = 0.5 nm, sphere.radius = 1 mm",
                            repr(0.5e-9), repr(1e-3)]
    # a point computed by other femadh code (its record's fingerprint differs) is run again,
    # and the study says so; the others are reused
    from femadh import code_id

    f = sorted((tmp_path / "here").glob("points/*/record.json"))[0]
    rec = json.loads(f.read_text())
    assert rec["femadh"] == code_id()
    rec["femadh"] = "0.2.0+000000000000"
    f.write_text(json.dumps(rec))
    # a temporary file a killed worker left beside a record (written then renamed into
    # place: a kill -9 between the two) is removed by the next run of the study
    stale = f.parent / ".record.json.abc123.tmp"
    stale.write_text("{")
    # ... but not in a point's folder whose run lock is held (a worker orphaned by a killed
    # driver, still writing there)
    import fcntl

    busy = sorted((tmp_path / "here").glob("points/*/record.json"))[1].parent
    (busy / ".summary.json.xyz.tmp").write_text("{")
    fd = os.open(busy / ".femadh.lock", os.O_RDWR | os.O_CREAT)
    fcntl.flock(fd, fcntl.LOCK_EX)
    try:
        again = run_study(sc, vary, tmp_path / "here", workers=1, estimate=False)
    finally:
        os.close(fd)
    assert not stale.exists() and (tmp_path / "here" / "study.png").exists()
    assert (busy / ".summary.json.xyz.tmp").exists()
    timing = json.loads((tmp_path / "here" / "timing.json").read_text())
    assert timing["computed"] == 1 and timing["reused"] == 3
    assert any("computed by other femadh code run again" in n for n in again.notes)
    assert json.loads(f.read_text())["femadh"] == code_id()
    assert _table(tmp_path / "here") == rows


def test_a_signal_as_the_last_point_finishes_still_stops_the_study(tmp_path, monkeypatch,
                                                                   capsys):
    """A SIGINT whose stop flag is raised as the last point's record comes in (every point
    finished, nothing left to stop): the study still ends Interrupted, with every point
    kept and its table written - it ended as if the signal had not been sent (exit 0; found
    by a review), where a run ends "interrupted" at its last check."""
    from femadh.errors import Interrupted
    from femadh.studies import sweep

    real = sweep.execute

    def execute(todo, out, workers, scheduler, estimate, stop, notes):
        yield from real(todo, out, workers, scheduler, estimate, stop, notes)
        stop.append(signal.SIGINT)          # as driver_signals' handler records it
    monkeypatch.setattr(sweep, "execute", execute)
    vary = {"effects.asperity_gap.sigma": "0.5 nm,1 nm"}
    with pytest.raises(Interrupted) as info:
        run_study(small(), vary, tmp_path / "s", workers=1, estimate=False, figures=False)
    assert {r["status"] for r in info.value.study.records.values()} == {"converged"}
    assert len(info.value.study.records) == 2 and len(_table(tmp_path / "s")) == 3
    # the command's line then says nothing is left to compute (not "compute the others")
    assert main(["study", "sweep", str(FIG3), "--vary", "effects.asperity_gap.sigma=0.5 nm,1 nm",
                 "--out", str(tmp_path / "c"), "--workers", "1", "--no-estimate",
                 "--no-figures", "--quiet"]) == 130
    err = capsys.readouterr().err
    assert "2 of 2 points finished" in err and "none is left to compute" in err
    # points finished without the estimates now asked for are run again: not counted kept
    # (a review: "2 of 2 ... none is left" was said of points the next run computes)
    def stopped(todo, out, workers, scheduler, estimate, stop, notes):
        stop.append(signal.SIGINT)
        yield from ()
    monkeypatch.setattr(sweep, "execute", stopped)
    assert main(["study", "sweep", str(FIG3), "--vary", "effects.asperity_gap.sigma=0.5 nm,1 nm",
                 "--out", str(tmp_path / "c"), "--workers", "1", "--quiet"]) == 130
    err = capsys.readouterr().err
    assert "0 of 2 points finished" in err and "compute the other 2" in err


def test_killed_study_loses_no_completed_point(tmp_path):
    scene = tmp_path / "s.toml"
    scene.write_text(study_text())
    out = tmp_path / "study"
    cmd = [sys.executable, "-m", "femadh", "study", "sweep", str(scene), "--vary",
           "effects.asperity_gap.sigma=0.8 nm..2 nm:6", "--out", str(out), "--workers", "1",
           "--quiet", "--no-estimate"]
    p = subprocess.Popen(cmd, cwd=ROOT, env=ENV, stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE)
    t0 = time.time()
    # kill while a point is under way (its record says "running") after one has finished:
    # a kill between two points would leave nothing to redo
    while not (_finished(out) and _running(out)) and time.time() - t0 < 60:
        time.sleep(0.01)
    p.send_signal(signal.SIGKILL)
    p.communicate()
    done = {f.parent.name for f in out.glob("points/*/record.json")
            if json.loads(f.read_text())["finished"]}
    assert 1 <= len(done) < 6
    # the rerun in this process (the same command; no interpreter to start)
    assert main(cmd[3:]) == 0
    timing = json.loads((out / "timing.json").read_text())
    # the point the kill cut short has a record that never finished: it is redone
    assert timing["computed"] == 6 - len(done) and timing["reused"] == len(done)
    assert timing["redone"] >= 1
    assert len(list(out.glob("points/*/record.json"))) == 6


@pytest.mark.slow
def test_results_are_light_and_picklable():
    """A result holds arrays and numbers only: the Fig 4 scene at N = 800 (in contact from
    d = -1 to -3 nm, 11 states a branch, the 12 surface profiles a branch keeps) pickles under
    1 MB (measured 434 kB; its LU factorisations of 169 MB stay in the solver). The error
    estimate's members are left out: they add no field to the result, only 15 s."""
    sc = femadh.load_scene(ROOT / "validation" / "scenes" / "paper1_fig4.toml").replace(
        {"solver.nodes": 800, "sweep.start": "-1 nm", "sweep.stop": "-3 nm"})
    res = femadh.run(sc, progress=False, estimate=False)
    blob = pickle.dumps(res)
    assert len(blob) < 1_000_000
    back = pickle.loads(blob)
    assert np.array_equal(back.curve("approach")["F_ex"], res.curve("approach")["F_ex"])


def test_mesh_cache_is_safe_with_concurrent_writers(tmp_path):
    """Two processes build the same (new) mesh into one cache at once: both end with the
    complete mesh (a unique temporary file each, renamed into place), no temporary left."""
    code = ("import sys; from femadh.elastic.fe.mesh import MeshSpec, cached_mesh, read_mesh;"
            "s = MeshSpec((0.0, 0.25, 0.5, 0.75, 1.0, 1.0 + 1e-9 * %d), 50.0, 0.5, 0.2);"
            "p = cached_mesh(s, sys.argv[1]); pts, tri = read_mesh(p); print(len(tri))")
    seed = int(time.time() * 1000) % 100000        # a mesh no cache holds yet
    procs = [subprocess.Popen([sys.executable, "-c", code % seed, str(tmp_path)], cwd=ROOT,
                              env=ENV, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                              text=True) for _ in range(2)]
    outs = [p.communicate(timeout=120) for p in procs]
    assert all(p.returncode == 0 for p in procs), [o[1] for o in outs]
    n = {o[0].strip() for o in outs}
    assert len(n) == 1 and int(n.pop()) > 10
    files = list(tmp_path.iterdir())
    assert len(files) == 1 and files[0].suffix == ".msh"


# --------------------------------------------------------------------------- nothing lost

SIGMAS = "effects.asperity_gap.sigma=0.8 nm..2 nm:8"    # 8 points that all converge


def _descendants(pid):
    """Every live process below ``pid`` (from /proc: the study's workers, Dask's nannies)."""
    parent = {}
    for d in Path("/proc").iterdir():
        if d.name.isdigit():
            try:
                stat = (d / "stat").read_text()
            except OSError:
                continue
            fields = stat.rsplit(")", 1)[1].split()
            if fields[0] != "Z":                        # a zombie is gone, only not reaped
                parent[int(d.name)] = int(fields[1])
    out, frontier = set(), {pid}
    for _ in range(10):                                  # the tree is 3 deep at most
        frontier = {c for c, p in parent.items() if p in frontier} - out
        if not frontier:
            break
        out |= frontier
    return out


def _alive(pids):
    alive = set()
    for pid in pids:
        try:
            state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
        except OSError:
            continue
        if state != "Z":
            alive.add(pid)
    return alive


@pytest.fixture(scope="module")
def study_scene(tmp_path_factory):
    """The 60-node Fig 3 scene (0.5-nm steps) and its 8-point study run uninterrupted (the
    reference, in this process: the same solver and inputs as a pool's workers, the same
    numbers)."""
    tmp = tmp_path_factory.mktemp("study")
    scene = tmp / "s.toml"
    scene.write_text(study_text())
    ref = tmp / "ref"
    assert main(_cmd(scene, ref, "--workers", "1")[3:]) == 0
    return scene, ref


def _cmd(scene, out, *extra):
    # (no error estimates: what is kept and redone is the point, not its accuracy; no
    # study.png: the tables are compared)
    return [sys.executable, "-m", "femadh", "study", "sweep", str(scene), "--vary", SIGMAS,
            "--out", str(out), "--quiet", "--no-estimate", "--no-figures", *extra]


def _table(out):
    """study.csv as a list of rows of cells (text as written)."""
    import csv

    with open(Path(out) / "study.csv", newline="") as f:
        return list(csv.reader(f))


# each signal and each executor once: the driver turns SIGINT and SIGTERM into one flag
# (femadh.studies.executors) and always stops its pool's workers with SIGTERM, so a SIGTERM to
# a pool's driver repeated the SIGINT case but for the exit code, which the Dask case checks
# (that third case cost ~3.3 CPU-s: a driver and two workers started). The Dask case runs a
# LocalCluster of one worker process: stopping a cluster's workers is the same call for one as
# for two, and each worker process started costs ~1 CPU-s of imports (distributed, femadh)
@pytest.mark.parametrize("sig, executor", [(signal.SIGINT, "pool"), (signal.SIGTERM, "dask")])
def test_signalled_study_stops_its_workers_and_a_rerun_ends_equal(study_scene, tmp_path, sig,
                                                                  executor, capsys):
    """SIGINT/SIGTERM to the driver mid-way: exit 130/143 within seconds, no process left,
    the finished points kept; the points not finished (if any: see below) are computed by
    the next run, whose study.csv equals the uninterrupted study's cell by cell (same
    solver, same inputs)."""
    scene, ref = study_scene
    out = tmp_path / "study"
    extra = ("--workers", "2") if executor == "pool" else ("--scheduler", "local:1")
    p = subprocess.Popen(_cmd(scene, out, *extra), cwd=ROOT, env=ENV,
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    kids, t0 = set(), time.time()
    while len(_finished(out)) < 2 and p.poll() is None and time.time() - t0 < 120:
        kids |= _descendants(p.pid)
        time.sleep(0.05)
    assert p.poll() is None, "the study ended before the signal"
    kids |= _descendants(p.pid)
    t_sig = time.time()
    p.send_signal(sig)
    _, err = p.communicate(timeout=60)
    stop_s = time.time() - t_sig
    assert p.returncode == 128 + sig, err
    assert f"interrupted by {signal.Signals(sig).name}" in err
    # the way on: run the same again, or - every point finished before the signal landed
    # (below) - nothing left (failed once in session 14 asking for "run the same" there)
    assert ("run the same" in err) != ("none is left to compute" in err), err
    assert stop_s < 15, stop_s            # measured 0.2 s (pool) and 1.0 s (Dask)
    t0 = time.time()
    while _alive(kids) and time.time() - t0 < 10:
        time.sleep(0.1)
    assert kids and not _alive(kids), _alive(kids)
    kept = _finished(out)
    # every point may have finished before the signal landed (the 60-node points take
    # ~0.05 s: Dask's workers finished all 8 within one 0.05-s poll, measured, the driver
    # still writing its table): the stop is then tested and the rerun reuses every point;
    # that a point cut short is redone is test_killed_study_loses_no_completed_point's
    assert 2 <= len(kept) <= 8
    # study.csv after the signal holds exactly the finished points
    assert {row[1] for row in _table(out)[1:]} == kept
    # the rest in this process (no pool, no interpreter to start: the same solver, the same
    # numbers, as the reference was run)
    code = main(_cmd(scene, out, "--workers", "1")[3:])
    cap = capsys.readouterr()
    assert code == 0, cap.err
    timing = json.loads((out / "timing.json").read_text())
    assert timing["reused"] == len(kept) and timing["redone"] + timing["new"] == 8 - len(kept)
    assert f"reused {len(kept)}" in cap.out
    assert _table(out) == _table(ref)


def test_killed_worker_is_noticed_and_its_point_requeued(study_scene, tmp_path):
    """kill -9 of one pool worker mid-point: the driver notices (a note names the point),
    re-queues that point once on a fresh pool, and the study ends complete, exit 0, equal
    to the uninterrupted study."""
    scene, ref = study_scene
    out = tmp_path / "study"
    p = subprocess.Popen(_cmd(scene, out, "--workers", "2"), cwd=ROOT, env=ENV,
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    victim, t0 = None, time.time()
    while victim is None and p.poll() is None and time.time() - t0 < 60:
        for f in out.glob("points/*/record.json"):
            try:
                rec = json.loads(f.read_text())
            except ValueError:
                continue
            if rec["status"] == "running" and rec["pid"] != p.pid:
                victim = rec
                break
        time.sleep(0.02)
    assert victim is not None
    os.kill(victim["pid"], signal.SIGKILL)
    _, err = p.communicate(timeout=120)
    assert p.returncode == 0, err
    assert f"point {victim['index']}: its worker (pid {victim['pid']}) died (signal 9); " \
           "re-queued" in err
    assert _table(out) == _table(ref)


def test_unfinished_records_are_redone_and_failed_points_exit_3(tmp_path, capsys):
    """A record that says "interrupted" (or a point whose worker crashed) is run again,
    a finished one reused; a study with failed points exits 3 with one line per distinct
    reason; a study whose every point failed draws no figure and says so."""
    scene = tmp_path / "s.toml"
    scene.write_text(fig3_uniform_text().replace("nodes = 200", "nodes = 60"))
    out = tmp_path / "st"
    # sigma = 0.4 nm on 60 nodes is lattice trapping (a physical failure, final); 1 nm runs
    args = ["study", "sweep", str(scene), "--vary", "effects.asperity_gap.sigma=0.4 nm,1 nm",
            "--out", str(out), "--workers", "1", "--no-estimate"]
    assert main(args) == 3
    cap = capsys.readouterr()
    assert "1 of 2 points failed:" in cap.err and "1 point (0): " in cap.err
    assert "lattice trapping" in cap.err and "reused 0, redone 0, new 2" in cap.out
    recs = {json.loads(f.read_text())["index"]: f for f in out.glob("points/*/record.json")}
    failed = json.loads(recs[0].read_text())
    assert failed["status"] == "failed" and failed["finished"]
    ok = json.loads(recs[1].read_text())
    recs[1].write_text(json.dumps({**ok, "status": "interrupted", "finished": False}))
    assert main(args) == 3
    assert "reused 1, redone 1, new 0" in capsys.readouterr().out
    assert json.loads(recs[1].read_text())["status"] == "converged"
    # every point failed: no empty figure
    allbad = tmp_path / "bad"
    assert main(["study", "sweep", str(scene), "--vary",
                 "effects.asperity_gap.sigma=0.3 nm,0.4 nm", "--out", str(allbad),
                 "--workers", "1", "--no-estimate"]) == 3
    err = capsys.readouterr().err
    assert "2 of 2 points failed" in err and "no figure: every point failed" in err
    assert len([ln for ln in err.splitlines() if ln.startswith("femadh: error:   ")]) == 1
    assert not (allbad / "study.png").exists() and (out / "study.png").exists()


def test_typed_values_need_units_and_absurd_ones_are_refused(tmp_path, capsys):
    """scene.replace and --vary refuse a bare number for a length with the scene file's
    error; a sigma larger than the sphere or the sweep, a step longer than the sweep, are
    refused before anything runs in one line; a key that is no string is a scene error."""
    sc = small()
    with pytest.raises(SceneError, match="bare number has no unit"):
        sc.replace({"effects.asperity_gap.sigma": 0.6})
    assert sc.replace({"effects.asperity_gap.sigma": 0.6e-9}, si=True).gap.sigma == 0.6e-9
    assert sc.replace({"effects.asperity_gap.sigma": "0.6 nm"}).gap.sigma == 0.6e-9
    with pytest.raises(SceneError, match="dotted scene key"):
        sc.replace({1: 2})
    file_err = tmp_path / "f.toml"
    file_err.write_text(fig3_uniform_text().replace('sigma = "1.0 nm"', "sigma = 0.8"))
    with pytest.raises(SceneError) as from_file:
        femadh.load_scene(file_err)
    # the same words as the file's error (its value 0.8 is the range's first)
    for vary, words in (("effects.asperity_gap.sigma=0.8..1.2:3", from_file.value.expected),
                        ("effects.asperity_gap.sigma=0.8 m..1.2 m:3", "below the sphere radius"),
                        ("effects.asperity_gap.sigma=8 nm,9 nm", "within the sweep's range"),
                        ("sweep.step=10 nm", "no longer than the sweep")):
        out = tmp_path / "s"
        assert main(["study", "sweep", str(FIG3), "--vary", vary, "--out", str(out)]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and words in err[0], (vary, err)
        assert not out.exists()


def test_study_progress_counts_done_failed_reused(capsys):
    """In a terminal the study's bar counts points done, failed and reused."""
    from femadh.io.progress import StudyProgress

    bar = StudyProgress(4, 2, "demo")
    bar.point({"status": "failed"})
    bar.point({"status": "converged"})
    bar.bar.refresh()
    bar.close()
    err = capsys.readouterr().err
    assert "4/4" in err and "failed 1, reused 2" in err


def test_points_differing_in_the_modulus_do_not_share_an_operator(tmp_path):
    """A worker reuses the surface operator of an identical grid and body only: two points
    that differ in the disk's modulus (E* scales the Green function) each build their own,
    and a stiffer disk indents less: F_ex at the deepest separation differs (by ~E*)."""
    from femadh.studies.executors import OPERATOR_CACHE, run_point

    OPERATOR_CACHE.clear()
    pts = study_points(small().replace({"sweep.stop": "-1 nm"}),
                       {"materials.disk.youngs_modulus": "100 GPa,400 GPa,100 GPa"})
    recs = [run_point(p, tmp_path, estimate=False) for p in pts]
    assert [r["status"] for r in recs] == ["converged"] * 3
    assert [r["operator_reused"] for r in recs] == [False, False, False]
    assert recs[2]["F_ex_deepest_N"] == recs[0]["F_ex_deepest_N"]
    assert recs[1]["F_ex_deepest_N"] != pytest.approx(recs[0]["F_ex_deepest_N"], rel=1e-2, abs=0)


def test_points_without_estimates_are_not_reused_by_a_study_that_asks_for_them(tmp_path,
                                                                              capsys):
    """--no-estimate: each point's record says what its run estimated ("peak": the peak
    located, no error estimates; study.json says it of the run). A later study with
    estimates runs such a point again (never reuses it as if estimated) and says so; a
    study without estimates reuses a point that has them (its errors are real). A record of
    an earlier femadh (no "estimate") is taken for what it shows."""
    scene = tmp_path / "s.toml"
    scene.write_text(study_text())
    out = tmp_path / "st"
    args = ["study", "sweep", str(scene), "--vary", "effects.asperity_gap.sigma=1 nm",
            "--out", str(out), "--workers", "1"]
    rec_file = out / "points" / study_points(femadh.load_scene(scene), {
        "effects.asperity_gap.sigma": "1 nm"})[0].id / "record.json"
    assert main(args + ["--no-estimate"]) == 0
    assert "reused 0, redone 0, new 1" in capsys.readouterr().out
    rec = json.loads(rec_file.read_text())
    assert rec["estimate"] == "peak" and not [k for k in rec if k.endswith("_error")]
    assert json.loads((out / "study.json").read_text())["estimate"] == "peak"
    assert "max_adhesion_N_error" not in _table(out)[0]
    assert main(args) == 0
    cap = capsys.readouterr()
    assert "reused 0, redone 1, new 0" in cap.out
    assert "1 finished point computed without error estimates (--no-estimate) run again" \
        in cap.err
    rec = json.loads(rec_file.read_text())
    assert rec["estimate"] == "errors" and rec["max_adhesion_N_error"] > 0
    assert "max_adhesion_N_error" in _table(out)[0]
    # the other way round, from an earlier femadh's record: with an estimated error it
    # serves a study that asks for no estimate
    rec_file.write_text(json.dumps({k: v for k, v in rec.items() if k != "estimate"}))
    assert main(args + ["--no-estimate"]) == 0
    cap = capsys.readouterr()
    assert "reused 1, redone 0, new 0" in cap.out and "run again" not in cap.err
    # without one it is not taken for estimated
    rec_file.write_text(json.dumps({k: v for k, v in rec.items()
                                    if k != "estimate" and not k.endswith("_error")}))
    assert main(args) == 0
    assert "reused 0, redone 1, new 0" in capsys.readouterr().out


def test_a_meniscus_point_records_the_estimate_its_run_made(tmp_path, capsys):
    """A meniscus run estimates its force's error whatever it is asked (run_meniscus takes no
    ``estimate``): its point's record says "errors" under --no-estimate too, so a later study
    with estimates reuses it (no false "run again" note); an earlier femadh's meniscus record
    (no "estimate" field, no ``*_error`` key) is taken for estimated by its forces."""
    from femadh.studies.sweep import point_estimate

    scene = Path(__file__).parent.parent / "validation" / "scenes" / "paper2_ethanol_100nm.toml"
    out = tmp_path / "st"
    args = ["study", "sweep", str(scene), "--vary", "meniscus.temperature=298.15 K",
            "--out", str(out), "--workers", "1", "--quiet"]
    assert main(args + ["--no-estimate"]) == 0
    rec_file, = (out / "points").glob("*/record.json")
    rec = json.loads(rec_file.read_text())
    assert rec["estimate"] == "errors"
    assert main(args) == 0
    cap = capsys.readouterr()
    assert "reused 1, redone 0, new 0" in cap.out and "run again" not in cap.err
    old = {k: v for k, v in rec.items() if k != "estimate"}
    assert any(k.startswith("max_force_N[") for k in old)
    assert point_estimate(old) == "errors"
    assert point_estimate({k: v for k, v in old.items()
                           if not k.startswith("max_force_N[")}) == "none"
