"""The fault matrix of a single run: a signal at each phase, then ``--resume``; damaged files.

``python -m validation.fault_matrix`` writes validation/results/fault_matrix.md (about a
minute on two cores, one BLAS thread).

Each cell runs the command line in this process (``femadh.cli.main``) on a short scene (the
Fig 3 scene on 200 uniform nodes, 36 separations each way, with its error estimate and
figures: ~1 s) and sends SIGINT or SIGTERM to itself at a chosen phase - the operator build,
the sweep (after the 20th state, so that it lands inside a Newton iteration of the 21st), the
peak search, an error-estimate member, the figures - by wrapping that phase's function. It
records the exit code, the status in summary.json, the time from the signal to the run's
return, then runs ``--resume`` and compares its summary.json field by field with an
uninterrupted run's (timings and wall times excepted), and curve.csv row by row.

The damaged-folder cells damage a folder stopped in the sweep in one way each and record the
one line ``--resume`` answers with and its exit code.
"""
import argparse
import contextlib
import io
import json
import math
import os
from pathlib import Path
import shutil
import signal
import tempfile
import time

ROOT = Path(__file__).resolve().parents[1]
#: summary.json fields that legitimately differ between two runs of one scene
VOLATILE = ("timings_s", "wall_time_s")


def short_scene(folder, nodes=200, step="0.2 nm", extra=""):
    """The Fig 3 scene on uniform nodes (its file, written into ``folder``)."""
    text = (ROOT / "validation" / "scenes" / "paper1_fig3.toml").read_text()
    text = text.replace("[solver]\n", f"[solver]\nnodes = {nodes}\n", 1)
    text = text.replace('step = "0.2 nm"', f'step = "{step}"') + extra
    p = Path(folder) / "short.toml"
    p.write_text(text)
    return p


class Signal:
    """Send ``sig`` to this process when the wrapped phase function is called (its
    ``after``-th call), remembering when."""

    def __init__(self, sig, after=1):
        self.sig, self.after, self.calls, self.sent = sig, after, 0, None

    def wrap(self, fn, when=None):
        def wrapped(*a, **kw):
            self.calls += 1
            if self.sent is None and self.calls >= self.after and (when is None
                                                                   or when(*a, **kw)):
                self.sent = time.perf_counter()
                os.kill(os.getpid(), self.sig)
            return fn(*a, **kw)
        return wrapped


@contextlib.contextmanager
def phase(name, sig):
    """Patch the phase ``name`` to send ``sig`` as it runs; yields the Signal."""
    import femadh.io.plots as plots
    import femadh.runner.contact as contact
    import femadh.runner.estimates as estimates

    s = Signal(sig)
    saved = []

    def patch(obj, attr, new):
        saved.append((obj, attr, getattr(obj, attr)))
        setattr(obj, attr, new)
    if name == "operator":
        patch(contact, "build_problem", s.wrap(contact.build_problem))
    elif name == "sweep":
        s.after = 20
        patch(contact.Sink, "state", s.wrap(contact.Sink.state))
    elif name == "peak search":
        patch(estimates, "peak_adhesion", s.wrap(estimates.peak_adhesion))
    elif name == "estimate":
        # the first coarser member's run (an in-memory run inside the run)
        patch(contact, "_run", s.wrap(contact._run, when=lambda sc, folder, **kw:
                                      folder is None))
    elif name == "figures":
        patch(plots, "contact_figures", s.wrap(plots.contact_figures))
    else:
        raise ValueError(name)
    try:
        yield s
    finally:
        for obj, attr, old in reversed(saved):
            setattr(obj, attr, old)


def cli(*argv):
    """(exit code, stderr) of ``femadh`` in this process."""
    from femadh.cli import main

    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        code = main([str(a) for a in argv])
    return code, err.getvalue()


def summary(out):
    return json.loads((Path(out) / "summary.json").read_text())


def differences(a, b, path=""):
    """Field paths where two summaries differ (volatile fields excepted)."""
    if isinstance(a, dict) and isinstance(b, dict):
        out = []
        for k in sorted(set(a) | set(b)):
            if k in VOLATILE:
                continue
            out += differences(a.get(k), b.get(k), f"{path}.{k}" if path else k)
        return out
    if isinstance(a, list) and isinstance(b, list) and len(a) == len(b):
        return [x for i, (u, v) in enumerate(zip(a, b)) for x in differences(u, v,
                                                                            f"{path}[{i}]")]
    same = a == b or (isinstance(a, float) and isinstance(b, float) and math.isnan(a)
                      and math.isnan(b))
    return [] if same else [path]


def relative_gap(a, b):
    """The largest relative difference of the numbers two summaries share (volatile fields
    excepted), and where."""
    worst = (0.0, "")

    def walk(u, v, path):
        nonlocal worst
        if isinstance(u, dict) and isinstance(v, dict):
            for k in set(u) & set(v):
                if k not in VOLATILE:
                    walk(u[k], v[k], f"{path}.{k}")
        elif isinstance(u, list) and isinstance(v, list) and len(u) == len(v):
            for i, (x, y) in enumerate(zip(u, v)):
                walk(x, y, f"{path}[{i}]")
        elif isinstance(u, float) and isinstance(v, float) and math.isfinite(u) \
                and math.isfinite(v) and u != v:
            r = abs(u - v) / max(abs(u), abs(v))
            if r > worst[0]:
                worst = (r, path)
    walk(a, b, "")
    return worst


def curve_rows(out):
    return (Path(out) / "curve.csv").read_text().splitlines()


def signal_cell(scene, out, name, sig, *flags):
    """Run with a signal at phase ``name``, then --resume. Returns a dict of what happened."""
    with phase(name, sig) as s:
        t0 = time.perf_counter()
        code, err = cli("run", scene, "--out", out, "--quiet", *flags)
        t1 = time.perf_counter()
    stopped = summary(out)["status"]
    latency = t1 - s.sent if s.sent is not None else math.nan
    code2, err2 = cli("run", scene, "--out", out, "--quiet", "--resume", *flags)
    return {"phase": name, "signal": signal.Signals(sig).name, "exit": code,
            "status": stopped, "latency_s": latency, "first_s": t1 - t0,
            "stderr": err.strip().splitlines()[-1] if err.strip() else "",
            "resume_exit": code2, "resume_status": summary(out)["status"],
            "resume_stderr": err2.strip()}


DAMAGES = {
    "empty curve.csv": lambda o: (o / "curve.csv").write_text(""),
    "duplicated last row": lambda o: (o / "curve.csv").write_text(
        (o / "curve.csv").read_text() + (o / "curve.csv").read_text().splitlines()[-1]
        + "\n"),
    "garbage bytes in curve.csv": lambda o: _garbage(o / "curve.csv", 6),
    "a changed digit in curve.csv": lambda o: _change_digit(o / "curve.csv", 4),
    "fields.csv truncated": lambda o: _cut(o / "fields.csv", 0.5),
    "fields.csv deleted": lambda o: (o / "fields.csv").unlink(),
    "diagnostics.csv deleted": lambda o: (o / "diagnostics.csv").unlink(),
    "jumps.csv deleted": lambda o: (o / "jumps.csv").unlink(),
    "summary.json truncated": lambda o: _cut(o / "summary.json", 0.3),
    "summary.json deleted": lambda o: (o / "summary.json").unlink(),
}


def _garbage(path, row):
    lines = path.read_bytes().split(b"\n")
    lines[row] = b"\x00\xff\xfe garbage \x81"
    path.write_bytes(b"\n".join(lines))


def _change_digit(path, row):
    lines = path.read_text().split("\n")
    cells = lines[row].split(",")
    cells[6] = cells[6][:-2] + ("1" if cells[6][-2] != "1" else "2") + cells[6][-1]
    lines[row] = ",".join(cells)
    path.write_text("\n".join(lines))


def _cut(path, fraction):
    data = path.read_bytes()
    path.write_bytes(data[:int(len(data) * fraction)])


def damage_cell(scene, out, name, flags=("--no-figures", "--no-estimate")):
    """Stop a run in its sweep, damage its folder one way, --resume: (exit, stderr, status,
    the rows equal to the reference's)."""
    with phase("sweep", signal.SIGTERM):
        cli("run", scene, "--out", out, "--quiet", *flags)
    DAMAGES[name](Path(out))
    code, err = cli("run", scene, "--out", out, "--quiet", "--resume", *flags)
    status = summary(out)["status"] if (Path(out) / "summary.json").exists() else "-"
    return {"damage": name, "exit": code, "stderr": err.strip(), "status": status}


def outside(scene, out, rows, delay, sig):
    """A real ``femadh run`` process signalled from outside once curve.csv has ``rows``
    rows (and ``delay`` s more): (exit code, seconds from the signal to its exit)."""
    import subprocess
    import sys

    p = subprocess.Popen([sys.executable, "-m", "femadh", "run", str(scene), "--out",
                          str(out), "--quiet"], cwd=ROOT, stdout=subprocess.DEVNULL,
                         stderr=subprocess.DEVNULL, env=dict(os.environ,
                                                             OPENBLAS_NUM_THREADS="1"))
    curve = Path(out) / "curve.csv"
    t0 = time.time()
    while not (curve.exists() and curve.read_text().count("\n") > rows):
        if p.poll() is not None or time.time() - t0 > 120:
            p.kill()
            return p.wait(), math.nan
        time.sleep(0.01)
    time.sleep(delay)
    t = time.perf_counter()
    p.send_signal(sig)
    code = p.wait()
    return code, time.perf_counter() - t


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=str(ROOT / "validation" / "results" / "fault_matrix.md"))
    ap.add_argument("--fig4", action="store_true", help="also the paper's Fig 4 scene (its "
                    "adaptive grid; ~30 s a run): SIGINT in each phase, then --resume")
    args = ap.parse_args(argv)
    os.environ.setdefault("FEMADH_MESH_PATH", str(ROOT / "meshes"))
    tmp = Path(tempfile.mkdtemp(prefix="femadh-faults-"))
    try:
        scene = short_scene(tmp)
        ref = tmp / "ref"
        t0 = time.perf_counter()
        assert cli("run", scene, "--out", ref, "--quiet")[0] == 0
        t_ref = time.perf_counter() - t0
        ref_summary, ref_rows = summary(ref), curve_rows(ref)
        lines = ["# Fault matrix: a single run", "",
                 "`python -m validation.fault_matrix` (this file; about a minute on two "
                 "cores). Scene: Fig 3 on 200 uniform nodes, 36 separations each way, with "
                 f"its error estimate and figures (uninterrupted: {t_ref:.2f} s). A signal "
                 "is sent by the process to itself as the phase runs (the sweep: at its "
                 "21st state); latency = from the signal to the run's return. Then `--resume`"
                 "; its summary.json is compared field by field with the uninterrupted "
                 "run's (timings excepted), curve.csv row by row.", "",
                 "| phase | signal | exit | status | latency | resume exit | summary "
                 "fields differing | largest relative difference | curve.csv rows "
                 "differing |", "|---|---|---|---|---|---|---|---|---|"]
        for name in ("operator", "sweep", "peak search", "estimate", "figures"):
            for sig in (signal.SIGINT, signal.SIGTERM):
                out = tmp / f"{name}-{sig}".replace(" ", "_")
                c = signal_cell(scene, out, name, sig)
                s = summary(out)
                diff = differences(ref_summary, s)
                gap, where = relative_gap(ref_summary, s)
                rows = curve_rows(out)
                nrow = sum(a != b for a, b in zip(rows, ref_rows)) + abs(len(rows)
                                                                         - len(ref_rows))
                lines.append(f"| {name} | {c['signal']} | {c['exit']} | {c['status']} | "
                             f"{c['latency_s'] * 1e3:.0f} ms | {c['resume_exit']} | "
                             f"{len(diff)}{' (' + ', '.join(diff[:3]) + ')' if diff else ''} "
                             f"| {gap:.1e}{' (' + where + ')' if where else ''} | {nrow} |")
        # as after a kill -9: no checkpoint, the last state re-solved from fields.csv
        out = tmp / "sweep-no-checkpoint"
        with phase("sweep", signal.SIGTERM):
            cli("run", scene, "--out", out, "--quiet")
        (out / "checkpoint.npz").unlink()
        code2 = cli("run", scene, "--out", out, "--quiet", "--resume")[0]
        s = summary(out)
        diff = differences(ref_summary, s)
        gap, where = relative_gap(ref_summary, s)
        hl_gap = relative_gap(ref_summary["headline"], s["headline"])
        rows = curve_rows(out)
        nrow = sum(a != b for a, b in zip(rows, ref_rows)) + abs(len(rows) - len(ref_rows))
        lines.append(f"| sweep, checkpoint.npz deleted (as after kill -9) | SIGTERM | 143 | "
                     f"interrupted | - | {code2} | {len(diff)} | {gap:.1e} ({where}); "
                     f"headline {hl_gap[0]:.1e} | {nrow} |")
        if args.fig4:
            fig4 = ROOT / "validation" / "scenes" / "paper1_fig4.toml"
            assert cli("run", fig4, "--out", tmp / "fig4-ref", "--quiet")[0] == 0
            f4 = summary(tmp / "fig4-ref")
            for name in ("sweep", "peak search", "estimate", "figures"):
                out = tmp / f"fig4-{name}".replace(" ", "_")
                c = signal_cell(fig4, out, name, signal.SIGINT)
                s = summary(out)
                diff = differences(f4, s)
                nrow = curve_rows(out) != curve_rows(tmp / "fig4-ref")
                lines.append(f"| Fig 4 (adaptive): {name} | SIGINT | {c['exit']} | "
                             f"{c['status']} | {c['latency_s'] * 1e3:.0f} ms | "
                             f"{c['resume_exit']} | {len(diff)} | "
                             f"{relative_gap(f4, s)[0]:.1e} | {'all' if nrow else 0} |")
            hl = f4["headline"]
            lines += ["", f"Fig 4 uninterrupted: max adhesion {hl['max_adhesion_N'] * 1e6:.5g}"
                      f" ± {hl['max_adhesion_N_error'] * 1e6:.2g} µN at d = "
                      f"{hl['d_at_max_adhesion_m'] * 1e9:.5g} nm; every resumed run above "
                      "ends with the same numbers."]
        (tmp / "n800").mkdir()
        big = short_scene(tmp / "n800", nodes=800)
        said = []
        for label, rows, delay, sig in (("sweep", 20, 0.0, signal.SIGINT),
                                        ("estimate members", 72, 0.5, signal.SIGTERM)):
            code, dt = outside(big, tmp / f"out-{rows}", rows, delay, sig)
            said.append(f"{label}: exit {code} {dt * 1e3:.0f} ms")
        lines += ["", "From outside, a real `femadh run` process (the scene on 800 nodes, "
                  "~40 ms a state) signalled while it runs, to its exit (interpreter "
                  "shutdown included): " + "; ".join(said) + "."]
        lines += ["", "A run stopped inside its sweep saves its last committed state whole "
                  "(checkpoint.npz: the factorisation the next step predicts from included), "
                  "so the resumed sweep is bit for bit the uninterrupted one. Without it (a "
                  "kill -9) the state is re-solved by Newton from fields.csv, which moves the "
                  "following states by the solver tolerance's effect: the last row above "
                  "(the largest relative difference is of an error estimate's grid part, a "
                  "difference of nearly equal numbers; tests/test_fault_matrix.py bounds each "
                  "number by 1e-9 of its quantity).", "",
                  "## Damaged folders", "",
                  "A run stopped by SIGTERM in its sweep, its folder damaged one way, then "
                  "`--resume` (no figures, no estimate):", "",
                  "| damage | exit | what --resume says | status after |", "|---|---|---|---|"]
        for name in DAMAGES:
            out = tmp / ("dmg-" + name.replace(" ", "_").replace(".", "_"))
            c = damage_cell(scene, out, name)
            said = " / ".join(c["stderr"].splitlines()) or "(nothing)"
            lines.append(f"| {name} | {c['exit']} | {said.replace('|', '/')} | "
                         f"{c['status']} |")
        Path(args.out).write_text("\n".join(lines) + "\n")
        print("\n".join(lines))
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    main()
