"""One run lifecycle for every scene kind (femadh.runner.lifecycle), one result base
(femadh.runner.result.RunResult) and the public API (femadh.__all__, femadh.run).

The lifecycle is checked on its own (each way a run can end -> the status written last, the
exit code, what is raised) and through both runners (contact and meniscus): summary.json says
"running" first and the outcome last, and a fault inside a run keeps every state committed
before it."""
import dataclasses
import inspect
import json
import os
import pickle
import pydoc
import signal
import time

import numpy as np
import pytest

import femadh
from femadh import interrupt
from femadh.errors import (ConvergenceError, Interrupted, OutputError, TimeLimitReached)
from femadh.io.run_folder import RunFolder
from femadh.runner.lifecycle import lifecycle, raise_if_stopped
from femadh.runner.result import ContactResult, MeniscusRunResult, RunResult
from validation.fault_matrix import short_scene

MENISCUS = "validation/scenes/paper2_ethanol_100nm.toml"


def _recorder(res):
    written = []

    def write(status=None):
        written.append(status or res.status)
    return written, write


# --------------------------------------------------------------------------- the lifecycle

def _raise(exc):
    def body():
        raise exc
    return body


@pytest.mark.parametrize("body,status,error,code", [
    (lambda: None, "converged", None, None),
    (_raise(ConvergenceError("no convergence", d=1e-9, n_iter=7)), "failed",
     "no convergence; d = 1 nm; after 7 iterations", None),
    (_raise(Interrupted(signal.SIGINT)), "interrupted", "interrupted by SIGINT", 130),
    (_raise(Interrupted(signal.SIGTERM)), "interrupted", "interrupted by SIGTERM", 143),
    (_raise(TimeLimitReached(600.0)), "time limit", "time limit 10 min reached", 6),
], ids=["returns", "solver-failure", "sigint", "sigterm", "time-limit"])
def test_each_end_of_a_run_is_one_status_written_last(body, status, error, code):
    res = RunResult("t", None)
    written, write = _recorder(res)
    stops, cleaned = [], []
    with lifecycle(res, write, failures=(ConvergenceError,)) as life:
        life.on_stop = lambda: stops.append(res.status)
        life.cleanup(lambda: cleaned.append(res.status))
        assert written == ["running"] and res.status == "running"
        body()
    assert written == ["running", status]
    assert (res.status, res.error, res.exit_code) == (status, error, code)
    # the checkpoint hook runs only for a stop, after the status is set; cleanups always,
    # before the final summary
    assert stops == ([status] if code else [])
    assert cleaned == [status]
    assert res.timings["total_s"] >= 0


def test_a_fault_outside_the_solver_fails_the_run_and_is_raised():
    res = RunResult("t", None)
    written, write = _recorder(res)
    with pytest.raises(OutputError, match="disk full"):
        with lifecycle(res, write, failures=(ConvergenceError,)):
            raise OutputError("disk full")
    assert written == ["running", "failed"]
    assert (res.status, res.error, res.exit_code) == ("failed", "OutputError: disk full", None)
    # a folder refused while it is checked is left as it was: no summary written over it
    res = RunResult("t", None)
    written, write = _recorder(res)
    with pytest.raises(OutputError):
        with lifecycle(res, write, announce=False) as life:
            life.untouched_on = (OutputError,)
            raise OutputError("damaged record")
    assert written == [] and res.status == "failed"


def test_a_signal_after_the_last_safe_point_still_stops_the_run():
    res = RunResult("t", None)
    written, write = _recorder(res)
    with lifecycle(res, write):
        os.kill(os.getpid(), signal.SIGTERM)      # deferred: no check() follows in the work
    assert written == ["running", "interrupted"] and res.exit_code == 143
    # the run's time limit passed after its last state: "time limit", not "converged"
    res = RunResult("t", None)
    with interrupt.interruptible(1e-3), lifecycle(res):
        time.sleep(0.01)
    assert (res.status, res.exit_code) == ("time limit", 6)


def test_a_signal_while_the_running_summary_is_written_stops_the_run_cleanly():
    """A signal that lands while the "running" summary is written (whole files are written
    in an immediate block, where a signal raises at once) stops the run at its first safe
    point, "interrupted" - it ended in "generator didn't yield" (a study's point recorded an
    internal error), seen once in a signalled study."""
    res = RunResult("t", None)
    written = []

    def write(status=None):
        written.append(status or res.status)
        if status == "running":
            with interrupt.immediate():
                os.kill(os.getpid(), signal.SIGTERM)
    ran = []
    with lifecycle(res, write):
        ran.append(1)
        interrupt.check()               # the first safe point
        ran.append(2)
    assert ran == [1] and written == ["running", "interrupted"]
    assert (res.status, res.exit_code) == ("interrupted", 143)


def test_the_python_api_ends_an_interrupted_run_with_keyboard_interrupt():
    for status, code, raised in [("interrupted", 130, KeyboardInterrupt),
                                 ("interrupted", 143, SystemExit)]:
        with pytest.raises(raised) as exc:
            raise_if_stopped(RunResult("t", None, status=status, error="interrupted by X",
                                       out_dir="o", exit_code=code))
        if raised is SystemExit:
            assert exc.value.code == 143
        else:
            assert "kept in o" in str(exc.value)
    for status, code in [("time limit", 6), ("converged", None), ("failed", None)]:
        r = RunResult("t", None, status=status, exit_code=code)
        assert raise_if_stopped(r) is r


# --------------------------------------------------------------------------- both runners

@pytest.fixture
def summaries(monkeypatch):
    """Every status a run writes into summary.json, in order (the file itself is written)."""
    seen = []
    real = RunFolder.write_summary

    def spy(self, data):
        seen.append(data["status"])
        return real(self, data)
    monkeypatch.setattr(RunFolder, "write_summary", spy)
    return seen


def _rows(path):
    return path.read_text().splitlines()[1:]


def test_both_runners_write_running_then_their_outcome(tmp_path, summaries):
    res = femadh.run(short_scene(tmp_path), tmp_path / "c", figures=False, progress=False,
                     estimate=False)
    assert summaries == ["running", "converged"] and res.exit_code is None
    summaries.clear()
    res = femadh.run(MENISCUS, tmp_path / "m", figures=False, progress=False)
    assert summaries == ["running", "converged"] and res.exit_code is None
    summary = json.loads((tmp_path / "m" / "summary.json").read_text())
    assert summary["status"] == "converged"


def test_both_runners_stop_at_their_time_limit_keeping_what_they_committed(tmp_path,
                                                                            summaries):
    # the limit has passed at the first safe point: the contact run stops at its operator
    # build (nothing committed), the meniscus run after its first point (one row kept)
    res = femadh.run(short_scene(tmp_path), tmp_path / "c", progress=False, time_limit=1e-9)
    assert (res.status, res.exit_code) == ("time limit", 6)
    assert summaries == ["running", "time limit"]
    assert json.loads((tmp_path / "c" / "summary.json").read_text())["status"] == "time limit"
    summaries.clear()
    res = femadh.run(MENISCUS, tmp_path / "m", progress=False, time_limit=1e-9)
    assert (res.status, res.exit_code) == ("time limit", 6)
    assert summaries == ["running", "time limit"]
    assert len(_rows(tmp_path / "m" / "meniscus.csv")) == 1
    # no figure after a stop (it used to be drawn and the stop reported again "while drawing
    # the figure")
    assert res.error == "time limit 1e-09 s reached"
    assert not (tmp_path / "m" / "meniscus_force.png").exists()
    assert len(res.curves) == 1 and len(next(iter(res.curves.values()))["p_ratio"]) == 1
    # data: a study sends it between processes
    again = pickle.loads(pickle.dumps(res))
    assert (again.status, again.exit_code, again.error) == (res.status, 6, res.error)


def test_a_solver_failure_inside_a_contact_run_keeps_every_committed_state(tmp_path,
                                                                            monkeypatch,
                                                                            summaries):
    import femadh.runner.tracing as tracing

    real = tracing.trace

    def failing(problem, d_vals, *, on_state, **kw):
        def state(st):
            if len(_rows(tmp_path / "out" / "curve.csv")) == 4:
                raise ConvergenceError("seeded failure", d=st.d, n_iter=3)
            on_state(st)
        return real(problem, d_vals, on_state=state, **kw)
    monkeypatch.setattr(tracing, "trace", failing)
    scene = short_scene(tmp_path)
    res = femadh.run(scene, tmp_path / "out", figures=False, progress=False, estimate=False)
    assert res.status == "failed" and res.error.startswith("seeded failure; d = ")
    assert summaries == ["running", "failed"]
    rows = _rows(tmp_path / "out" / "curve.csv")
    assert len(rows) == 4 and len(res.branches["approach"]["d_m"]) == 4
    monkeypatch.setattr(tracing, "trace", real)
    ref = femadh.run(scene, tmp_path / "ref", figures=False, progress=False, estimate=False)
    assert rows == _rows(tmp_path / "ref" / "curve.csv")[:4]
    assert ref.status == "converged"


def test_a_fault_in_a_resumed_run_after_its_folder_was_checked_is_failed(tmp_path,
                                                                         monkeypatch,
                                                                         summaries):
    """While a resumed folder is checked an OutputError leaves it as it was; once it is
    checked (and the run appends to it) the same fault ends the run "failed" on disk."""
    from femadh.io.writers import ContactWriter

    scene, out = short_scene(tmp_path), tmp_path / "out"
    assert femadh.run(scene, out, progress=False, time_limit=1e-9).status == "time limit"
    real = ContactWriter.write_state

    def failing(self, branch, state):
        if self.count == 3:
            raise OutputError("cannot write curve.csv: seeded fault")
        return real(self, branch, state)
    monkeypatch.setattr(ContactWriter, "write_state", failing)
    summaries.clear()
    with pytest.raises(OutputError, match="seeded fault"):
        femadh.run(scene, out, progress=False, figures=False, estimate=False, resume=True)
    assert summaries == ["running", "failed"]
    assert json.loads((out / "summary.json").read_text())["status"] == "failed"
    assert len(_rows(out / "curve.csv")) == 3


def test_a_fault_inside_a_meniscus_run_keeps_every_committed_point(tmp_path, monkeypatch,
                                                                  summaries):
    from femadh.io.atomic import RowLog

    real = RowLog.append

    def failing(self, rows):
        if self.path.name == "meniscus.csv" and len(_rows(self.path)) == 3:
            raise OutputError(f"cannot write {self.path}: seeded fault")
        return real(self, rows)
    monkeypatch.setattr(RowLog, "append", failing)
    with pytest.raises(OutputError, match="seeded fault"):
        femadh.run(MENISCUS, tmp_path / "out", progress=False)
    assert summaries == ["running", "failed"]
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert summary["status"] == "failed" and "seeded fault" in summary["error"]
    monkeypatch.setattr(RowLog, "append", real)
    femadh.run(MENISCUS, tmp_path / "ref", progress=False, figures=False)
    rows = _rows(tmp_path / "out" / "meniscus.csv")
    assert len(rows) == 3 and rows == _rows(tmp_path / "ref" / "meniscus.csv")[:3]


# --------------------------------------------------------------------------- the results

@pytest.mark.parametrize("cls", [ContactResult, MeniscusRunResult])
def test_results_share_one_base_with_exit_code_declared(cls):
    assert issubclass(cls, RunResult)
    names = [f.name for f in dataclasses.fields(cls)]
    base = [f.name for f in dataclasses.fields(RunResult)]
    assert names[:len(base)] == base == ["name", "scene", "status", "error", "timings",
                                         "out_dir", "headline", "exit_code", "failure_kind"]
    r = cls("x", None)
    assert (r.status, r.exit_code, r.wall_time) == ("running", None, 0.0)
    r.stop(Interrupted(signal.SIGTERM), " while drawing the figures")
    assert (r.status, r.error, r.exit_code) == ("interrupted",
                                                "interrupted by SIGTERM while drawing the "
                                                "figures", 143)
    assert dataclasses.asdict(pickle.loads(pickle.dumps(r))) == dataclasses.asdict(r)


def test_meniscus_headline_is_each_curves_largest_force_with_its_error(tmp_path):
    res = femadh.run(MENISCUS, None, progress=False)
    assert len(res.headline) == 2 * len(res.curves) == 8
    for (liq, R, meth), c in res.curves.items():
        k = int(np.nanargmax(c["force_N"]))
        key = f"max_force_N[{liq},{R:g},{meth}]"
        assert res.headline[key] == c["force_N"][k]
        err = res.headline[f"{key}_error"]
        assert err == c["force_error_N"][k] or (np.isnan(err) and meth == "circular")
    # the same rows through to_csv as in the run's meniscus.csv (columns in another order)
    res.to_csv(tmp_path / "t.csv")
    assert len(_rows(tmp_path / "t.csv")) == 4 * 8


# --------------------------------------------------------------------------- the public API

def test_every_public_name_is_importable():
    ns = {}
    exec("from femadh import *", ns)
    assert set(femadh.__all__) <= set(ns) and set(femadh.__all__) <= set(dir(femadh))
    for name in ("Scene", "RunResult", "ContactResult", "MeniscusRunResult", "run",
                 "load_scene", "FemadhError", "SceneError", "OutputError", "ConvergenceError",
                 "Interrupted", "TimeLimitReached"):
        assert name in femadh.__all__
    assert isinstance(femadh.load_scene("validation/scenes/paper1_fig3.toml"), ns["Scene"])
    assert issubclass(ns["ContactResult"], ns["RunResult"])
    errors = [n for n in femadh.__all__ if n.endswith("Error") or n in ("Interrupted",
                                                                        "TimeLimitReached")]
    assert len(errors) >= 9
    assert all(issubclass(ns[n], femadh.FemadhError) for n in errors)


def test_help_of_run_spells_out_every_keyword():
    sig = inspect.signature(femadh.run)
    # the runner's own entry has the same keywords (the public spelling cannot drift)
    from femadh.runner.run import run as runner_run
    assert sig == inspect.signature(runner_run)
    assert not any(p.kind is p.VAR_KEYWORD for p in sig.parameters.values())
    text = pydoc.render_doc(femadh.run, renderer=pydoc.plaintext)
    head, lines = text.split("\n")[2], [ln.strip() for ln in text.splitlines()]
    for name, p in sig.parameters.items():
        # in the signature help shows, and described under Parameters
        assert (f"{name}=" if p.default is not p.empty else f"({name},") in head, name
        assert any(ln.startswith(f"{name} : ") for ln in lines), name
    for word in ("KeyboardInterrupt", "RunResult", "status"):
        assert word in text
