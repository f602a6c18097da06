"""Faults: signals, resume, a full disk, read-only and occupied folders, concurrent runs, an
existing file as the output folder. Every fault ends in one clear line and loses no completed
state; a resumed run gives the states an uninterrupted one gives."""
import json
import os
import re
from pathlib import Path
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

import femadh
from femadh.cli import main
from femadh.io.writers import read_curve

from conftest import fig3_uniform_text, check_curve_against_fields

ROOT = Path(__file__).resolve().parents[1]
FIG3 = ROOT / "validation" / "scenes" / "paper1_fig3.toml"
ENV = dict(os.environ, OPENBLAS_NUM_THREADS="1", PYTHONPATH=str(ROOT))


def long_scene(tmp_path, step="0.02 nm", nodes=100, extra=""):
    """The Fig 3 scene with many small steps (350 per branch): long enough to interrupt."""
    text = fig3_uniform_text().replace('step = "0.2 nm"', f'step = "{step}"').replace(
        "nodes = 200", f"nodes = {nodes}") + extra
    p = tmp_path / "long.toml"
    p.write_text(text)
    return p


def start(scene, out, *flags):
    return subprocess.Popen([sys.executable, "-m", "femadh", "run", str(scene), "--out",
                             str(out), "--quiet", "--no-estimate", *flags], cwd=ROOT, env=ENV,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def wait_rows(out, n, proc, timeout=60):
    t0 = time.time()
    while time.time() - t0 < timeout:
        path = out / "curve.csv"
        if path.exists() and path.read_text().count("\n") > n:
            return
        if proc.poll() is not None:
            raise AssertionError(f"the run ended before {n} rows: {proc.stderr.read()}")
        time.sleep(0.05)
    raise AssertionError("no rows appeared")


def assert_same_as_uninterrupted(scene_path, out):
    """The resumed run's curve equals an uninterrupted in-memory run's: the same states, forces
    within the Newton tolerance's effect (measured <= 2e-12 relative of the peak force)."""
    ref = femadh.run(femadh.load_scene(scene_path), progress=False, estimate=False)
    c = read_curve(out / "curve.csv")
    for b, cols in ref.branches.items():
        sel = c["branch"] == b
        assert sel.sum() == len(cols["d_m"])
        assert np.array_equal(c["d_m"][sel], cols["d_m"])
        peak = np.max(np.abs(cols["F_ex_N"]))
        assert np.max(np.abs(c["F_ex_N"][sel] - cols["F_ex_N"])) <= 1e-10 * peak
    jumps = list(csvrows(out / "jumps.csv"))
    assert len(jumps) == len(ref.jumps)


def csvrows(path):
    import csv

    with open(path, newline="") as f:
        yield from csv.DictReader(f)


@pytest.mark.slow
def test_signals_and_kill_9_stop_cleanly_and_three_resumes_complete(tmp_path):
    """One run of the long Fig 3 scene (352 states), by the CLI in a subprocess, stopped three
    times - kill -9 after 20 rows (the fresh run: its own "running" summary), SIGINT after 60
    (in the first --resume, which had no checkpoint: the last state re-solved from
    fields.csv), SIGTERM after 100 (in the second) - then resumed to its end. (One test, not
    one per stop: the checks share the run, and pytest-xdist would run a shared fixture once
    per worker.)

    - kill -9: summary still "running", no torn row;
    - SIGINT and SIGTERM: exit 128 + the signal, one error line naming --resume, summary
      "interrupted", every committed state in every file;
    - the last --resume ends "converged" with every state complete in every file and the
      curve of an uninterrupted run.

    0.04-nm steps (176 a branch; the long scene's 0.02 nm made 702 states): the last stop, at
    row 100, leaves 252 states (~0.9 s through the CLI on a quiet machine) for the signal to
    arrive in; the final resume and the uninterrupted run the curve is compared with cost
    half as much."""
    from validation.fault_matrix import cli

    scene, out = long_scene(tmp_path, step="0.04 nm"), tmp_path / "out"
    states = 2 * 176
    for k, (how, code, rows) in enumerate((("kill -9", -signal.SIGKILL, 20), ("SIGINT", 130, 60),
                                           ("SIGTERM", 143, 100))):
        # the signal must land in this process's run, not while it starts (SIGTERM's default
        # action there kills it without a word): wait for rows of its own. The previous stop
        # can leave more rows than this stop's mark - at ~280 states/s a loaded machine's
        # delay between the poll and the signal lets a run go on from 60 past 100 - the
        # likely cause of one failure in a clean-clone run of the suite (exit -15, no
        # output, the evidence gone with pytest's tmp folders). A few rows of its own show it
        # is in its sweep (its handlers are installed before it solves), which leaves more of
        # the states for the signal than waiting for 20. (A failure in session 14, 1 in ~12
        # suite runs, was another: the figure worker stopped inside its matplotlib import
        # wrote a traceback under the stop's line - test_a_figure_worker_stopped_while_...)
        before = (out / "curve.csv").read_text().count("\n") if k else 0
        p = start(scene, out, *(("--resume",) if k else ()))
        wait_rows(out, max(rows, before + 5), p)
        if how == "kill -9":
            p.kill()
        else:
            p.send_signal(getattr(signal, how))
        _, err = p.communicate(timeout=60)
        assert p.returncode == code, (how, err)
        status = json.loads((out / "summary.json").read_text())["status"]
        n = len(read_curve(out / "curve.csv")["d_m"])     # a torn last line is dropped
        assert rows <= n < states, (how, n)
        if how == "kill -9":
            assert status == "running"
            continue
        lines = err.strip().splitlines()
        assert lines and all(line.startswith("femadh: error:") for line in lines), how
        assert "--resume" in err and "Traceback" not in err, how
        assert status == "interrupted", how
        assert check_curve_against_fields(out) == n, how
    code, err = cli("run", scene, "--out", out, "--quiet", "--no-estimate", "--no-figures",
                    "--resume")
    assert code == 0, err
    assert json.loads((out / "summary.json").read_text())["status"] == "converged"
    assert check_curve_against_fields(out) == states
    assert_same_as_uninterrupted(scene, out)


@pytest.mark.slow
def test_fe_run_interrupted_keeps_its_vtk_consistent_and_resumes(tmp_path):
    """An FE run with VTK, stopped by SIGTERM and resumed: the .pvd collections list exactly
    the committed states (the resumed run keeps the earlier entries), every listed file
    exists and opens, and the curve equals an uninterrupted run's."""
    import meshio

    from validation.fault_matrix import cli

    # 19 states each way (2 to -1.6 nm: through the jump-in into contact): their VTK files
    # (~50 ms a state) keep the run going ~1.5 s past the 8th row, when the signal is sent
    # (was 36 each way to -5 nm, signalled at 15: the resume and the uninterrupted run the
    # curve is compared with solved and wrote twice as many FE states)
    text = (ROOT / "validation" / "scenes" / "paper1_fig3_fe.toml").read_text()
    text = text.replace("nodes = 200", "nodes = 60").replace('stop = "-5 nm"',
                                                             'stop = "-1.6 nm"')
    text += "vtk = true\n"                 # [output]: every state's VTK as it converges
    scene = tmp_path / "fe.toml"
    scene.write_text(text)
    out = tmp_path / "out"
    p = start(scene, out)
    wait_rows(out, 8, p)
    p.send_signal(signal.SIGTERM)
    _, err = p.communicate(timeout=60)
    assert p.returncode == 143, err
    assert 8 <= len(read_curve(out / "curve.csv")["d_m"]) < 38
    code, err = cli("run", scene, "--out", out, "--quiet", "--no-estimate", "--no-figures",
                    "--resume")
    assert code == 0, err
    n = check_curve_against_fields(out)
    c = read_curve(out / "curve.csv")
    listed = 0
    for branch in ("approach", "retract"):
        text = (out / f"{branch}.pvd").read_text()
        files = re.findall(r'file="([^"]+)"', text)
        states = sorted({int(x) for x in re.findall(r'timestep="(\d+)"', text)})
        assert states == [int(k) for k, b in zip(c["state"], c["branch"]) if b == branch]
        assert len(files) == 2 * len(states)
        for f in files[:2] + files[-2:]:
            assert len(meshio.read(out / f).points) > 0
        listed += len(states)
    assert listed == n
    assert not list((out / "vtk").glob(".*"))          # no temporary file left behind
    assert_same_as_uninterrupted(scene, out)


@pytest.mark.slow
def test_arclength_run_interrupted_is_traced_again_on_resume(tmp_path):
    """An arclength trace stopped by SIGINT keeps its streamed points consistent; --resume
    traces the curve again from its start (its paths are read off the whole curve) and says
    so, ending equal to an uninterrupted run."""
    from validation.fault_matrix import cli

    # 175 points (~10 ms each through the CLI): still tracing well past the 30th (0.01 nm
    # made 329: the resume and the uninterrupted run traced twice as many)
    text = (ROOT / "validation" / "scenes" / "lj_sphere_mu2_arclength.toml").read_text()
    scene = tmp_path / "arc.toml"
    scene.write_text(text.replace('step = "0.1 nm"', 'step = "0.02 nm"'))
    out = tmp_path / "out"
    p = start(scene, out)
    t0 = time.time()
    eq = out / "equilibrium_curve.csv"
    while not (eq.exists() and eq.read_text().count("\n") > 30):
        assert p.poll() is None and time.time() - t0 < 60, "the trace ended before 30 points"
        time.sleep(0.05)
    p.send_signal(signal.SIGINT)
    _, err = p.communicate(timeout=60)
    assert p.returncode == 130, err
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "interrupted"
    rows = eq.read_text().splitlines()
    assert len(rows) > 30 and all(r.count(",") == rows[0].count(",") for r in rows)
    code, err = cli("run", scene, "--out", out, "--quiet", "--no-estimate", "--no-figures",
                    "--resume")
    assert code == 0, err
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "converged"
    assert any("traced again from its start" in w for w in summary["warnings"])
    assert_same_as_uninterrupted(scene, out)


def test_output_fault_mid_run_is_failed_not_converged_and_resumes(tmp_path, monkeypatch,
                                                                  capsys):
    """A fault outside the solver (here the writer failing at state 5, as a full disk does)
    ends the run "failed" in its summary - never "converged" - and --resume completes it to
    the uninterrupted curve."""
    from femadh.errors import OutputError
    from femadh.io.writers import ContactWriter

    scene, out = long_scene(tmp_path, step="0.2 nm"), tmp_path / "out"
    real = ContactWriter.write_state

    def failing(self, branch, state):
        if self.count == 5:
            raise OutputError("cannot write curve.csv: seeded fault")
        return real(self, branch, state)

    monkeypatch.setattr(ContactWriter, "write_state", failing)
    assert main(["run", str(scene), "--out", str(out), "--quiet", "--no-figures",
                 "--no-estimate"]) == 4
    assert capsys.readouterr().err.count("femadh: error:") == 1
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "failed" and "seeded fault" in summary["error"]
    assert len(read_curve(out / "curve.csv")["d_m"]) == 5
    monkeypatch.setattr(ContactWriter, "write_state", real)
    assert main(["run", str(scene), "--out", str(out), "--quiet", "--no-figures",
                 "--no-estimate", "--resume"]) == 0
    assert_same_as_uninterrupted(scene, out)


def test_resume_of_a_run_stopped_before_its_first_state(tmp_path):
    """Stopped in the operator build (no csv written yet): --resume simply runs the scene."""
    from femadh.scene import scene_id

    scene, out = long_scene(tmp_path, step="0.2 nm"), tmp_path / "out"
    out.mkdir()
    (out / "summary.json").write_text(json.dumps(
        {"scene_id": scene_id(femadh.load_scene(scene)), "status": "interrupted",
         "scene": {"name": "long"}}))
    assert main(["run", str(scene), "--out", str(out), "--quiet", "--no-figures",
                 "--no-estimate", "--resume"]) == 0
    assert_same_as_uninterrupted(scene, out)


def test_whole_files_get_ordinary_permissions(tmp_path):
    """Atomically written files (summary, VTK, figures) are readable as a plain open() would
    make them (mkstemp alone gives owner-only 0600: a ParaView server of another user could
    not read the .vtu)."""
    from femadh.io.atomic import save_atomic, write_atomic

    plain = tmp_path / "plain"
    plain.write_text("x")
    write_atomic(tmp_path / "a.json", "{}")
    save_atomic(tmp_path / "b.vtu", lambda p: Path(p).write_text("x"))
    mode = plain.stat().st_mode & 0o777
    assert (tmp_path / "a.json").stat().st_mode & 0o777 == mode
    assert (tmp_path / "b.vtu").stat().st_mode & 0o777 == mode


def test_previous_run_refused_overwrite_cleans_it(tmp_path, capsys):
    out = tmp_path / "out"
    fe = ROOT / "validation" / "scenes" / "paper1_fig3_fe.toml"
    text = fe.read_text().replace("nodes = 200", "nodes = 40")
    text = text.replace('stop = "-5 nm"', 'stop = "0 nm"').replace('step = "0.2 nm"',
                                                                    'step = "1 nm"')
    text += "vtk = true\n"                 # [output]: every state's VTK as it converges
    (tmp_path / "fe.toml").write_text(text)
    # (no error estimates, no figures: what the folder holds and what --overwrite removes is
    # the point; the estimate's coarser FE members and the figures added ~0.5 CPU-s)
    quick = ["--quiet", "--no-figures", "--no-estimate"]
    assert main(["run", str(tmp_path / "fe.toml"), "--out", str(out), *quick]) == 0
    assert list((out / "vtk").glob("*.vtu"))
    capsys.readouterr()
    # another scene (30 states on 100 uniform nodes: the folder's handling is the point)
    other = long_scene(tmp_path, step="0.5 nm")
    assert main(["run", str(other), "--out", str(out), "--quiet"]) == 4
    err = capsys.readouterr().err
    # (its run has finished: --resume would only be refused, so it is not advised)
    assert err.count("femadh: error:") == 1 and "--overwrite" in err and "--resume" not in err
    assert "it has finished" in err
    assert main(["run", str(other), "--out", str(out), *quick, "--overwrite"]) == 0
    assert not (out / "vtk").exists() and not (out / "approach.pvd").exists()
    assert main(["run", str(other), "--out", str(out), "--quiet", "--resume"]) == 4
    assert "nothing to resume" in capsys.readouterr().err


def test_existing_file_and_uncreatable_folder_as_out(tmp_path, capsys):
    f = tmp_path / "file"
    f.write_text("x")
    assert main(["run", str(FIG3), "--out", str(f), "--quiet"]) == 4
    err = capsys.readouterr().err
    assert "is an existing file" in err and err.count("\n") == 1
    assert main(["run", str(FIG3), "--out", "/proc/femadh-cannot-be-here", "--quiet"]) == 4
    assert "cannot create the output folder" in capsys.readouterr().err


def test_concurrent_runs_into_one_folder(tmp_path, capsys):
    scene = long_scene(tmp_path)
    out = tmp_path / "out"
    p = start(scene, out)
    try:
        wait_rows(out, 5, p)
        assert main(["run", str(FIG3), "--out", str(out), "--quiet", "--overwrite"]) == 4
        err = capsys.readouterr().err
        assert "in use by another femadh run" in err and f"pid {p.pid}" in err
    finally:
        p.kill()
        p.communicate()


def _mount_tmpfs(path, opts):
    path.mkdir()
    r = subprocess.run(["mount", "-t", "tmpfs", "-o", opts, "tmpfs", str(path)],
                       capture_output=True)
    if r.returncode:
        pytest.skip(f"cannot mount a tmpfs here ({r.stderr.decode().strip()})")
    return path


def test_full_disk_is_a_clear_error_and_keeps_earlier_rows(tmp_path, capsys):
    mnt = _mount_tmpfs(tmp_path / "small", "size=256k")
    try:
        out = mnt / "out"
        code = main(["run", str(long_scene(tmp_path)), "--out", str(out), "--quiet",
                     "--no-figures"])
        assert code == 4
        err = capsys.readouterr().err
        assert "No space left on device" in err and "cannot write" in err
        assert "Traceback" not in err and err.count("femadh: error:") == 1
        # every complete row is parseable and every committed state complete in all files
        c = read_curve(out / "curve.csv")
        assert len(c["d_m"]) > 0
        for name in ("curve.csv", "fields.csv", "diagnostics.csv"):
            assert (out / name).read_bytes().endswith(b"\n")
    finally:
        subprocess.run(["umount", str(mnt)])


def test_read_only_folder(tmp_path, capsys):
    mnt = _mount_tmpfs(tmp_path / "ro", "ro,size=64k")
    try:
        t0 = time.perf_counter()
        assert main(["run", str(FIG3), "--out", str(mnt), "--quiet"]) == 4
        err = capsys.readouterr().err
        assert "not writable" in err and "Read-only file system" in err
        assert time.perf_counter() - t0 < 5          # refused before anything is computed
    finally:
        subprocess.run(["umount", str(mnt)])


def test_every_meniscus_point_failing_exits_non_zero(tmp_path, capsys):
    text = (ROOT / "validation" / "scenes" / "paper2_ethanol_100nm.toml").read_text()
    text = text.replace('tip_radius = "100 nm"', 'tip_radius = "1 nm"').replace(
        "relative_pressure = [0.05, 0.1, 0.15, 0.2, 0.4, 0.6, 0.8, 0.95]",
        "relative_pressure = [0.999]").replace('methods = ["fe", "shooting", "circular", '
                                               '"no-film"]', 'methods = ["fe"]')
    (tmp_path / "m.toml").write_text(text)
    assert main(["run", str(tmp_path / "m.toml"), "--out", str(tmp_path / "o"), "--quiet"]) == 3
    err = capsys.readouterr().err
    assert "no point of the scene has a meniscus" in err
    assert json.loads((tmp_path / "o" / "summary.json").read_text())["status"] == "failed"


@pytest.mark.parametrize("cmd", ["mesh", "study"])
def test_contact_commands_on_a_meniscus_scene(tmp_path, capsys, cmd):
    scene = ROOT / "validation" / "scenes" / "paper2_ethanol_100nm.toml"
    argv = [cmd, str(scene)] if cmd == "mesh" else [cmd, "convergence", str(scene)]
    assert main(argv + ["--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err.count("femadh: error:") == 1 and "a contact scene" in err


def test_one_ctrl_c_stops_a_python_loop_of_runs(tmp_path):
    """In a script, Ctrl-C stops the current run at a safe point (its states kept, its summary
    'interrupted') and then reaches the script as KeyboardInterrupt: one Ctrl-C ends a loop
    of runs instead of only the run it fell into."""
    scene = long_scene(tmp_path)
    script = tmp_path / "loop.py"
    script.write_text(
        "import femadh\n"
        f"sc = femadh.load_scene({str(scene)!r})\n"
        "try:\n"
        "    for i in range(5):\n"
        f"        femadh.run(sc, {str(tmp_path)!r} + f'/run{{i}}', estimate=False,\n"
        "                   figures=False, progress=False)\n"
        "        print('run', i, 'done', flush=True)\n"
        "except KeyboardInterrupt as exc:\n"
        "    print('stopped:', exc, flush=True)\n")
    p = subprocess.Popen([sys.executable, str(script)], cwd=ROOT, env=ENV,
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    wait_rows(tmp_path / "run0", 20, p)
    p.send_signal(signal.SIGINT)
    out, err = p.communicate(timeout=60)
    assert "stopped: interrupted by SIGINT" in out and "run 1 done" not in out, out + err
    assert json.loads((tmp_path / "run0" / "summary.json").read_text())["status"] == \
        "interrupted"
    assert not (tmp_path / "run1").exists()


def test_a_figure_worker_stopped_while_it_imports_exits_quietly():
    """The figure worker stopped by SIGTERM (the run stops it on a Ctrl-C) while it still
    imports matplotlib: exit 0 and not a word on the run's stderr. Before, SystemExit was
    raised inside the import: exit 1, and once in the suite (session 14) a half-built
    pyparsing Forward's __del__ wrote "Exception ignored ... AttributeError" under the run's
    one-line stop message. ~0.5 s (a Python with femadh imported, a fork)."""
    code = ("import os, signal, time\n"
            "from femadh.runner.figures import FigureWorker\n"
            "w = FigureWorker()\n"
            "time.sleep(0.05)\n"                 # (its handler is set; matplotlib ~0.3 s away)
            "os.kill(w.pid, signal.SIGTERM)\n"
            "print(os.waitstatus_to_exitcode(os.waitpid(w.pid, 0)[1]))\n")
    out = subprocess.run([sys.executable, "-c", code], cwd=ROOT, env=ENV, capture_output=True,
                         text=True, timeout=60)
    assert (out.returncode, out.stdout.strip(), out.stderr) == (0, "0", "")
