"""What a user's run costs besides its solve: the state writer's text and the figures' worker.

- ``fields.csv`` is written from whole columns (:func:`femadh.io.writers.field_lines`): its
  text must be byte for byte what the csv module writes for the per-cell rows (each number as
  ``repr(float(x))``, the formatting every femadh csv has used), for every kind of double
  (negative zero, subnormals, the extremes, inf, nan) and for a branch name csv must quote;
  every cell reads back to the same double.
- The figures of a command-line run are drawn by a worker process forked before the solve
  (:mod:`femadh.runner.figures`): the run's folder gets the same figures as an in-process
  run, the worker is gone when the run returns, and a run without figures starts none.
"""
import csv
import io
import math
import os
from types import SimpleNamespace

import numpy as np
import pytest

from femadh.io.atomic import csv_text
from femadh.io.writers import field_lines, formatted


def _reference(k, branch, d, columns):
    """The rows as the per-cell writer formatted them: each number repr(float(x))."""
    n = len(columns[0])
    rows = [[k, branch, repr(float(d))] + [repr(float(c[i])) for c in columns]
            for i in range(n)]
    buf = io.StringIO()
    csv.writer(buf, lineterminator="\n").writerows(rows)
    return buf.getvalue()


ODD = [0.0, -0.0, 5e-324, -5e-324, 2.2250738585072014e-308, 1.7976931348623157e308,
       -1.7976931348623157e308, math.inf, -math.inf, math.nan, 1.0, 0.1, 1e16, 1e-7,
       123456789.0, -3.0000000000000004e-09, 2 ** 53 + 1.0]


SCENE = os.path.join(os.path.dirname(__file__), "..", "validation", "scenes",
                     "paper1_fig3.toml")


def _small_scene(folder):
    """The Fig 3 scene on 60 uniform nodes swept from 2 to -1 nm and back (in contact from
    d = 1 nm, no jump, as to -5 nm: 16 states a branch; a run of ~0.4 CPU-s with two
    figures, of which the figures take 0.39. To -5 nm, the scene's own stop, each run with
    figures cost 0.18 CPU-s more: deeper contact states only, nothing these tests read)."""
    text = open(SCENE).read().replace("[solver]\n", "[solver]\nnodes = 60\n", 1)
    assert text.count('stop = "-5 nm"') == 1
    text = text.replace('stop = "-5 nm"', 'stop = "-1 nm"')
    path = folder / "fig3_small.toml"
    path.write_text(text)
    return path


def test_field_lines_are_the_csv_of_the_per_cell_rows():
    rng = np.random.default_rng(21)
    n = 301
    cols = [rng.normal(size=n) * 10.0 ** rng.integers(-14, 9, n) for _ in range(4)]
    cols.append(np.array((ODD * (n // len(ODD) + 1))[:n]))
    cols.append(rng.normal(size=n).astype(np.float32))     # widened exactly to double
    cols.append(np.arange(n))                               # integers as floats
    for k, branch, d in ((0, "approach", -1.5e-09), (71, "retract", 3e-10),
                         (5, "a,b", math.nan), (6, 'q"x', 0.0)):
        assert field_lines(k, branch, d, cols) == _reference(k, branch, d, cols)
    # pre-formatted columns (the writer formats the grid's nodes once per grid)
    assert field_lines(3, "approach", 1e-9, [formatted(cols[0])] + cols[1:]) == \
        _reference(3, "approach", 1e-9, cols)
    assert field_lines(0, "approach", 0.0, [np.zeros(0)]) == csv_text([])


def test_every_cell_reads_back_to_the_same_double():
    rng = np.random.default_rng(3)
    col = np.concatenate([rng.normal(size=500) * 10.0 ** rng.integers(-300, 300, 500),
                          np.array(ODD)])
    text = field_lines(2, "approach", 1e-9, [col])
    back = np.array([float(r[3]) for r in csv.reader(io.StringIO(text))])
    same = (back == col) | (np.isnan(back) & np.isnan(col))
    assert same.all()
    # -0.0 keeps its sign
    assert math.copysign(1.0, back[np.flatnonzero(col == 0)[0]]) == math.copysign(
        1.0, col[np.flatnonzero(col == 0)[0]])


def test_a_run_writes_fields_whose_cells_are_their_own_shortest_repr(tmp_path):
    """fields.csv of a real run: every number cell is the shortest repr of the double it
    reads back to (what the per-cell writer wrote), rows in state order, header first."""
    import femadh

    scene = femadh.load_scene(_small_scene(tmp_path))
    res = femadh.run(scene, tmp_path / "out", figures=False, estimate=False, progress=False)
    assert res.status == "converged"
    with open(tmp_path / "out" / "fields.csv", newline="") as f:
        rows = list(csv.reader(f))
    head, body = rows[0], rows[1:]
    assert head[:3] == ["state", "branch", "d_m"]
    assert body and all(len(r) == len(head) for r in body)
    states = [int(r[0]) for r in body]
    assert states == sorted(states)
    for r in body[:: max(1, len(body) // 400)]:
        assert all(repr(float(c)) == c for c in r[2:])


# --------------------------------------------------------------------------- figure worker

needs_worker = pytest.mark.skipif(
    not (hasattr(os, "fork") and hasattr(os, "sched_getaffinity")
         and len(os.sched_getaffinity(0)) >= 2),
    reason="the figure worker runs on Linux with two cores or more")


def _pngs(folder):
    return sorted(p.name for p in folder.iterdir() if p.suffix == ".png")


def _no_temporary_files(folder):
    return [p.name for p in folder.iterdir() if p.name.startswith(".")] == []


def _program(tmp_path, args, spy=""):
    """Run ``femadh ARGS`` as the program (its own process, sys.argv[0] 'femadh') with
    ``spy`` (Python run first, e.g. patches that print to stderr); (exit code, stderr)."""
    import subprocess
    import sys

    code = ("import sys\nsys.argv = ['femadh'] + sys.argv[1:]\n" + spy
            + "\nfrom femadh.cli import main\nsys.exit(main())\n")
    env = {**os.environ, "OPENBLAS_NUM_THREADS": "1"}
    env.pop("COVERAGE_PROCESS_START", None)
    env.pop("PYTHONUNBUFFERED", None)                  # (a pipe is block-buffered)
    p = subprocess.run([sys.executable, "-c", code, *map(str, args)], capture_output=True,
                       text=True, cwd=os.path.join(os.path.dirname(__file__), ".."), env=env)
    return p.returncode, p.stderr


#: prints what the figure worker was asked and left undrawn
SPY = """
from femadh.runner import figures
real = figures.FigureWorker.draw
def spy(self, res, folder, *only):
    left = real(self, res, folder, *only)
    print("WORKER LEFT", left, file=sys.stderr)
    return left
figures.FigureWorker.draw = spy
"""


FIGURES = ["force_curve.png", "profiles_and_forces.png"]


@pytest.fixture(scope="module")
def drawn_here(tmp_path_factory):
    """The small scene and two of its command-line runs (--quiet --no-estimate) whose
    figures are drawn in this process, with FigureWorker made to fail if started: ``one``,
    the program on one core (:func:`femadh.cli._main` as the program, the affinity one CPU;
    the program's own start-up and exit are the tests' below that run it as a process),
    ``script``, :func:`femadh.cli.main` called by a script. They are the worker test's
    reference pictures too (they were a run of the Python API: the same in-process drawing)."""
    from femadh import cli
    from femadh.runner import figures

    tmp = tmp_path_factory.mktemp("drawn_here")
    path = _small_scene(tmp)
    run = ["run", str(path), "--quiet", "--no-estimate"]
    real_init, real_aff = figures.FigureWorker.__init__, os.sched_getaffinity

    def no_fork(self):
        raise AssertionError("a figure worker was started")
    try:
        figures.FigureWorker.__init__ = no_fork
        os.sched_getaffinity = lambda pid: {0}
        one = cli._main(run + ["--out", str(tmp / "one")], program=True)
        os.sched_getaffinity = real_aff
        script = cli.main(run + ["--out", str(tmp / "script")])
    finally:
        figures.FigureWorker.__init__, os.sched_getaffinity = real_init, real_aff
    return path, {"one": (one, tmp / "one"), "script": (script, tmp / "script")}


@needs_worker
def test_the_program_has_its_figures_drawn_by_the_worker(tmp_path, drawn_here):
    """The worker writes every figure (none left to the run): the same files, byte for
    byte, as a run draws in-process."""
    path, here = drawn_here
    code, err = _program(tmp_path, ["run", path, "--out", tmp_path / "cli", "--quiet",
                                    "--no-estimate"], SPY)
    assert code == 0, err
    assert "WORKER LEFT []" in err
    for code, folder in here.values():
        assert code == 0 and _pngs(folder) == FIGURES
    assert _pngs(tmp_path / "cli") == FIGURES
    for name in FIGURES:
        # the same data, the same matplotlib: the same picture, byte for byte
        for _, folder in here.values():
            assert (tmp_path / "cli" / name).read_bytes() == (folder / name).read_bytes()
    assert _no_temporary_files(tmp_path / "cli")


@needs_worker
def test_a_dead_worker_leaves_its_figures_to_the_run(tmp_path):
    import signal

    import femadh
    from femadh.runner.figures import figure_worker

    scene = femadh.load_scene(_small_scene(tmp_path))
    with figure_worker() as worker:
        os.kill(worker.pid, signal.SIGKILL)
        res = femadh.run(scene, tmp_path / "out", progress=False, estimate="peak")
    assert res.status == "converged" and "figures_s" in res.timings
    assert _pngs(tmp_path / "out") == ["force_curve.png", "profiles_and_forces.png"]


@needs_worker
def test_a_signal_while_the_worker_draws_stops_the_run_and_the_worker(tmp_path, monkeypatch):
    """SIGINT arriving while the run waits for its worker: the run ends "interrupted", the
    worker is stopped and reaped, and the folder holds no temporary or partial figure."""
    import signal

    import femadh
    from femadh import interrupt
    from femadh.runner import figures
    from PIL import Image

    scene = femadh.load_scene(_small_scene(tmp_path))
    res = femadh.run(scene, tmp_path / "out", progress=False, figures=False, estimate="peak")
    real = figures._recv
    with figures.figure_worker() as worker:
        pid = worker.pid

        def interrupted_recv(fd):
            os.kill(os.getpid(), signal.SIGINT)       # the user's Ctrl-C, job sent
            return real(fd)
        monkeypatch.setattr(figures, "_recv", interrupted_recv)
        with interrupt.interruptible():
            figures.draw_figures(res, SimpleNamespace(path=tmp_path / "out"))
    assert res.status == "interrupted" and "while drawing the figures" in res.error
    with pytest.raises(ChildProcessError):
        os.waitpid(pid, os.WNOHANG)
    folder = tmp_path / "out"
    assert _no_temporary_files(folder)
    for name in _pngs(folder):                         # whole or absent
        Image.open(folder / name).verify()


def test_no_worker_without_figures_on_one_core_or_inside_a_script(tmp_path, drawn_here):
    """--no-figures forks nothing; on one core, or when a script calls femadh.cli.main, the
    figures are drawn in-process (drawn_here: a worker started there fails its run)."""
    forked = ("from femadh.runner import figures\nreal = figures.FigureWorker.__init__\n"
              "def init(self):\n    print('FORKED', file=sys.stderr)\n    real(self)\n"
              "figures.FigureWorker.__init__ = init\n")
    path, here = drawn_here
    run = ["run", path, "--quiet", "--no-estimate"]
    code, err = _program(tmp_path, run + ["--out", tmp_path / "bare", "--no-figures"], forked)
    assert code == 0 and "FORKED" not in err, err
    assert _pngs(tmp_path / "bare") == []
    for code, folder in here.values():
        assert code == 0 and _pngs(folder) == FIGURES


def test_the_program_ends_at_once_with_its_output_and_exit_code(tmp_path):
    """``python -m femadh run`` skips the interpreter's teardown (cli.main): what it printed
    into a pipe (block-buffered) still arrives, and its exit codes are kept."""
    import subprocess
    import sys

    root = os.path.join(os.path.dirname(__file__), "..")
    path = _small_scene(tmp_path)
    cmd = [sys.executable, "-m", "femadh", "run", str(path), "--out", str(tmp_path / "o"),
           "--no-estimate", "--no-figures"]
    env = {**os.environ, "OPENBLAS_NUM_THREADS": "1"}
    env.pop("COVERAGE_PROCESS_START", None)
    env.pop("PYTHONUNBUFFERED", None)                  # (a pipe is block-buffered)
    p = subprocess.run(cmd, capture_output=True, text=True, cwd=root, env=env)
    assert p.returncode == 0, p.stderr
    assert "max adhesion" in p.stdout                 # the summary lines, from a pipe
    assert (tmp_path / "o" / "summary.json").exists()
    again = subprocess.run(cmd, capture_output=True, text=True, cwd=root, env=env)
    assert again.returncode == 4                      # the folder holds a run
    assert again.stderr.startswith("femadh: error: ") and "--overwrite" in again.stderr
