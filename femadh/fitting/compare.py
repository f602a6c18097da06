"""A measured curve against a femadh run: the model at every measured point, the residual,
the contact points and jumps of both, and one figure.

The contact-point offset (``d = z - z_offset``) is the best one for the run unless given: a
shift of the run's curve, no further run (:func:`femadh.fitting.model.initial_offset`).
"""
from dataclasses import dataclass, field
import csv
import io
import json
import math
from pathlib import Path

import numpy as np

from .model import coverage, initial_offset, sim_curve

#: a measured step counts as a jump when it is this many times the branch's median step
JUMP_RATIO = 5.0


@dataclass
class Comparison:
    """``model``, ``residual`` (N, AFM sign) per measured point; ``offset`` (m); ``rms`` (N);
    ``outside``: points beyond the simulated range; ``contact``: {"measured", "simulated"} z
    (m, nan when none); ``jumps``: {"measured": [(branch, z, f_before, f_after)], "simulated":
    [...]}."""

    curve: object
    sim: object
    offset: float
    model: np.ndarray
    residual: np.ndarray
    rms: float
    outside: int
    contact: dict = field(default_factory=dict)
    jumps: dict = field(default_factory=dict)

    def as_json(self):
        return {"rms_residual_N": self.rms, "z_offset_m": self.offset,
                "points": len(self.curve), "outside_simulated_range": self.outside,
                "simulated_position": self.sim.x_kind,
                "contact_point_z_m": {k: _num(v) for k, v in self.contact.items()},
                "jumps": {k: [{"branch": b, "z_m": z, "force_before_N": f0,
                               "force_after_N": f1} for b, z, f0, f1 in v]
                          for k, v in self.jumps.items()}}


def _num(x):
    return None if not math.isfinite(x) else float(x)


def compare(res_or_sim, curve, offset=None):
    """Compare a run (ContactResult, or a SimCurve) with a measured ForceCurve."""
    sim = res_or_sim if hasattr(res_or_sim, "force_at") else sim_curve(res_or_sim)
    from ..errors import SceneError

    for b in curve.branches():
        if b not in sim.x:
            raise SceneError(None, "sweep.directions", "(without " + b + ")",
                             f"a {b} branch: the measured curve has {b} points")
    off = initial_offset(sim, curve) if offset is None else float(offset)
    model = sim.force_at(curve.z, curve.branch, off)
    r = model - curve.force
    rms = math.sqrt(float(r @ r) / len(r))
    sim_jumps = [(b, x + off, f0, f1) for b, x, f0, f1 in sim.jumps]
    return Comparison(curve, sim, off, model, r, rms, coverage(sim, curve, off),
                      {"measured": measured_contact(curve), "simulated": off},
                      {"measured": measured_jumps(curve), "simulated": sim_jumps})


def measured_contact(curve):
    """The measured contact point (m): where the approach force, repulsive (> 0) at every
    point from the lowest z up, first turns attractive (<= 0), interpolated; nan when the
    lowest point does not repel (noise crossings far out are not contact)."""
    sel = curve.branch == "approach"
    if not sel.any():
        sel = curve.branch == "retract"
    z, f = curve.z[sel], curve.force[sel]
    k = np.argsort(z)
    z, f = z[k], f[k]
    if not len(f) or f[0] <= 0:
        return math.nan
    i = int(np.argmax(f <= 0)) - 1          # the last point of the repulsive run from below
    if i < 0:
        return math.nan                     # repulsive everywhere: contact beyond the data
    return float(z[i] + (z[i + 1] - z[i]) * f[i] / (f[i] - f[i + 1]))


def measured_jumps(curve):
    """Per branch, the largest force step between neighbouring points when it exceeds
    JUMP_RATIO x the branch's median step: (branch, z mid-way, force before, force after)."""
    out = []
    for b in curve.branches():
        sel = np.flatnonzero(curve.branch == b)
        if len(sel) < 3:
            continue
        df = np.abs(np.diff(curve.force[sel]))
        k = int(np.argmax(df))
        med = float(np.median(df))
        if df[k] > JUMP_RATIO * med and df[k] > 0:
            i, j = sel[k], sel[k + 1]
            out.append((b, float(0.5 * (curve.z[i] + curve.z[j])), float(curve.force[i]),
                        float(curve.force[j])))
    return out


def write_comparison(cmp, out_dir, name="compare", title=None):
    """``<name>.png`` (measured and simulated curves, contact points, jumps; residual below),
    ``<name>.csv`` (per point) and ``<name>.json`` into ``out_dir``, each atomically.
    Returns the figure's path."""
    from ..errors import OutputError
    from ..io.atomic import write_atomic

    out = Path(out_dir)
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise OutputError(f"cannot create the output folder {out}: {exc.strerror}") from None
    c = cmp.curve
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(["branch", "z_m", "force_N", "model_force_N", "residual_N"])
    for row in zip(c.branch, c.z, c.force, cmp.model, cmp.residual):
        w.writerow([row[0]] + [repr(float(v)) for v in row[1:]])
    png = out / f"{name}.png"
    _figure(cmp, png, title)
    write_atomic(out / f"{name}.csv", buf.getvalue())
    write_atomic(out / f"{name}.json", json.dumps(cmp.as_json(), indent=1) + "\n")
    return png


def _figure(cmp, path, title):
    from ..io.plots import _pyplot, _save, force_unit

    plt = _pyplot()
    c, sim, off = cmp.curve, cmp.sim, cmp.offset
    fs, fl = force_unit(np.r_[c.force, cmp.model])
    zs = 1e9
    fig, (ax, axr) = plt.subplots(2, 1, figsize=(7, 7), sharex=True,
                                  gridspec_kw={"height_ratios": [3, 1]})
    colours = {"approach": "tab:blue", "retract": "tab:red"}
    zlo, zhi = float(np.min(c.z)), float(np.max(c.z))
    for b in c.branches():
        sel = c.branch == b
        ax.plot(c.z[sel] * zs, c.force[sel] * fs, "o", ms=3.5, mfc="none",
                color=colours[b], label=f"measured {b}")
        x = sim.x[b] + off
        keep = (x >= zlo - 0.05 * (zhi - zlo)) & (x <= zhi + 0.05 * (zhi - zlo))
        ax.plot(x[keep] * zs, sim.f[b][keep] * fs, "-", color=colours[b], lw=1.2,
                label=f"simulated {b} ({'in z' if sim.x_kind == 'z' else 'd + offset'})")
        axr.plot(c.z[sel] * zs, cmp.residual[sel] * fs, "o", ms=3, color=colours[b])
    for who, style in (("measured", ":"), ("simulated", "--")):
        zc = cmp.contact.get(who, math.nan)
        if math.isfinite(zc):
            ax.axvline(zc * zs, color="0.4", ls=style, lw=0.8,
                       label=f"{who} contact point {zc * zs:.3g} nm")
        for b, z, f0, f1 in cmp.jumps.get(who, []):
            ax.annotate("", xy=(z * zs, f1 * fs), xytext=(z * zs, f0 * fs),
                        arrowprops={"arrowstyle": "->", "color": colours[b],
                                    "ls": "solid" if who == "simulated" else "dotted"})
            ax.plot([], [], color=colours[b], ls=style, label=f"{who} {b} jump at "
                    f"{z * zs:.3g} nm")
    ax.axhline(0, color="0.7", lw=0.6)
    ax.set_ylabel(f"force on the tip ({fl}), repulsive > 0")
    ax.legend(fontsize=7, loc="best")
    ax.set_title(title or f"{Path(c.source).name}: rms residual {cmp.rms * fs:.3g} {fl}, "
                 f"offset {off * zs:.4g} nm")
    axr.axhline(0, color="0.5", lw=0.6)
    axr.set_ylabel(f"model - measured ({fl})")
    axr.set_xlabel(f"z (nm; measured column '{c.columns.get('z', 'z')}'); d = z - offset")
    fig.tight_layout()
    _save(fig, path)
    plt.close(fig)
