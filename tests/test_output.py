"""What a user sees: the progress display (one over a whole run, phases named, a sane width,
quiet in pipes), the printed headline (one largest-adhesion number, notes in plain words),
the figure files and the regime table."""
import io
import re
from pathlib import Path

import numpy as np
import pytest

from femadh.io import progress
from femadh.runner.run import run
from validation.paper1 import scene as paper1_scene


ROOT = Path(__file__).resolve().parents[1]


class _Tty(io.StringIO):
    """A stderr that says it is a terminal (of ``cols`` columns via COLUMNS)."""

    def isatty(self):
        return True

    def fileno(self):
        raise OSError("no file descriptor")


def _small(sigma="0.5 nm", n=60):
    sc = paper1_scene("paper1_fig3", n, sigma=sigma)
    data = dict(sc.raw)
    data["sweep"] = {"start": "1.6 nm", "stop": "0 nm", "step": "0.2 nm",
                     "directions": ["approach", "retract"]}
    from femadh.scene import scene_from_dict

    return scene_from_dict(data, "test")


def test_one_display_names_every_phase_of_a_run(monkeypatch):
    """In a terminal a run shows one display whose label walks through the phases: the
    operator, both branches with their counts, the estimate members (nested runs report into
    the same display, no second bar), the peak search; the terminal reports 0 columns, so the
    width is COLUMNS."""
    tty = _Tty()
    monkeypatch.setattr("sys.stderr", tty)
    monkeypatch.setenv("COLUMNS", "120")
    res = run(_small(sigma="1 nm", n=40), progress=True)
    assert res.status == "converged"
    text = re.sub(r"\x1b\[[0-9;]*[A-Za-z]", "", tty.getvalue())
    labels = [p.strip() for p in re.split(r"[\r\n]", text) if p.strip()]
    joined = "\n".join(labels)
    # (N = 40's members: N/sqrt2 and N/2, its N/4 member would soften beyond TRAP_SAFE)
    for phase in ("› operator", "› approach: ", "› retract: ", "› estimate: member 1/2 (N = 28)",
                  "› estimate: member 1/2 (N = 28) › approach: ",
                  "› estimate: member 2/2 (N = 20)", "› peak search"):
        assert phase in joined, phase
    assert all(lb.startswith("paper1-fig3") for lb in labels)   # one display, the run's name
    assert max(len(lb) for lb in labels) <= 120             # the width it was given
    assert progress._active is None                          # closed at the end


def test_the_estimate_is_one_phase_whose_members_follow_one_another(monkeypatch):
    """The error estimate is one phase of the run, its members its parts: on an adaptive
    grid, whose reduced members are solved in two passes (the judged numbers, then the
    folds), the line goes from one member to the next and never back to the grid's sweep
    between them (a newcomer trial saw it flicker between the two). The labels are read off
    a fake terminal, as test_one_display_names_every_phase_of_a_run does."""
    from femadh.scene import scene_from_dict

    data = dict(_small(sigma="1 nm", n=40).raw)
    data["solver"] = {**{k: v for k, v in data["solver"].items() if k != "nodes"},
                      "accuracy": 1e-2}
    tty = _Tty()
    monkeypatch.setattr("sys.stderr", tty)
    monkeypatch.setenv("COLUMNS", "120")
    res = run(scene_from_dict(data, "test"), progress=True, figures=False)
    assert res.status == "converged" and [m["reduced"] for m in res.grid["member_solves"]] \
        == [True, True]
    text = re.sub(r"\x1b\[[0-9;]*[A-Za-z]", "", tty.getvalue())
    labels = [re.sub(r", [0-9.]+ s$", "", p.strip()) for p in re.split(r"[\r\n]", text)]
    labels = [lb for i, lb in enumerate(labels) if lb and (i == 0 or lb != labels[i - 1])]
    grid = f"paper1-fig3 › grid ({res.accuracy['nodes']} nodes)"
    first = labels.index(f"{grid} › estimate")
    last = max(i for i, lb in enumerate(labels) if "› estimate: member" in lb)
    inside = [lb.split("› estimate")[-1] for lb in labels[first:last + 1]]
    members = [m["member"] for m in res.grid["member_solves"]]
    assert inside == ["", f": member 1/2 ({members[0]})", f": member 2/2 ({members[1]})",
                      f": member 1/2 ({members[0]})", f": member 2/2 ({members[1]})"], inside
    assert labels[last + 1] == grid         # the phase ends after its last member


def test_width_falls_back_when_the_terminal_reports_zero(monkeypatch):
    monkeypatch.delenv("COLUMNS", raising=False)
    assert progress.width(_Tty()) == progress.FALLBACK_COLUMNS == 80
    monkeypatch.setenv("COLUMNS", "0")
    assert progress.width(_Tty()) == 80


def test_a_terminal_of_zero_size_still_shows_the_display(monkeypatch):
    """A pseudo-terminal nobody sized reports 0 columns and 0 rows; the display must still
    show the run's phases there (tqdm hides a bar below a screen's last row: with 0 rows it
    printed nothing at all before the rows fell back to 24)."""
    import os

    master, slave = os.openpty()
    assert os.get_terminal_size(slave) == (0, 0)
    monkeypatch.delenv("COLUMNS", raising=False)
    monkeypatch.delenv("LINES", raising=False)
    with open(slave, "w", closefd=True) as tty:
        monkeypatch.setattr("sys.stderr", tty)
        with progress.display("demo", True):
            with progress.phase("approach"):
                progress.begin("approach", 3)
                progress.advance()
    out = b""
    os.set_blocking(master, False)
    try:
        while chunk := os.read(master, 65536):
            out += chunk
    except (BlockingIOError, OSError):
        pass
    os.close(master)
    assert "demo › approach" in out.decode(errors="replace")


def test_phase_and_advance_are_no_ops_without_a_display():
    with progress.phase("anything"):
        progress.begin("approach", 3)
        progress.advance()
    assert progress._active is None


def test_headline_prints_one_max_adhesion_number_with_its_error(capsys):
    """One 'max adhesion' line, with its ±; the branch lines count states and jumps and
    carry no second (grid) adhesion value; lengths print in µm, not um. The run, in a pipe
    (pytest's captured stderr is no terminal), printed nothing on stderr: no progress, from
    its estimate's members either (this was a test of its own, a run of its own)."""
    from femadh.runner.report import headline_lines

    res = run(_small(n=64))
    assert capsys.readouterr().err == ""
    lines = headline_lines(res)
    adhesion = [ln for ln in lines if "adhesion" in ln]
    assert len(adhesion) == 1 and adhesion[0].startswith("max adhesion ") and "±" in adhesion[0]
    assert re.match(r"approach: \d+ states from d = 1.6 nm to 0 nm, 1 jump$", lines[0])
    assert not any(re.search(r"\bum\b", ln) for ln in lines)
    # the N = 32 member is refused at this sigma (a node's softening 1.13 of its stiffness,
    # measured; N = 64's members are N/sqrt2 and N/2): its note says what that means
    notes = [ln for ln in lines if ln.startswith("note: ")]
    assert len(notes) == 1 and "member did not converge" in notes[0] and len(notes[0]) < 250


def test_a_failed_estimate_member_is_a_note_in_plain_words():
    """The note names the member, its reason's first clause, where the error comes from
    instead (or that it lacks the grid part), in one short line."""
    from femadh.runner.estimates import member_note
    from femadh.runner.report import NOTE

    long_error = ("continuation stalled at d = 1.1 nm: Newton residual 3e-09 m after 60 "
                  "iterations (tolerance 1e-19 m); the landing after the fold could not be "
                  "polished, a finer grid or a smaller step may help " * 2)
    note = member_note("N = 50", long_error, "N = 200", ["N = 100"])
    assert note.startswith(NOTE)
    assert ("the N = 50 member did not converge (continuation stalled at d = 1.1 nm); the "
            "grid error is taken from N = 200 and N = 100") in note
    assert len(note) < 220                       # the old warning was 280+ characters
    none = member_note("N = 100", long_error, "N = 200", [])
    assert "lack the grid part" in none and "lower bounds" in none


def test_figures_are_named_for_what_they_show_and_the_loop_is_visible(tmp_path):
    """A sigma-gap run with jumps writes force_curve.png and profiles_and_forces.png (no
    fig3_panels.png); the hysteresis panel spans both folds, and each jump is at least a
    quarter of its height (on the whole curve it is ~1 % of the force scale)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from femadh.io.plots import (branch_with_folds, contact_figures, draw_hysteresis_loop,
                                 force_unit)

    # (N = 80: the two jumps of N = 100, whose run took 0.04 s more)
    res = run(_small(n=80), estimate="peak")
    assert len(res.jumps) == 2
    paths = contact_figures(res, tmp_path)
    assert sorted(p.name for p in paths) == ["force_curve.png", "profiles_and_forces.png"]
    assert all(p.stat().st_size > 20_000 for p in paths)
    # the approach is drawn to its fold, broken, and continued from its landing
    j = next(j for j in res.jumps if j["branch"] == "approach")
    d, F = branch_with_folds(res, "approach", res.branches["approach"])
    k = int(np.flatnonzero(d == j["d_fold_m"])[0])
    assert F[k] == j["F_ex_before_N"] and np.isnan(d[k + 1]) and F[k + 2] == j["F_ex_after_N"]
    assert np.all(np.diff(d[np.isfinite(d)]) <= 0)         # in the order it was traced
    fig, ax = plt.subplots()
    fs, _ = force_unit([res.headline["max_adhesion_N"]])
    lo_m, hi_m = draw_hysteresis_loop(ax, res, fs, "µN")
    lo, hi = ax.get_xlim()
    assert (lo, hi) == pytest.approx((lo_m * 1e9, hi_m * 1e9))   # the strip on the main axes
    y0, y1 = ax.get_ylim()
    for j in res.jumps:
        assert lo < j["d_fold_m"] * 1e9 < hi
        assert abs(j["F_ex_after_N"] - j["F_ex_before_N"]) * fs > 0.25 * (y1 - y0)
    plt.close(fig)


def test_regime_prints_a_short_table_and_keeps_the_csv_in_the_file(regime_run):
    """`femadh regime` prints one header and one row per point (a few columns, aligned), not
    the csv; regime.csv keeps every column. (conftest's regime_run: mu 0.5 and 1, the run
    test_roughness reads the files of.)"""
    from femadh.studies.regime import REGIME_HEADER

    code, text, tmp_path = regime_run
    assert code == 0
    out = text.splitlines()
    assert out[0].split() == ["mu", "pull-off/πRΔγ", "Maugis-Dugdale", "jump-in", "d/z0",
                              "jump-out", "d/z0", "hysteresis", "nodes"]
    assert len(out) == 4 and out[-1].startswith(f"results in {tmp_path}: regime.csv")
    assert "," not in "".join(out[:3]) and max(len(ln) for ln in out[:3]) <= 100
    assert len({len(ln) for ln in out[:3]}) == 1                  # aligned columns
    assert "±" in out[1] and "±" in out[2]
    header = (tmp_path / "regime.csv").read_text().splitlines()[0]
    assert header == ",".join(REGIME_HEADER) and len(REGIME_HEADER) > 20


def test_render_exports_the_state_it_draws_headless_and_quiet(tmp_path, capfd, tiny_fe_run):
    """An FE run writes no per-state VTK by default; `femadh render --state K` exports that
    state from fields.csv (its .vtu and a .pvd listing it), draws it, and says nothing on
    stderr (no VTK X-server warning on a machine without a display); the exported volume
    field equals the run's surface displacement to the csv's round-trip (exact reprs)."""
    import os

    import pyvista as pv

    from femadh.cli import main
    from femadh.io.writers import read_fields_state

    out = tiny_fe_run(tmp_path)                   # conftest: shared with test_cli's render
    assert not (out / "vtk").exists()
    capfd.readouterr()
    env = os.environ.pop("DISPLAY", None)
    try:
        assert main(["render", str(out), "--state", "3"]) == 0
    finally:
        if env is not None:
            os.environ["DISPLAY"] = env
    cap = capfd.readouterr()
    assert cap.err == "" and cap.out.strip() == f"rendered {out / 'render.png'}"
    assert sorted(p.name for p in (out / "vtk").iterdir()) == ["approach_0003.vtu",
                                                             "approach_surface_0003.vtu"]
    assert 'timestep="3"' in (out / "approach.pvd").read_text()
    vol = pv.read(out / "vtk" / "approach_0003.vtu")
    _, w = read_fields_state(out, "approach")                 # state 3: the last approach
    i0 = int(np.argmin(np.hypot(vol.points[:, 0], vol.points[:, 1])))
    # the body re-solved from the saved pressures: w(0) to the solver's residual (1e-19 m
    # against ~1 nm; measured 1.9e-13 relative)
    assert vol["displacement"][i0, 1] == pytest.approx(w[0], rel=1e-9, abs=0)
    assert main(["render", str(out), "--state", "99"]) == 4
