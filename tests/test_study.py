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
from femadh.studies.sweep import parse_values, run_study, study_points

ROOT = Path(__file__).resolve().parents[1]
FIG3 = ROOT / "validation" / "scenes" / "paper1_fig3.toml"
ENV = dict(os.environ, OPENBLAS_NUM_THREADS="1", PYTHONPATH=str(ROOT))


def small():
    return femadh.load_scene(FIG3).replace({"solver.nodes": 60, "sweep.step": "0.5 nm",
                                            "sweep.stop": "-3 nm"})


def test_values_and_points_are_validated_before_anything_runs(tmp_path, capsys):
    assert parse_values("0.2 nm..2 nm:4") == ["0.2 nm", "0.8 nm", "1.4 nm", "2 nm"]
    assert parse_values("1e-3..1e-1:3:log") == pytest.approx([1e-3, 1e-2, 1e-1], rel=1e-12, abs=0)
    assert parse_values("100,200") == [100, 200]
    pts = study_points(small(), {"effects.asperity_gap.sigma": "0.5 nm,1 nm",
                                 "sphere.radius": "1 mm,2 mm"})
    assert len(pts) == 4 and len({p.id for p in pts}) == 4
    assert pts[1].scene.sphere.radius == 2e-3 and pts[2].scene.gap.sigma == 1e-9
    # an invalid value names the point, the key and the value; nothing is computed
    assert main(["study", "sweep", str(FIG3), "--vary",
                 "effects.asperity_gap.sigma=1 nm,-2 nm", "--out", str(tmp_path / "s")]) == 2
    err = capsys.readouterr().err
    assert "point 1" in err and "effects.asperity_gap.sigma" in err and "-2 nm" in err
    assert not (tmp_path / "s" / "points").exists()


@pytest.mark.slow
def test_dask_local_cluster_matches_the_process_pool_and_resumes(tmp_path):
    """4 points on a Dask LocalCluster of process workers and on the local pool: the same
    numbers to the last digit (same solver, same inputs); a rerun computes nothing."""
    sc, vary = small(), {"effects.asperity_gap.sigma": "0.5 nm,1 nm",
                         "sphere.radius": "1 mm,2 mm"}
    _, pool = run_study(sc, vary, tmp_path / "pool", workers=2, estimate=False)
    _, dask = run_study(sc, vary, tmp_path / "dask", scheduler="local:2", estimate=False)
    assert set(pool) == set(dask) and len(pool) == 4
    for k, r in pool.items():
        assert r["status"] == dask[k]["status"] == "converged"
        assert r["max_adhesion_N"] == dask[k]["max_adhesion_N"]
    t0 = time.perf_counter()
    run_study(sc, vary, tmp_path / "pool", workers=2, estimate=False)
    assert json.loads((tmp_path / "pool" / "timing.json").read_text())["computed"] == 0
    assert time.perf_counter() - t0 < 5
    rows = (tmp_path / "pool" / "study.csv").read_text().splitlines()
    assert len(rows) == 5 and rows[0].startswith("index,id,effects.asperity_gap.sigma,"
                                                 "sphere.radius,status")


def test_killed_study_loses_no_completed_point(tmp_path):
    scene = tmp_path / "s.toml"
    scene.write_text(fig3_uniform_text().replace("nodes = 200", "nodes = 60"))
    out = tmp_path / "study"
    cmd = [sys.executable, "-m", "femadh", "study", "sweep", str(scene), "--vary",
           "effects.asperity_gap.sigma=0.4 nm..2 nm:6", "--out", str(out), "--workers", "1",
           "--quiet"]
    p = subprocess.Popen(cmd, cwd=ROOT, env=ENV, stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE)
    t0 = time.time()
    while not list(out.glob("points/*/record.json")) and time.time() - t0 < 60:
        time.sleep(0.05)
    p.send_signal(signal.SIGKILL)
    p.communicate()
    done = {f.parent.name for f in out.glob("points/*/record.json")}
    assert 1 <= len(done) < 6
    r = subprocess.run(cmd, cwd=ROOT, env=ENV, capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert json.loads((out / "timing.json").read_text())["computed"] == 6 - len(done)
    assert len(list(out.glob("points/*/record.json"))) == 6


@pytest.mark.slow
def test_results_are_light_and_picklable():
    """A result holds arrays and numbers only: the Fig 4 scene at N = 800 (in contact from
    d = -1 to -3 nm, 11 states a branch, the 12 surface profiles a branch keeps) pickles under
    1 MB (measured 434 kB; its LU factorisations of 169 MB stay in the solver)."""
    sc = femadh.load_scene(ROOT / "validation" / "scenes" / "paper1_fig4.toml").replace(
        {"solver.nodes": 800, "sweep.start": "-1 nm", "sweep.stop": "-3 nm"})
    res = femadh.run(sc, progress=False)
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
