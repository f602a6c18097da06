"""A study's table (study.csv, study.parquet with pyarrow) and its figure (study.png).

The table is tidy: one row per point that has an outcome, the varied values as numbers in SI
with the unit in the column header (``effects.asperity_gap.sigma_m``) and, in ``label``, as
typed (``effects.asperity_gap.sigma = 0.8 nm``); then the status, the error and the headline
numbers (SI, unit in the name). What depends on the schedule rather than the physics (which
worker reused an operator, wall times, pids) stays in each point's record.json, so that a
study interrupted and run again writes the same table, cell by cell, as one run at once.
"""
import csv
import io
import math
from pathlib import Path

import numpy as np

from .atomic import save_atomic, write_atomic

#: record fields that are not table columns (schedule, bookkeeping)
_NOT_COLUMNS = ("index", "pid", "wall_time_s", "signum", "operator_reused", "finished")


def table_rows(points, records):
    """(header, rows) of a study's table; rows of the points with an outcome, in order."""
    from ..scene.values import si_columns, si_value

    cols = si_columns(points)
    numbers = sorted({k for r in records.values() for k, v in r.items()
                      if isinstance(v, (int, float)) and not isinstance(v, bool)
                      and k not in _NOT_COLUMNS})
    header = ["index", "id", "label"] + [h for h, _, _ in cols] + ["status", "error"] + numbers
    rows = []
    for p in points:
        r = records.get(p.id)
        if r is None or r.get("status") in ("running", "interrupted"):
            continue                # no outcome yet: the study's next run computes it
        label = ", ".join(f"{k} = {v}" for k, v in p.changes.items())
        row = [p.index, p.id, label]
        for _, k, dim in cols:
            row.append(si_value(p.changes[k])[0] if dim else p.changes[k])
        row += [r["status"], r.get("error") or ""] + [r.get(k, "") for k in numbers]
        rows.append(row)
    return header, rows


def write_table(points, records, out):
    """study.csv (and study.parquet with pyarrow): one row per point, tidy, SI."""
    header, rows = table_rows(points, records)
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(header)
    w.writerows(rows)
    write_atomic(Path(out) / "study.csv", buf.getvalue())
    try:
        import pyarrow as pa
        import pyarrow.parquet as pq
    except ImportError:
        return
    cols = list(zip(*rows)) if rows else [[] for _ in header]

    def column(values):
        # a column of numbers (missing cells as null) stays numeric; anything else is text
        vals = [None if v == "" else v for v in values]
        if all(v is None or (isinstance(v, (int, float)) and not isinstance(v, bool))
               for v in vals):
            return vals
        return [None if v is None else str(v) for v in vals]

    table = pa.table({h: column(c) for h, c in zip(header, cols)})
    save_atomic(Path(out) / "study.parquet", lambda p: pq.write_table(table, p))


def study_figure(points, records, out, quantity="max_adhesion_N"):
    """One varied key: the quantity against it; two: a heat map over both.

    Returns the path, or None when there is nothing to draw (more than two keys, or no point
    with a finite value of the quantity: every point failed). No empty figure is written,
    and a study.png of an earlier run of the folder is removed rather than left standing."""
    from ..scene.values import si_value

    keys = list(points[0].changes) if points else []
    vals = [(p, records[p.id].get(quantity, math.nan)) for p in points
            if records.get(p.id, {}).get("status") == "converged"]
    vals = [(p, v) for p, v in vals if isinstance(v, (int, float)) and math.isfinite(v)]
    path = Path(out) / "study.png"
    if not vals or len(keys) not in (1, 2):
        if not vals and path.exists():
            path.unlink()
        return None
    from .plots import _pyplot, force_unit, length_unit

    si_unit = {"pressure": "Pa", "energy": "J", "surface_energy": "J/m²",
               "temperature": "K", "areal_density": "1/m²", "molar_volume": "m³/mol"}

    def parsed(v):
        x, dim = si_value(v)
        return (float(x), dim) if isinstance(x, (int, float)) else (math.nan, None)

    def axis(key):
        """{study value: plotted number} and the axis label, in a unit fitting the values."""
        raw = {repr(p.changes[key]): parsed(p.changes[key]) for p, _ in vals}
        dims = {d for _, d in raw.values()}
        scale, unit = 1.0, ""
        if dims == {"length"}:
            scale, unit = length_unit([x for x, _ in raw.values()])
        elif len(dims) == 1 and None not in dims:
            unit = si_unit[dims.pop()]
        label = key.split(".")[-1].replace("_", " ") + (f" ({unit})" if unit else "")
        return {k: x * scale for k, (x, _) in raw.items()}, f"{label}  [{key}]"

    plt = _pyplot()
    y = np.array([v for _, v in vals], float)
    fs, fl = force_unit(y) if quantity.endswith("_N") else (1.0, "")
    qlabel = quantity.removesuffix("_N").replace("_", " ") + (f" ({fl})" if fl else "")
    fig, ax = plt.subplots(figsize=(7, 5))
    if len(keys) == 1:
        xmap, xl = axis(keys[0])
        x = np.array([xmap[repr(p.changes[keys[0]])] for p, _ in vals])
        order = np.argsort(x)
        # each value with its estimated error (nan where a run had no estimate)
        err = np.array([records[p.id].get(quantity + "_error", math.nan) for p, _ in vals],
                       float)
        ax.errorbar(x[order], y[order] * fs, yerr=np.abs(err[order]) * fs, fmt="o-",
                    capsize=3)
        ax.set(xlabel=xl, ylabel=qlabel)
        _verdicts(ax, [(xv, yv * fs, records[p.id].get("instrument_stuck"))
                       for (p, _), xv, yv in zip(vals, x, y)])
        ax.grid(alpha=0.3)
    else:
        (xmap, xl), (ymap, yl) = axis(keys[0]), axis(keys[1])
        xs, ys = sorted(set(xmap.values())), sorted(set(ymap.values()))
        Z = np.full((len(ys), len(xs)), np.nan)
        for (p, v) in vals:
            Z[ys.index(ymap[repr(p.changes[keys[1]])]),
              xs.index(xmap[repr(p.changes[keys[0]])])] = v * fs
        im = ax.pcolormesh(_edges(xs), _edges(ys), Z, shading="flat", cmap="viridis")
        fig.colorbar(im, ax=ax, label=qlabel)
        ax.set(xlabel=xl, ylabel=yl)
        _verdicts(ax, [(xmap[repr(p.changes[keys[0]])], ymap[repr(p.changes[keys[1]])],
                        records[p.id].get("instrument_stuck")) for p, _ in vals])
    name = getattr(getattr(points[0], "scene", None), "name", "study")
    ax.set_title(f"{name}: " + quantity.removesuffix("_N").replace("_", " ")
                 + (" ± estimated error" if len(keys) == 1 else ""))
    fig.tight_layout()
    save_atomic(path, lambda p: fig.savefig(p, dpi=110))
    plt.close(fig)
    return path


def _verdicts(ax, points):
    """The MEMS verdict of each point (scenes with [instrument] rest_gap): a red cross where
    the part stays stuck, a white circle where its suspension frees it."""
    stuck = [(x, y) for x, y, v in points if v == 1.0]
    free = [(x, y) for x, y, v in points if v == 0.0]
    if stuck:
        ax.plot(*zip(*stuck), "x", color="tab:red", ms=9, mew=2, ls="", label="stuck")
    if free:
        ax.plot(*zip(*free), "o", mfc="white", mec="k", ms=7, ls="", label="frees itself")
    if stuck or free:
        ax.legend(loc="best", fontsize=8)


def _edges(c):
    c = np.asarray(c, float)
    if c.size == 1:
        return np.array([c[0] * 0.9, c[0] * 1.1]) if c[0] else np.array([-0.5, 0.5])
    mid = 0.5 * (c[1:] + c[:-1])
    return np.concatenate([[c[0] - (mid[0] - c[0])], mid, [c[-1] + (c[-1] - mid[-1])]])
