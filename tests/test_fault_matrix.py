"""The fault matrix of a single run (validation/fault_matrix.py, in this process): SIGINT and
SIGTERM at each phase end in exit 130/143, status "interrupted", promptly; --resume then ends
with the summary.json of an uninterrupted run; a damaged folder is refused or repaired in
one line; the time limit ends a run cleanly; femadh check estimates time."""
import json
import os
import signal

import pytest

import femadh
from femadh.cli import main
from validation.fault_matrix import (DAMAGES, cli, curve_rows, damage_cell, differences,
                                     phase, short_scene, signal_cell, summary)

#: without its checkpoint (a kill -9, a lost file) a run resumed inside its sweep differs from
#: the uninterrupted run by the solver tolerance's effect (the resumed branch restarts from
#: its last state re-solved from the saved surface): headline numbers measured <= 1.3e-11
#: relative, each error-estimate component <= 1.1e-14 N absolute against 1.6e-3 N (7e-12 of
#: its quantity); allowed: 1e-9 of the quantity (~100x the measured)
SWEEP_RESUME_REL = 1e-9


@pytest.fixture(scope="module")
def ref(tmp_path_factory):
    """The short scene on 100 uniform nodes (validation/fault_matrix.py's report runs 200: the
    phases and their bookkeeping are the same, each run ~0.2 s cheaper) and its uninterrupted
    run with its estimate, without figures (its summary.json and curve.csv are the same with
    them but for timings, see _flags; drawing them cost the fixture ~0.5 s)."""
    tmp = tmp_path_factory.mktemp("ref")
    scene = short_scene(tmp, nodes=100)
    assert cli("run", scene, "--out", tmp / "ref", "--quiet", "--no-figures")[0] == 0
    return scene, summary(tmp / "ref"), curve_rows(tmp / "ref")


#: every phase once, the two signals alternating (each signal at two or three phases): the
#: handler, the safe points and the resume are one path for SIGINT and SIGTERM (femadh.interrupt
#: records which arrived; only the exit code differs), so the 5 x 2 grid the test ran before
#: repeated each phase's check for the other signal (5 runs and 5 resumes, ~7 CPU-s)
PHASE_SIGNALS = [("operator", signal.SIGINT, 130), ("sweep", signal.SIGTERM, 143),
                 ("peak search", signal.SIGINT, 130), ("estimate", signal.SIGTERM, 143),
                 ("figures", signal.SIGINT, 130)]


#: the cells stopped before the figures resume without them: what is compared (summary.json,
#: curve.csv) is the same with and without figures (measured: no field differs from the
#: reference run's, which draws them), and drawing them cost ~0.6 of each cell's ~1 CPU-s;
#: the "figures" cell stops and resumes in them (its resume draws them and solves nothing).
#: Without figures nothing after an estimate member would notice a pending signal, so the
#: estimate cell is the stricter one this way.
def _flags(phase):
    return () if phase == "figures" else ("--no-figures",)


@pytest.mark.parametrize("phase,sig,code", PHASE_SIGNALS)
def test_signal_at_each_phase_then_resume_equals_uninterrupted(ref, tmp_path, phase, sig,
                                                              code):
    scene, ref_summary, ref_rows = ref
    out = tmp_path / "out"
    c = signal_cell(scene, out, phase, sig, *_flags(phase))
    assert (c["exit"], c["status"]) == (code, "interrupted"), c
    # the solver checks between iterations: stopped well within a second (measured 1-45 ms)
    assert c["latency_s"] < 1.0
    assert "--resume" in c["stderr"] and f"--out {out}" in c["stderr"]
    assert (c["resume_exit"], c["resume_status"]) == (0, "converged"), c
    # the same states, the same numbers, bit for bit (inside the sweep: from the checkpoint
    # of the last committed state, factorisation included)
    assert differences(ref_summary, summary(out)) == []
    assert curve_rows(out) == ref_rows
    assert not (out / "checkpoint.npz").exists()


def test_resume_inside_the_sweep_without_checkpoint_equals_to_tolerance(ref, tmp_path):
    """As after a kill -9 (no checkpoint): the last state is re-solved from fields.csv."""
    scene, ref_summary, ref_rows = ref
    out = tmp_path / "out"
    with phase("sweep", signal.SIGTERM):
        assert cli("run", scene, "--out", out, "--quiet", "--no-figures")[0] == 143
    (out / "checkpoint.npz").unlink()
    # without figures: the summary compared is the same with them (see _flags)
    assert cli("run", scene, "--out", out, "--quiet", "--resume", "--no-figures")[0] == 0
    got = summary(out)
    assert len(curve_rows(out)) == len(ref_rows)
    hl, hl_ref = got["headline"], ref_summary["headline"]
    assert hl.keys() == hl_ref.keys()
    for k, v in hl_ref.items():
        if isinstance(v, float):
            # an error estimate: to the allowance of its quantity
            scale = abs(hl_ref[k[:-6]]) if k.endswith("_error") else abs(v)
            assert hl[k] == pytest.approx(v, rel=0, abs=SWEEP_RESUME_REL * scale), k
        else:
            assert hl[k] == v, k
    for q, parts in ref_summary["error_estimates"].items():
        for part, v in parts.items():
            assert got["error_estimates"][q][part] == pytest.approx(
                v, abs=SWEEP_RESUME_REL * abs(hl_ref[q])), (q, part)
    for k in ("grid", "warnings", "run_id", "scene", "status"):
        assert got[k] == ref_summary[k], k
    assert [j["branch"] for j in got["jumps"]] == [j["branch"] for j in ref_summary["jumps"]]


@pytest.fixture(scope="module")
def ref_states(ref):
    """The number of states of the short scene's sweep, run in this process without estimate
    (once per module: each damage case used to run it again, ten runs for one number)."""
    ref_run = femadh.run(femadh.load_scene(ref[0]), progress=False, estimate=False)
    return sum(len(b["d_m"]) for b in ref_run.branches.values())


@pytest.mark.parametrize("name", list(DAMAGES))
def test_damaged_folder_refused_or_repaired_in_one_line(ref, ref_states, tmp_path, name):
    scene = ref[0]
    c = damage_cell(scene, tmp_path / "out", name)
    lines = c["stderr"].splitlines()
    assert len(lines) == 1 and "Traceback" not in c["stderr"], c
    if name in ("duplicated last row", "garbage bytes in curve.csv",
                "a changed digit in curve.csv"):
        # the commit record itself is damaged: refused, naming the file and the row
        assert c["exit"] == 4 and lines[0].startswith("femadh: error: curve.csv row ")
        assert "--resume-from" in lines[0] and "--overwrite" in lines[0]
        k = int(lines[0].split("--resume-from ")[1].split()[0])
        code, err = cli("run", scene, "--out", tmp_path / "out", "--quiet", "--no-figures",
                        "--no-estimate", "--resume-from", k)
        assert code == 0, err
    else:
        assert c["exit"] == 0 and lines[0].startswith("femadh: note: resume: ")
        assert c["status"] == "converged"
    # repaired or resumed from a valid prefix: the full sweep, every row checked again
    assert len(curve_rows(tmp_path / "out")) == ref_states + 1


def test_time_limit_ends_the_run_cleanly_and_resume_completes(tmp_path, monkeypatch):
    # 141 states each way on 100 nodes, on the run's clock made to advance by 1 s at each of
    # its readings (one when the limit is armed, one at each safe point: every corrector
    # iteration and committed state), so a 100-s limit falls inside the sweep on any host
    # and at any load (a limit in real seconds - a fixed 0.3 s, or half of a reference
    # run's time - let the whole run finish in time on a fast or briefly less loaded host)
    import types

    import femadh.interrupt

    ticks = [0.0]

    def monotonic():
        ticks[0] += 1.0
        return ticks[0]
    monkeypatch.setattr(femadh.interrupt, "time", types.SimpleNamespace(monotonic=monotonic))
    limit = "100 s"
    scene = short_scene(tmp_path, nodes=100, step="0.05 nm")
    out = tmp_path / "out"
    code, err = cli("run", scene, "--out", out, "--quiet", "--no-estimate", "--no-figures",
                    "--time-limit", limit)
    assert code == 6 and f"time limit {limit} reached" in err and err.count("\n") == 1
    s = summary(out)
    assert s["status"] == "time limit"
    assert 0 < len(curve_rows(out)) - 1 < 282
    code, err = cli("run", scene, "--out", out, "--quiet", "--no-estimate", "--no-figures",
                    "--resume")
    assert code == 0, err
    # continued from the checkpoint of its last state: the uninterrupted rows, bit for bit
    assert cli("run", scene, "--out", tmp_path / "ref", "--quiet", "--no-estimate",
               "--no-figures")[0] == 0
    assert curve_rows(out) == curve_rows(tmp_path / "ref") and len(curve_rows(out)) == 283
    # the scene key, with units; a bare number is refused like any dimensional key
    text = scene.read_text().replace("[solver]\n", f'[solver]\ntime_limit = "{limit}"\n', 1)
    scene.write_text(text)
    assert cli("run", scene, "--out", tmp_path / "o2", "--quiet", "--no-estimate")[0] == 6
    scene.write_text(text.replace(f'"{limit}"', "2"))
    code, err = cli("check", scene)
    assert code == 2 and "solver.time_limit" in err and err.count("\n") == 1


def test_check_estimates_time_and_refuses_absurd_cost(tmp_path, capsys):
    from femadh.scene.resources import time_estimate

    small = short_scene(tmp_path, nodes=200)
    assert main(["check", str(small)]) == 0
    said = capsys.readouterr().out
    assert " with its error estimate: 72 states of 200 nodes, at rates measured" in said
    # the estimate counts the sweep's states and grows with the nodes (its rates and their
    # accuracy against real runs are measured in femadh/scene/resources.py: a timing
    # assertion here would judge the CI machine's load, not the model)
    est = {n: time_estimate(femadh.load_scene(short_scene(tmp_path, nodes=n)))[0]
           for n in (200, 800, 3200)}
    assert est[200] < est[800] < est[3200]
    finer = short_scene(tmp_path, nodes=800, step="0.1 nm")
    # twice the states (the first state and the peak search do not double)
    assert 1.5 * est[800] < time_estimate(femadh.load_scene(finer))[0] < 2 * est[800]
    big = short_scene(tmp_path, nodes=5000, step="0.02 nm")       # ~1 h estimated
    assert main(["check", str(big)]) == 2
    err = capsys.readouterr().err
    assert "solver.nodes" in err and "--force" in err and err.count("\n") == 1
    assert main(["check", str(big), "--force"]) == 0
    acc = short_scene(tmp_path, extra="")
    acc.write_text(acc.read_text().replace("[solver]\n", "[solver]\naccuracy = 1e-9\n", 1))
    assert main(["run", str(acc), "--out", str(tmp_path / "o"), "--quiet"]) == 2
    err = capsys.readouterr().err
    # the refusal names the budget of the grid the request would run on: the uniform
    # accuracy mode's where the scene gives its nodes, the adaptive family's where it does
    # not (it said 3200 for both; the newcomer trial found the README's 4000)
    from femadh.estimate.refine import BANDED_MAX_NODES, UNIFORM_MAX_NODES

    assert "solver.accuracy" in err and f"budget ({UNIFORM_MAX_NODES})" in err
    acc.write_text("\n".join(ln for ln in acc.read_text().splitlines()
                             if not ln.startswith("nodes")) + "\n")
    assert femadh.load_scene(acc).adaptive
    assert main(["check", str(acc)]) == 2
    assert f"budget ({BANDED_MAX_NODES})" in capsys.readouterr().err


def test_run_into_empty_folder_name_is_refused(tmp_path, monkeypatch):
    from femadh.errors import OutputError

    monkeypatch.chdir(tmp_path)
    with pytest.raises(OutputError, match="empty"):
        femadh.run(femadh.load_scene(short_scene(tmp_path)), "")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["short.toml"]


def test_a_result_built_by_hand_is_running():
    from femadh import ContactResult

    assert ContactResult("x", None).status == "running"


def test_resume_of_another_scene_without_summary_is_refused(tmp_path):
    """summary.json lost: the rows' checksums (seeded with the scene id) tell this scene's
    run from another's."""
    a = short_scene(tmp_path)
    out = tmp_path / "out"
    damage_cell(a, out, "summary.json deleted")          # (repaired: converged)
    (out / "summary.json").unlink()
    other = tmp_path / "other.toml"
    other.write_text(a.read_text().replace('"2 mm"', '"1 mm"', 1))
    code, err = cli("run", other, "--out", out, "--quiet", "--resume")
    assert code == 4 and "curve.csv row 1 does not match" in err and "another scene" in err
    assert json.loads(json.dumps(err))


def test_accuracy_run_stopped_in_its_second_trial_resumes_to_the_uninterrupted(tmp_path):
    """An accuracy run (trials on ever finer grids in one folder) stopped by SIGTERM inside
    its second trial: --resume recognises the folder (claimed under the user's scene),
    runs the first trial again (the folder holds the second's rows, which do not check with
    the first's id) and continues; summary.json and curve.csv as uninterrupted, bit for
    bit."""
    import femadh.runner.contact as contact
    from validation.fault_matrix import Signal

    scene = short_scene(tmp_path, nodes=50, step="0.5 nm")
    scene.write_text(scene.read_text().replace("[solver]\n", "[solver]\naccuracy = 5e-3\n", 1))
    assert cli("run", scene, "--out", tmp_path / "ref", "--quiet", "--no-figures")[0] == 0
    ref = summary(tmp_path / "ref")
    first, second = [s["nodes"] for s in ref["accuracy"]["steps"]]      # two trials
    assert first == 50 < second
    out = tmp_path / "out"
    s = Signal(signal.SIGTERM)
    real = contact.Sink.state
    # at the 11th state of the second trial's own sweep (its members have fewer nodes)
    contact.Sink.state = s.wrap(real, when=lambda sink, branch, st:
                                sink.problem.grid.n == second
                                and len(sink.rows.get(branch, ())) >= 10)
    try:
        assert cli("run", scene, "--out", out, "--quiet", "--no-figures")[0] == 143
    finally:
        contact.Sink.state = real
    stopped = summary(out)
    assert stopped["status"] == "interrupted" and stopped["scene"]["solver"]["nodes"] == second
    code, err = cli("run", scene, "--out", out, "--quiet", "--no-figures", "--resume")
    assert code == 0, err
    assert differences(ref, summary(out)) == []
    assert curve_rows(out) == curve_rows(tmp_path / "ref")


def test_meniscus_sweep_beyond_reason_is_refused(tmp_path, capsys):
    from pathlib import Path

    text = (Path(__file__).resolve().parents[1] / "validation" / "scenes"
            / "paper2_ethanol_100nm.toml").read_text()
    p = tmp_path / "m.toml"
    p.write_text(text)
    assert main(["check", str(p)]) == 0
    assert "solves, about " in capsys.readouterr().out
    p.write_text(text.replace("relative_pressure = [0.05, 0.1, 0.15, 0.2, 0.4, 0.6, 0.8, 0.95]",
                              "relative_pressure = { start = 0.01, stop = 0.99, num = 100000 }"))
    assert main(["run", str(p), "--out", str(tmp_path / "o"), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert "meniscus.relative_pressure" in err and "--force" in err and err.count("\n") == 1
    assert not (tmp_path / "o").exists()


def test_a_signal_stops_the_state_being_solved_not_after_it(ref, tmp_path):
    """The solver checks for a signal between its iterations: a signal that arrives in the
    first Newton iteration of the 21st state leaves that state uncommitted (stopping only
    between states would commit it first)."""
    import os

    import femadh.contact.complementarity as cp
    import femadh.runner.contact as contact

    scene = ref[0]
    out = tmp_path / "out"
    committed = []
    real_state, real_residual = contact.Sink.state, cp._residual

    def state(self, branch, st):
        committed.append(st.d)
        return real_state(self, branch, st)

    def residual(*a):
        if len(committed) == 20 and not getattr(residual, "sent", False):
            residual.sent = True
            os.kill(os.getpid(), signal.SIGTERM)
        return real_residual(*a)
    contact.Sink.state, cp._residual = state, residual
    try:
        code, err = cli("run", scene, "--out", out, "--quiet", "--no-estimate")
    finally:
        contact.Sink.state, cp._residual = real_state, real_residual
    assert code == 143, err
    assert len(committed) == 20 and len(curve_rows(out)) == 21     # header + 20 states


@pytest.mark.parametrize("sig,code", [(signal.SIGINT, 130)])
def test_signal_in_an_estimate_member_without_figures_is_an_interrupt(ref, tmp_path, sig,
                                                                      code):
    """Without figures nothing after the estimate would notice a pending signal: a member
    stopped by it stops the run (never exit 0 "converged" with a degraded estimate). SIGINT
    only: the phase matrix above stops the estimate with SIGTERM (one handler for both)."""
    scene, ref_summary, _ = ref
    c = signal_cell(scene, tmp_path / "out", "estimate", sig, "--no-figures")
    assert (c["exit"], c["status"]) == (code, "interrupted"), c
    assert (c["resume_exit"], c["resume_status"]) == (0, "converged")
    assert summary(tmp_path / "out")["headline"] == ref_summary["headline"]


def test_sweep_with_jumps_stopped_after_its_jump_in_resumes_bit_for_bit(tmp_path):
    """The Fig 4 scene on 200 uniform nodes snaps in on approach (d ~ 1.11 nm, between its
    5th and 6th states) and out on retract: stopped by SIGTERM in its retract sweep, the
    resumed run keeps the committed jump and ends with the uninterrupted summary and files
    (jumps.csv included), bit for bit. Without the error estimate (its members are other
    runs, covered by the phase matrix): the sweep's bookkeeping is the point here."""
    from pathlib import Path

    from validation.fault_matrix import ROOT

    text = (ROOT / "validation" / "scenes" / "paper1_fig4.toml").read_text()
    scene = tmp_path / "fig4.toml"
    scene.write_text(text.replace("accuracy = 3e-3", "nodes = 200"))
    flags = ("--quiet", "--no-figures", "--no-estimate")
    assert cli("run", scene, "--out", tmp_path / "ref", *flags)[0] == 0
    ref = summary(tmp_path / "ref")
    assert [j["branch"] for j in ref["jumps"]] == ["approach", "retract"]
    out = Path(tmp_path / "out")
    with phase("sweep", signal.SIGTERM) as s:
        s.after = 40                                   # the retract's 5th state
        assert cli("run", scene, "--out", out, *flags)[0] == 143
    assert len((out / "jumps.csv").read_text().splitlines()) == 2      # header + jump-in
    assert cli("run", scene, "--out", out, "--resume", *flags)[0] == 0
    assert differences(ref, summary(out)) == []
    for name in ("curve.csv", "jumps.csv", "diagnostics.csv", "fields.csv"):
        assert (out / name).read_bytes() == (tmp_path / "ref" / name).read_bytes(), name


def test_instrument_scene_resumed_equals_uninterrupted_but_for_its_note(tmp_path):
    """A stepping scene with an [instrument]: its readout refines between every state and
    its jumps' fold and landing states (not in the files), so --resume computes the sweep
    again and says so; every other summary field equals the uninterrupted run's."""
    from validation.fault_matrix import ROOT

    text = (ROOT / "validation" / "scenes" / "afm_tip_cantilever.toml").read_text()
    scene = tmp_path / "ins.toml"
    scene.write_text(text.replace('continuation = "arclength"', 'continuation = "steps"')
                     .replace("nodes = 150", "nodes = 60"))
    assert cli("run", scene, "--out", tmp_path / "ref", "--quiet", "--no-figures")[0] == 0
    c = signal_cell(scene, tmp_path / "out", "estimate", signal.SIGTERM, "--no-figures")
    assert (c["exit"], c["resume_exit"]) == (143, 0)
    got, ref = summary(tmp_path / "out"), summary(tmp_path / "ref")
    assert differences(ref, got) == ["warnings"]
    assert [w for w in got["warnings"] if w not in ref["warnings"]] == [
        "resume: the sweep was computed again from its start (an instrument's readout needs "
        "every state of it in memory)"]
    assert got["instrument"] == ref["instrument"]


def test_a_lock_taken_on_a_removed_lock_file_is_taken_again(tmp_path, monkeypatch):
    """A run that opened the lock file just before the previous run removed it (as it ends)
    would lock a removed file, and a third run could lock the new one: both would run. The
    claim checks that the file it locked is still the folder's, and locks again if not."""
    import fcntl
    import os

    import femadh.io.run_folder as rf

    real = fcntl.flock
    calls = []

    def flock(fd, op):
        real(fd, op)
        if not calls:                         # the previous run's release, just now
            os.unlink(tmp_path / rf.LOCK)
        calls.append(fd)
    monkeypatch.setattr(rf.fcntl, "flock", flock)
    folder = rf.RunFolder(tmp_path, "id", "x", "new")
    try:
        assert len(calls) == 2                # taken again, on the folder's current file
        assert os.fstat(folder.lock_fd).st_ino == os.stat(tmp_path / rf.LOCK).st_ino
    finally:
        folder.release()
    assert not (tmp_path / rf.LOCK).exists()


@pytest.mark.parametrize("at", ["lock", "previous run"])
def test_a_signal_while_a_folder_is_claimed_leaves_no_lock(tmp_path, monkeypatch, at):
    """A SIGINT/SIGTERM (raised as KeyboardInterrupt) while RunFolder takes its lock or reads
    the previous run - before any ``with`` could release it - leaves no lock file in the
    folder (found by a review: a SIGTERM at the lock during ``femadh study`` left
    .femadh.lock behind); the folder can be claimed at once."""
    import fcntl

    import femadh.io.run_folder as rf

    def interrupted(*a, **k):
        raise KeyboardInterrupt
    if at == "lock":
        real = fcntl.flock
        calls = []

        def flock(fd, op):
            calls.append(op)
            if len(calls) == 1:
                raise KeyboardInterrupt        # the signal at the lock, before it is taken
            return real(fd, op)
        monkeypatch.setattr(rf.fcntl, "flock", flock)
    else:
        monkeypatch.setattr(rf, "previous_run", interrupted)
    with pytest.raises(KeyboardInterrupt):
        rf.RunFolder(tmp_path, "id", "x", "new")
    assert not (tmp_path / rf.LOCK).exists()
    monkeypatch.undo()
    rf.RunFolder(tmp_path, "id", "x", "new").release()


class _Clock:
    """The run's clock (femadh.interrupt.time) advanced 1 s at each reading: a time limit
    then falls after a fixed number of safe points, on any host and at any load."""

    def __init__(self):
        self.t = 0.0

    def monotonic(self):
        self.t += 1.0
        return self.t


@pytest.fixture(scope="module")
def fig4_fresh(tmp_path_factory):
    """Fig 4 at its defaults run whole on the counting clock: (scene, folder, readings)."""
    import femadh.interrupt

    out = tmp_path_factory.mktemp("fig4") / "fresh"
    sc = femadh.load_scene("validation/scenes/paper1_fig4.toml")
    clock = _Clock()
    with pytest.MonkeyPatch.context() as m:
        m.setattr(femadh.interrupt, "time", clock)
        # (a limit it never reaches: the clock is read only where a limit is armed)
        assert femadh.run(sc, out, progress=False, figures=False,
                          time_limit=1e12).status == "converged"
    return sc, out, clock.t


@pytest.mark.parametrize("at", [0.24, 0.85])
def test_a_resumed_adaptive_run_ends_with_the_uninterrupted_runs_estimates(fig4_fresh, tmp_path,
                                                                         monkeypatch, at):
    """The Fig 4 scene at its defaults (one adaptive trial, 285 nodes, a jump each way),
    stopped by its time limit on the counting clock at 24 % of its readings (inside the sweep,
    after its jump-in; 1691 readings in all, the sweep's last at 1132) or at 85 % (in its
    error estimate) and resumed from its checkpoint: the summary equals the uninterrupted
    run's, estimates and member records included, but for wall times. Before, a resumed run
    held only a few committed states in memory, so its estimate's members were traced whole
    ("the approach branch's states are not all in memory": Fig 3's F_LJ at the deepest
    state's error 4.79e-8 -> 5.49e-8 N), and it held no fold records, so the members traced
    the fine run's grid steps for their folds (44 or 68-92 solves where 27; the hysteresis and
    jump-out errors moved in their last digits; a stop in the estimate left no checkpoint at
    all) - found by reviews and a newcomer trial. (Without a checkpoint - a kill -9 - the
    restarted branch differs at the solver's tolerance: a review measured up to 1.1e-11
    relative on Fig 3, 4.9e-10 on Fig 4, 1.9e-9 on the slider meniscus.) At 85 % the resume
    draws its figures, is stopped while drawing them and resumed once more
    (:func:`_stop_in_figures_then_resume`): the summary still equals the uninterrupted
    run's."""
    import femadh.interrupt

    sc, fresh, readings = fig4_fresh
    with monkeypatch.context() as m:
        m.setattr(femadh.interrupt, "time", _Clock())
        cut = femadh.run(sc, tmp_path / "cut", progress=False, figures=False,
                         time_limit=float(int(at * readings)))
    assert cut.status == "time limit" and len(cut.jumps) >= 1
    # what it prints: its accuracy not assessed, never "NOT met" (a verdict it has not made)
    from femadh.runner.report import headline_lines

    acc = [ln for ln in headline_lines(cut) if ln.startswith("accuracy ")]
    assert acc and all("not assessed (time limit)" in ln for ln in acc), acc
    if at < 0.5:
        assert femadh.run(sc, tmp_path / "cut", progress=False, figures=False,
                          resume=True).status == "converged"
    else:
        # resumed with its figures, stopped while they are drawn, resumed again (one cut
        # Fig 4 run serves both checks: a run of its own cost the suite ~0.6 CPU-s)
        _stop_in_figures_then_resume(sc, tmp_path / "cut", tmp_path)
    a, b = summary(fresh), summary(tmp_path / "cut")
    for s in (a, b):
        for step in s["accuracy"]["steps"]:
            step.pop("wall_time_s")
    assert a["grid"]["member_solves"] == b["grid"]["member_solves"]
    assert all(m["reduced"] for m in b["grid"]["member_solves"])
    assert differences(a, b) == []


def _stop_in_figures_then_resume(sc, out, tmp_path):
    """The Fig 4 scene at its defaults (adaptive, a jump each way), its run in ``out``
    stopped before its figures, resumed with them and stopped by SIGINT while they are
    drawn, after force_curve.png is written, then resumed again: nothing is solved (its
    sweep, peak search and estimate are complete on disk), only the missing
    profiles_and_forces.png is drawn, from a result read back equal to the one the stopped
    run held (curves, kept profiles, nodes, jumps, numbers: exact), and the summary ends
    without the pending outcome (the caller compares it with the uninterrupted run's: equal
    but for wall times). Before, the checkpoint and its fold records were gone by the
    figures, the resume made the estimate again, and its members traced the fine run's grid
    steps for their folds: the jump-out and hysteresis errors (grid parts) and the members'
    solve counts differed from the uninterrupted run's. A resume stopped again before its
    figure is written leaves the folder as the first stop did; a folder whose curve.csv no
    longer matches its record is resumed as any stopped run (solved). (The drawing is a
    stand-in writing each file whole: which figures are drawn, from what, is the point
    here; the phase matrix's "figures" cell draws the real ones.)"""
    import os
    import shutil

    import numpy as np

    import femadh.io.plots as plots
    import femadh.runner.contact as contact
    from femadh.io.atomic import write_atomic
    from femadh.runner.run import run

    drawn = []

    def draw(res, folder, only=None, stop=None):
        for name in plots.figure_names(res):
            if only is None or name in only:
                if stop == "before":
                    os.kill(os.getpid(), signal.SIGINT)     # raised at once (immediate)
                drawn.append((name, res))
                write_atomic(folder / name, name)
                if stop == "after":
                    os.kill(os.getpid(), signal.SIGINT)

    class Solved(Exception):
        pass

    def no_solve(*a, **kw):
        raise Solved
    with pytest.MonkeyPatch.context() as m:
        m.setattr(plots, "contact_figures", lambda *a, **kw: draw(*a, **kw, stop="after"))
        cut = run(sc, out, progress=False, resume=True)
    assert (cut.status, cut.exit_code) == ("interrupted", 130) and len(cut.jumps) == 2
    assert [n for n, _ in drawn] == ["force_curve.png"]
    stopped = summary(out)
    assert stopped["status"] == "interrupted"
    assert stopped["stopped_in_figures"] == {"status": "converged", "error": None,
                                             "failure_kind": None}
    # a changed digit in curve.csv: not the run the summary records, resumed by solving
    shutil.copytree(out, tmp_path / "damaged")
    DAMAGES["a changed digit in curve.csv"](tmp_path / "damaged")
    with pytest.MonkeyPatch.context() as m:
        m.setattr(contact, "_run", no_solve)
        with pytest.raises(Solved):
            run(sc, tmp_path / "damaged", progress=False, resume=True)
        # stopped again before the missing figure is written: the folder as it was
        m.setattr(plots, "contact_figures", lambda *a, **kw: draw(*a, **kw, stop="before"))
        drawn.clear()
        again = run(sc, out, progress=False, resume=True)
        assert (again.status, again.exit_code) == ("interrupted", 130) and drawn == []
        assert differences(stopped, summary(out)) == []
        m.setattr(plots, "contact_figures", draw)
        res = run(sc, out, progress=False, resume=True)
    assert (res.status, res.exit_code) == ("converged", None)
    assert [n for n, _ in drawn] == ["profiles_and_forces.png"]
    assert (out / "force_curve.png").read_text() == "force_curve.png"   # kept, not redrawn
    back = drawn[0][1]
    assert back.branches.keys() == cut.branches.keys()
    for b, cols in cut.branches.items():
        for c, v in cols.items():
            assert back.branches[b][c].dtype == v.dtype and np.array_equal(
                back.branches[b][c], v), (b, c)
    assert back.profiles.keys() == cut.profiles.keys()
    for b, prof in cut.profiles.items():
        for k, v in prof.items():
            assert np.array_equal(back.profiles[b][k], v), (b, k)
    assert np.array_equal(back.nodes, cut.nodes)
    for name in ("jumps", "headline", "estimates", "accuracy", "grid", "warnings"):
        assert differences(getattr(back, name), getattr(cut, name)) == [], name
    assert "stopped_in_figures" not in summary(out)


def test_a_figures_resume_reads_back_only_the_run_asked_for(tmp_path, monkeypatch):
    """A resume after a stop in the figures reads the result back only where the folder holds
    the run that was asked for, its estimate as asked, and fields.csv as curve.csv records
    it; else it solves as any resume. (a) An accuracy loop (uniform trials of 50 and 200
    nodes) stopped in its second trial's figures: the trial's own call must not read back
    the folder (before: the 200-node numbers were recorded for the 50-node step and the loop
    declared met); resumed, its summary equals the uninterrupted one. (b) A run made without
    its estimate, resumed asking for one: the estimate is made. (c) fields.csv's first state
    edited (its w x 10, a node row dropped): the resume repairs and solves again."""
    import femadh
    import femadh.io.plots as plots
    import femadh.runner.contact as contact
    from femadh.io.atomic import write_atomic

    stop = {"at": None, "calls": 0}

    def draw(res, folder, only=None):
        stop["calls"] += 1
        for name in plots.figure_names(res):
            if only is None or name in only:
                write_atomic(folder / name, name)
                if stop["calls"] == stop["at"]:
                    os.kill(os.getpid(), signal.SIGINT)

    monkeypatch.setattr(plots, "contact_figures", draw)
    solved = []
    real = contact._run
    monkeypatch.setattr(contact, "_run", lambda sc, *a, **kw: solved.append(1) or real(sc, *a,
                                                                                   **kw))
    path = short_scene(tmp_path, nodes=50, step="0.5 nm")
    path.write_text(path.read_text().replace("[solver]\n", "[solver]\naccuracy = 5e-3\n", 1))
    sc = femadh.load_scene(path)
    femadh.run(sc, tmp_path / "ref", progress=False)
    ref = summary(tmp_path / "ref")
    assert len(ref["accuracy"]["steps"]) == 2            # two trials
    stop.update(at=2, calls=0)              # the second trial's figures
    with pytest.raises(KeyboardInterrupt):
        femadh.run(sc, tmp_path / "acc", progress=False)
    assert summary(tmp_path / "acc")["stopped_in_figures"]["status"] == "converged"
    stop.update(at=None)
    femadh.run(sc, tmp_path / "acc", progress=False, resume=True)
    assert differences(ref, summary(tmp_path / "acc")) == []
    # (b) and (c) on the 50-node grid alone
    one = femadh.load_scene(short_scene(tmp_path, nodes=50, step="0.5 nm"))
    stop.update(at=1, calls=0)
    with pytest.raises(KeyboardInterrupt):
        femadh.run(one, tmp_path / "ne", progress=False, estimate="peak")
    stop.update(at=None)
    res = femadh.run(one, tmp_path / "ne", progress=False, resume=True)
    assert res.status == "converged" and res.estimates and summary(tmp_path / "ne")[
        "error_estimates"]
    stop.update(at=1, calls=0)
    with pytest.raises(KeyboardInterrupt):
        femadh.run(one, tmp_path / "fd", progress=False)
    f = tmp_path / "fd" / "fields.csv"
    head, *rows = f.read_text().splitlines()
    iw = head.split(",").index("w_m")
    first = [i for i, r in enumerate(rows) if r.split(",")[0] == "0"]
    cut = []
    for i, r in enumerate(rows):
        c = r.split(",")
        if i in first:
            if i == first[-1]:
                continue
            c[iw] = repr(10 * float(c[iw]))
        cut.append(",".join(c))
    f.write_text("\n".join([head, *cut]) + "\n")
    stop.update(at=None)
    solved.clear()
    res = femadh.run(one, tmp_path / "fd", progress=False, resume=True)
    assert res.status == "converged" and solved
    assert any(w.startswith("resume: fields.csv") for w in res.warnings)
