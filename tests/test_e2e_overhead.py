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

    scene = femadh.load_scene(os.path.join(os.path.dirname(__file__), "..", "validation",
                                           "scenes", "paper1_fig3.toml"))
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
