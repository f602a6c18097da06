"""The lines a run prints: per branch its states and largest adhesion, the headline numbers
with their estimated errors, the jumps. Forces in the unit that fits their size."""


def _force(x, err=None):
    from ..io.plots import force_text     # (one formatting for the terminal and the figures)

    return force_text(x, err)


def _pm(v, err, digits):
    """``v ± err``, the value to the error's decimal place (io.plots.value_error_text)."""
    from ..io.plots import value_error_text

    return value_error_text(v, err, digits)


def _nm(x):
    return f"{x * 1e9:.4g} nm"


def headline_lines(res):
    """Human-readable summary lines of a ContactResult.

    One largest-adhesion number with its estimated error (the peak located between the
    computed separations; the per-branch lines count states and jumps and show no second
    adhesion value), the forces at the deepest separation, the accuracy reached, the jumps,
    and notes in plain words: what failed and what that means for the stated errors."""
    out = []
    hl = res.headline
    for b, c in res.branches.items():
        if not len(c["d_m"]):
            continue
        n_j = sum(j["branch"] == b for j in res.jumps)
        out.append(f"{b}: {len(c['d_m'])} states from d = {_nm(c['d_m'][0])} to "
                   f"{_nm(c['d_m'][-1])}" + (f", {n_j} jump{'s' * (n_j > 1)}" if n_j else ""))
    if "max_adhesion_N" in hl:
        from ..io.plots import max_adhesion_text    # (the force curve's inset says it too)

        out.append(max_adhesion_text(hl)
                   + (f" (DMT 2πRW = {_force(hl['dmt_pull_off_N'])}, JKR 1.5πRW = "
                      f"{_force(hl['jkr_pull_off_N'])})" if "dmt_pull_off_N" in hl else ""))
    if "F_ex_deepest_N" in hl:
        out.append(f"F_ex(d = {hl['d_deepest_m'] * 1e9:.4g} nm) = "
                   f"{_force(hl['F_ex_deepest_N'], hl.get('F_ex_deepest_N_error'))}, F_LJ = "
                   f"{_force(hl['F_LJ_deepest_N'], hl.get('F_LJ_deepest_N_error'))}")
    # a run stopped by a signal or its time limit has not judged its accuracy: it says so
    # (a newcomer read "NOT met" after a Ctrl-C as a verdict on the numbers)
    stopped = getattr(res, "status", None) in ("interrupted", "time limit")

    def verdict(a):
        return (f"not assessed ({res.status})" if stopped and not a["met"]
                else "met" if a["met"] else "NOT met")
    if res.accuracy and res.accuracy.get("steps"):
        a = res.accuracy
        grid = (f"{a['nodes']} nodes, band spacing {a['spacing_m'] * 1e9:.3g} nm to "
                f"{a['band_m'] * 1e6:.3g} µm" if a.get("adaptive") and a.get("spacing_m")
                and a.get("band_m") else f"N = {a.get('nodes')}")
        # a request refused before any grid ran has no radius: say so, not crash on None
        radius = (f", analysis radius {a['analysis_radius_m'] * 1e6:.4g} µm"
                  if a.get("analysis_radius_m") is not None else "")
        out.append(f"accuracy {a['target']:g} {verdict(a)}: {grid}"
                   f"{radius} after {len(a.get('steps', ()))} run(s)")
    if res.accuracy and res.accuracy.get("route") == "edge-branch":
        a = res.accuracy
        out.append(f"accuracy {a['target']:g} {verdict(a)} on the edge "
                   f"route: {a['members']} grids, the finest {a['nodes']} nodes, estimated "
                   f"relative error {a['estimated_rel_error']:.1g} of the max adhesion")
    for j in res.jumps:
        where = (f"±{j['resolution_m'] * 1e9:.1e} nm" if j["resolution_m"] > 0 else
                 "traced fold, dd/ds = 0")
        out.append(f"jump ({j['branch']}): branch folds at d = {j['d_fold_m'] * 1e9:.4f} nm "
                   f"({where}), h0 {j['h0_before_m'] * 1e9:.3f} -> {j['h0_after_m'] * 1e9:.3f} "
                   "nm")
    if res.instrument is not None:
        out += _instrument_lines(res)
    for w in res.warnings:
        out.append(f"note: {w[len(NOTE):]}" if w.startswith(NOTE) else f"warning: {w}")
    return out


#: warnings that are notes on the error estimate (printed as "note: ...", the prefix
#: dropped; summary.json keeps them whole)
NOTE = "error estimate: "


def _instrument_lines(res):
    """What the instrument records: its pull-off and snap-off, where it jumps (d and z)."""
    hl, k = res.headline, res.instrument["spring"]["stiffness_N_per_m"]

    def nm(name):
        v, e = hl[name] * 1e9, hl.get(f"{name}_error")
        return f"{_pm(v, e * 1e9, 8)} nm" if e is not None else f"{v:.4f} nm"
    line = f"instrument k = {k:.4g} N/m:"
    if "instrument_pull_off_N" in hl:
        line += (f" pull-off {_force(hl['instrument_pull_off_N'], hl.get('instrument_pull_off_N_error'))}")
    if "instrument_snap_off_N" in hl:
        line += (f", snaps off at {_force(hl['instrument_snap_off_N'], hl.get('instrument_snap_off_N_error'))}")
    out = [line]
    if "instrument_pull_off_N" in hl:
        out.append(_tail_line(res))
    if "instrument_jump_in_z_m" in hl:
        out.append(f"instrument jumps in at z = {nm('instrument_jump_in_z_m')} (d = "
                   f"{nm('instrument_jump_in_d_m')})")
    if "instrument_jump_out_z_m" in hl:
        out.append(f"instrument jumps out at z = {nm('instrument_jump_out_z_m')} (d = "
                   f"{nm('instrument_jump_out_d_m')})")
    if "instrument_stuck" in hl:
        g = res.instrument["spring"]["rest_gap_m"]
        out.append(f"MEMS verdict: {'STUCK' if hl['instrument_stuck'] else 'free'} at rest gap "
                   f"{g * 1e9:.4g} nm (restoring force k g = {_force(k * g)}"
                   + (f", jump-out at z = {hl['instrument_jump_out_z_m'] * 1e9:.4g} nm)"
                      if "instrument_jump_out_z_m" in hl else ", no jump-out: it peels off "
                      "continuously)"))
    if "instrument_hysteresis_J" in hl:
        e = hl.get("instrument_hysteresis_J_error")
        out.append(f"instrument hysteresis {_pm(hl['instrument_hysteresis_J'], e, 4)} J")
    return out


def _tail_line(res):
    """Why the instrument's pull-off differs from the max adhesion: the spring holds the whole
    sphere (F_ex + F_tail), the max adhesion is F_ex over the analysis disk alone."""
    t = res.instrument.get("pull_off_tail")
    if t is None:
        return ("instrument forces are the whole sphere's: F_ex plus F_tail, the laws' force "
                "beyond the analysis radius; the max adhesion above is the analysis disk's")
    from ..io.plots import force_unit

    s, unit = force_unit([res.headline["instrument_pull_off_N"]])
    a = f"r > {t['analysis_radius_m'] * 1e9:.4g} nm"
    if t["at_max_adhesion"]:
        # the max adhesion's error estimate counts this tail as its "tail" part: say so when
        # it is most of the printed ± (else the two numbers look inconsistent)
        est = res.estimates.get("max_adhesion_N", {})
        most = est.get("total") and abs(est.get("tail", 0.0)) > 0.5 * est["total"]
        return (f"instrument forces are the whole sphere's: pull-off = max adhesion "
                f"{t['max_adhesion_N'] * s:.5g} {unit} (analysis disk) + F_tail "
                f"{t['F_tail_N'] * s:.3g} {unit} ({a}) at d = {t['d_m'] * 1e9:.4g} nm"
                + (" (most of the max adhesion's ±)" if most else ""))
    return (f"instrument forces are the whole sphere's: its pull-off includes F_tail "
            f"{t['F_tail_N'] * s:.3g} {unit} ({a}) at d = {t['d_m'] * 1e9:.4g} nm; the max "
            "adhesion above is the analysis disk's alone")
