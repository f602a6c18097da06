"""A Ctrl-C at any moment of ``femadh run`` is one line and exit 130 (SIGTERM while it starts:
one line and exit 143); a SIGINT its parent set to be ignored stays ignored.

The program's start (importing femadh, parsing, the scene's checks, the lazy import of scipy)
comes before a run's own handlers (femadh.interrupt) are in place; a SIGINT there used to end
in a KeyboardInterrupt traceback of the import machinery (~40-100 lines). These tests send a
real SIGINT to a real ``python -m femadh run`` at chosen moments: deterministically, when a
given module starts to be imported (an audit hook in the child), and after a few delays from
femadh's first import (the child says when femadh starts; Python's own start-up before that,
its site module, is no code of femadh's and is not tested: measured ~15-30 ms here).

SIGTERM's default action is a silent death (exit -15, no line); while the program starts it
is taken as SIGINT is (femadh.cli, femadh.interrupt.Terminated): sent by the same hook at a
moment before main's guard, one inside it, and one while a study holds its claimed folder
(the temporary file of its study.json being opened: an "open" audit event).
"""
import os
from pathlib import Path
import signal
import subprocess
import sys
import time

import pytest

from conftest import fig3_uniform_text
from femadh import interrupt
from femadh.errors import Interrupted

ROOT = Path(__file__).resolve().parents[1]
ENV = dict(os.environ, OPENBLAS_NUM_THREADS="1", PYTHONPATH=str(ROOT))

#: the child: ``python -m femadh`` (runpy, as the program runs), or with FEMADH_TEST_SCRIPT
#: what the ``femadh`` script pip writes does (``from femadh.cli import main``: no __main__
#: module), with an audit hook that sends this process SIGINT (FEMADH_TEST_SIGNAL: another)
#: when the module named in FEMADH_TEST_SIGINT_AT starts to be imported (forgotten first if a
#: site hook imported it) or, for "open:TEXT" / "rename:TEXT", when a path holding TEXT is
#: opened / renamed (a temporary file about to become the whole file),
#: or writes one byte to the fd in FEMADH_TEST_READY_FD when femadh.cli starts to be imported
CHILD = r"""
import os, signal, sys
at, ready = os.environ.get("FEMADH_TEST_SIGINT_AT"), os.environ.get("FEMADH_TEST_READY_FD")
sig = getattr(signal, os.environ.get("FEMADH_TEST_SIGNAL", "SIGINT"))
fired = []
def hook(event, args):
    if fired or event not in ("import", "open", "os.rename"):
        return
    if event in ("open", "os.rename"):
        kind = "open:" if event == "open" else "rename:"
        if at and at.startswith(kind) and at[len(kind):] in str(args[0]):
            fired.append(1)
            os.kill(os.getpid(), sig)
        return
    if args[0] == at:
        fired.append(1)
        os.kill(os.getpid(), sig)
    elif ready and args[0] == "femadh.cli":
        fired.append(1)
        os.write(int(ready), b"!")
# a site hook may have imported the module already (a .pth of the interpreter's site-packages
# imports shutil on CI's Python): forget it, so that its importer really imports it again and
# the moment exists wherever the suite runs
if at in sys.modules and not at.startswith("femadh"):
    del sys.modules[at]
sys.addaudithook(hook)
if os.environ.get("FEMADH_TEST_SCRIPT"):
    sys.argv[0] = os.path.join(os.path.dirname(sys.executable), "femadh")
    from femadh.cli import main
    sys.exit(main())
import runpy
runpy.run_module("femadh", run_name="__main__", alter_sys=True)
"""


def _scene(tmp_path, step="0.5 nm"):
    """The Fig 3 scene on 60 uniform nodes (the tests need a run, not accuracy): in 0.5-nm
    steps a process of ~0.5 s, in the file's 0.2-nm steps ~0.65 s (its run ~0.1 s)."""
    p = tmp_path / "s.toml"
    p.write_text(fig3_uniform_text().replace("nodes = 200", "nodes = 60").replace(
        'step = "0.2 nm"', f'step = "{step}"'))
    return p


def _run_args(scene, out):
    return ["run", str(scene), "--out", str(out), "--no-figures", "--no-estimate"]


def _one_line(err, signame="SIGINT"):
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"femadh: error: interrupted by {signame}"), err
    assert "Traceback" not in err
    return lines[0]


def _child(tmp_path, launcher, at, args, signame="SIGINT"):
    """The child run with ``args`` (SCENE: the scene file), signalled at the moment ``at``."""
    env = dict(ENV, FEMADH_TEST_SIGINT_AT=at, FEMADH_TEST_SIGNAL=signame)
    if launcher == "script":
        env["FEMADH_TEST_SCRIPT"] = "1"
    scene = str(_scene(tmp_path))
    return subprocess.run([sys.executable, "-c", CHILD,
                           *(scene if a == "SCENE" else a for a in args)],
                          cwd=ROOT, env=env, capture_output=True, text=True, timeout=120)


# the moments: femadh.cli being imported (before its handler: python -m femadh's __main__
# takes it), argparse (cli's first import after its handler: the script has no __main__ to
# take it), shutil (argparse's, while the parser is built), femadh.scene (the scene is
# read), scipy (the runner's lazy import: the reviewer's case)
@pytest.mark.parametrize("launcher, module", [
    ("-m", "femadh.cli"), ("script", "argparse"), ("script", "shutil"), ("-m", "shutil"),
    ("-m", "femadh.scene"), ("-m", "scipy")])
def test_sigint_while_starting_is_one_line_and_exit_130(tmp_path, launcher, module):
    out = tmp_path / "out"
    p = _child(tmp_path, launcher, module, _run_args("SCENE", out))
    assert p.returncode == 130, p.stderr
    _one_line(p.stderr)
    assert p.stdout == ""
    assert not out.exists()           # nothing was written: nothing to lose or to clean


# the moments: argparse (the script's; before main's guard: femadh.cli's handler ends the
# process at once) and a study's study.json about to be renamed into place (inside the guard:
# Terminated, taken as a KeyboardInterrupt; the study's folder claimed and the temporary file
# written: both undone on the way out, which an exit at once would not do - its lock file
# stayed; the signal used to land at the temporary file's open, before it existed, so its
# removal was never tested: without it this case fails). Each child ends at the
# signal: 0.03 and 0.40 CPU-s (medians of 5 on CI's Python; the study loads its scene
# first); before, each died of the default action (exit -15, no line). And the moment
# femadh.cli starts to be imported by python -m femadh, before any of femadh.cli runs
# (femadh.__main__'s own handler: it died of the default action too; 0.03 CPU-s).
@pytest.mark.parametrize("launcher, moment, command", [
    ("script", "argparse", "run"), ("-m", "femadh.cli", "run"),
    ("-m", "rename:.study.json.", "study")])
def test_sigterm_while_starting_is_one_line_and_exit_143(tmp_path, launcher, moment,
                                                         command):
    out = tmp_path / "out"
    args = (_run_args("SCENE", out) if command == "run" else
            ["study", "sweep", "SCENE", "--vary", "effects.asperity_gap.sigma=1 nm,2 nm",
             "--workers", "1", "--no-estimate", "--out", str(out)])
    p = _child(tmp_path, launcher, moment, args, "SIGTERM")
    assert p.returncode == 143, (p.returncode, p.stderr)     # as a run stopped by SIGTERM
    _one_line(p.stderr, "SIGTERM")
    assert p.stdout == ""
    if command == "run":
        assert not out.exists()
    else:
        # the study had claimed its folder: no lock, no temporary file, no study.json left
        assert [f.name for f in out.iterdir()] == []


def test_sigint_after_a_few_delays_is_one_line_and_exit_130(tmp_path):
    """SIGINT to the process group (as a terminal's Ctrl-C) 0, 0.1, 0.3 and 0.55 s after
    femadh began to import: its start, the scene's checks, scipy's import, the run (on a
    quiet machine; on a loaded one the same moments fall earlier in the run's life)."""
    scene = _scene(tmp_path, step="0.2 nm")
    for i, delay in enumerate((0.0, 0.1, 0.3, 0.55)):
        out = tmp_path / f"out{i}"
        r, w = os.pipe()
        p = subprocess.Popen([sys.executable, "-c", CHILD, *_run_args(scene, out)], cwd=ROOT,
                             env=dict(ENV, FEMADH_TEST_READY_FD=str(w)), pass_fds=(w,),
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                             start_new_session=True)
        os.close(w)
        try:
            assert os.read(r, 1) == b"!"
        finally:
            os.close(r)
        time.sleep(delay)
        if p.poll() is None:
            os.killpg(p.pid, signal.SIGINT)
        _, err = p.communicate(timeout=120)
        if p.returncode == 0:
            continue                  # (a loaded machine: the run had ended: nothing to test)
        assert p.returncode == 130, (delay, err)
        line = _one_line(err)
        # a run stopped under way says what it kept and how to continue; one that had ended
        # (a Ctrl-C while its report prints) where its results are; before it, nothing
        ended = "the run had ended" in line and f"results are in {out}" in line
        assert ("--resume" in line or ended) == out.exists(), (delay, line)


def test_an_ignored_sigint_stays_ignored_by_a_run(tmp_path):
    """A run started with SIGINT ignored (nohup, a background job) runs to its end through
    SIGINTs sent every 20 ms: femadh's handlers leave SIG_IGN in place."""
    out = tmp_path / "out"
    p = subprocess.Popen([sys.executable, "-m", "femadh", *_run_args(_scene(tmp_path), out)],
                         cwd=ROOT, env=ENV, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                         text=True,
                         preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_IGN))
    sent, t0 = 0, time.time()
    while p.poll() is None and time.time() - t0 < 120:
        p.send_signal(signal.SIGINT)
        sent += 1
        time.sleep(0.02)
    _, err = p.communicate(timeout=120)
    assert sent >= 5                  # (the run takes ~0.5 s or more: signals it ignored)
    assert p.returncode == 0, err
    assert '"status": "converged"' in (out / "summary.json").read_text()


def test_interruptible_leaves_an_ignored_sigint_alone():
    """In-process: inside interruptible() an ignored SIGINT stays SIG_IGN (no flag, no stop)
    while SIGTERM still stops the run at its next check; both are as before afterwards."""
    old_int = signal.signal(signal.SIGINT, signal.SIG_IGN)
    old_term = signal.getsignal(signal.SIGTERM)
    try:
        with interrupt.interruptible():
            assert signal.getsignal(signal.SIGINT) is signal.SIG_IGN
            os.kill(os.getpid(), signal.SIGINT)
            time.sleep(0.01)
            interrupt.check()             # no Interrupted: the signal was ignored
            assert interrupt.pending() is None
            assert signal.getsignal(signal.SIGTERM) is not old_term
            os.kill(os.getpid(), signal.SIGTERM)
            time.sleep(0.01)
            with pytest.raises(Interrupted):
                interrupt.check()
        assert signal.getsignal(signal.SIGINT) is signal.SIG_IGN
        assert signal.getsignal(signal.SIGTERM) is old_term
    finally:
        signal.signal(signal.SIGINT, old_int)
        signal.signal(signal.SIGTERM, old_term)


def test_sigterm_startup_handler_is_never_a_workers(monkeypatch):
    """A study's or a fit's pool worker, spawned by the ``femadh`` script, has the program's
    argv and imports femadh.cli while it re-runs that script as "__mp_main__" (named
    SpawnProcess-N by then): it is not the program, so it takes neither start-up handler
    (a driver's SIGTERM to an idle worker must kill it, exit -15, not end it in exit 143 and a
    'while starting' line the pool reads as a death); and the workers' set-up takes a
    start-up handler out should one be there, leaving any other handler alone."""
    import multiprocessing

    from femadh import cli
    from femadh.interrupt import raise_terminated
    from femadh.studies import executors

    # (_worker_init's other effects undone afterwards: this process is no pool worker)
    monkeypatch.setattr(executors, "_IN_POOL", executors._IN_POOL)
    for var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS"):
        monkeypatch.setenv(var, os.environ.get(var, "1"))
    monkeypatch.setattr(sys, "argv", [os.path.join(os.path.dirname(sys.executable), "femadh"),
                                      "study", "sweep", "s.toml"])
    monkeypatch.delenv("COVERAGE_PROCESS_START", raising=False)
    assert cli._as_program()
    monkeypatch.setattr(multiprocessing.current_process(), "name", "SpawnProcess-1")
    assert not cli._as_program()
    old = signal.getsignal(signal.SIGTERM)
    try:
        for h, kept in ((cli._stop_at_once, False), (raise_terminated, False),
                        (signal.default_int_handler, True)):
            signal.signal(signal.SIGTERM, h)
            executors._worker_init()
            assert signal.getsignal(signal.SIGTERM) is (h if kept else signal.SIG_DFL)
    finally:
        signal.signal(signal.SIGTERM, old)
