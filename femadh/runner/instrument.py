"""The instrument's numbers of a run: read off the computed states
(:mod:`femadh.instrument.readout`), then sharpened by fresh states where the readout
interpolates (z's turning points, the landings, the largest tension)."""
import math

import numpy as np

#: rounds of fresh states in each interval the readout interpolates in
REFINE_ROUNDS = 8
#: fresh states per interval and round (the interval shrinks ~4x per round)
REFINE_STATES = 3
#: the readout's share of the run's accuracy target: fresh states stop once every headline
#: number's readout resolution is below this share of it (the hysteresis, an integral over the
#: whole loop, is judged by its own estimate and not refined locally)
REFINE_SHARE = 0.1
#: the target of runs without one (explicit nodes, no accuracy)
DEFAULT_TARGET = 1e-3
#: intervals narrower than this fraction of the sweep step are not refined further (the
#: displacement-controlled folds are located to the same 2^-10)
REFINE_MIN_FRACTION = 2.0**-10


#: the instrument's headline numbers (summary.json "instrument" drops the prefix)
INSTRUMENT_NUMBERS = ("pull_off_N", "snap_off_N", "jump_in_d_m", "jump_in_z_m",
                      "jump_out_d_m", "jump_out_z_m", "hysteresis_J")


def instrument_numbers(res, spring, branches=None):
    """The instrument's headline numbers, ``instrument_<name>`` (see
    :meth:`femadh.instrument.InstrumentPath.headline`); its paths, jumps and readout
    resolutions go to ``res.instrument``. ``branches``: the branches with fresh states added
    (:func:`refine_instrument`); default the run's. What the instrument cannot read (a jump landing
    beyond the traced separations, a drive that never presses the contact) is a warning."""
    from ..instrument import read_instrument

    directions = tuple(b for b in ("approach", "retract") if b in res.branches)
    try:
        ip = read_instrument(branches or res.branches, res.jumps, spring.stiffness,
                             directions)
    except ValueError as exc:
        res.warnings.append(f"instrument: {exc}")
        return {}
    hl = ip.headline()
    res.instrument = {"spring": spring.as_dict(), "paths": ip.paths, "jumps": ip.jumps,
                      "resolution": {k[:-len("_resolution")]: v for k, v in hl.items()
                                     if k.endswith("_resolution")},
                      "incomplete": ip.incomplete}
    if ip.incomplete:
        res.warnings.append(f"instrument: {ip.incomplete}")
    app = ip.paths.get("approach")
    early = app is not None and len(app["kind"]) > 1 and app["kind"][1] == "fold"
    if early:
        # its jump-in lies before the sweep's first state: not read (a bound is no number)
        for name in ("jump_in_d_m", "jump_in_z_m"):
            hl.pop(name, None)
        res.warnings.append("instrument: the spring is already softer than the contact at the "
                            f"sweep's start (d = {app['d_m'][0] * 1e9:.4g} nm): it jumps in "
                            "from farther out, not read; extend [sweep] start")
    if app is not None and not any(j["branch"] == "approach" for j in ip.jumps) \
            and app["F_N"][-1] > 0:
        res.warnings.append("instrument: the drive never presses the contact (its deepest "
                            f"state is still in tension, F = {app['F_N'][-1]:.4g} N): extend "
                            "[sweep] stop")
    out = {f"instrument_{k}": float(v) for k, v in hl.items() if k in INSTRUMENT_NUMBERS}
    if spring.rest_gap is not None:
        stuck = mems_verdict(ip.paths.get("retract"), spring.rest_gap, spring.stiffness)
        if "retract" not in ip.paths:
            res.warnings.append("instrument: no verdict without a retract: add 'retract' to "
                                "[sweep] directions")
        elif stuck is None:
            # the retract's far end: [sweep] stop for a retract-only sweep, else start
            far = "stop" if directions == ("retract",) else "start"
            res.warnings.append("instrument: the retract ends before the suspension's base is "
                                f"back at its rest gap ({spring.rest_gap * 1e9:.4g} nm): no "
                                f"verdict; extend [sweep] {far}")
        else:
            out["instrument_stuck"] = float(stuck)
        z_out = hl.get("jump_out_z_m")
        if z_out is not None:
            out["instrument_release_margin_m"] = float(z_out - spring.rest_gap)
    return out


#: a part held closer than this fraction of the rest gap, with its base at the rest gap, is
#: stuck (a free part hangs near the rest gap, a stuck one at contact: the two differ by ~g)
STUCK_FRACTION = 0.5


def mems_verdict(retract, rest_gap, stiffness):
    """Whether a part pressed into contact stays stuck when its suspension's base is back at
    the rest gap g: where the instrument's retract path is at z = g (its drive order: a jump
    keeps z) - still before its last jump-out (the restoring force k (g - d) has not beaten the
    adhesion yet), or near contact (d < STUCK_FRACTION g, the adhesion balancing k (g - d), as
    after a peel-off without a jump or a landing on a longer-range hold). A path that ends in a
    jump-out short of g is free (it landed beyond the traced separations); one that ends short
    of g pulling less than (1 - STUCK_FRACTION) k g is free too (beyond the trace the surface
    laws only decay: too weak to hold it near contact). Else None: trace further."""
    if retract is None or not len(retract["z_m"]):
        return None
    z, d, kind = retract["z_m"], retract["d_m"], retract["kind"]
    folds = [i for i, k in enumerate(kind) if k == "fold"]
    reach = np.flatnonzero(z >= rest_gap)
    if not reach.size:
        if folds and folds[-1] == len(kind) - 1:
            return False
        if abs(retract["F_N"][-1]) < (1 - STUCK_FRACTION) * stiffness * rest_gap:
            return False
        return None
    i = int(reach[0])
    if folds and i <= folds[-1]:
        return True                  # z = g comes before the last jump-out: still held
    if i == 0:
        return bool(d[0] < STUCK_FRACTION * rest_gap)
    t = (rest_gap - z[i - 1]) / (z[i] - z[i - 1]) if z[i] > z[i - 1] else 1.0
    return bool(d[i - 1] + t * (d[i] - d[i - 1]) < STUCK_FRACTION * rest_gap)


def refine_instrument(scene, res, problem, sink):
    """Sharpen the instrument's numbers: in every interval where the readout interpolates a
    turning point of z (:meth:`~femadh.instrument.InstrumentPath.brackets`), solve fresh
    states between the two
    computed ones (:func:`femadh.runner.peak.state_between`), read again; up to
    REFINE_ROUNDS rounds. The fresh states feed the readout only (curve.csv keeps the sweep's
    states). Updates ``res.headline`` and ``res.instrument``; returns the fresh states'
    count."""
    from ..contact.forces import state_forces, tail_force
    from ..instrument import read_instrument
    from .peak import state_between

    spring = scene.instrument
    pool = {b: list(v) for b, v in sink.states.items()}
    for branch, before, after in sink.jump_states:
        pool.setdefault(branch, []).extend([before, after])
    rows = {b: {k: list(c[k]) for k in ("d_m", "F_ex_N", "F_tail_N")}
            for b, c in res.branches.items()}
    step = abs(scene.d_values[1] - scene.d_values[0]) if len(scene.d_values) > 1 else 0.0
    done, fresh = set(), 0
    target = REFINE_SHARE * (scene.target_accuracy or DEFAULT_TARGET)

    def arrays():
        out = {}
        for b, c in rows.items():
            order = np.argsort(c["d_m"])
            if b == "approach":
                order = order[::-1]
            out[b] = {k: np.asarray(v, float)[order] for k, v in c.items()}
        return out

    def ends(branch, lo, hi):
        """The computed states at a bracket's ends on one piece of the branch. At a fold the
        branch's last state and its landing can share a separation (a traced fold lands at
        d_fold): of the candidates, the pair whose displacements differ least (a landing
        differs from its fold by the jump, ~ the gap). A fresh state solved between a fold and
        its landing lands on either branch, and one from the other piece in the branch's rows
        reads as a turn of z that is not there (a pull-off of 468 nN on a curve whose largest
        tension is 363 nN: the smooth sphere at mu = 2 on a 3e4 N/m spring)."""
        A = [st for st in pool.get(branch, ()) if st.d == lo]
        B = [st for st in pool.get(branch, ()) if st.d == hi]

        def apart(ab):
            a, b = ab
            if np.shape(a.w) != np.shape(b.w):
                return math.inf          # a band that moved between them: no interpolation
            return float(np.max(np.abs(np.asarray(a.w) - np.asarray(b.w))))
        pairs = [(a, b) for a in A for b in B]
        if not pairs:
            return None, None
        best = min(pairs, key=apart)
        return best if math.isfinite(apart(best)) else (None, None)

    for _ in range(REFINE_ROUNDS):
        try:
            ip = read_instrument(arrays(), res.jumps, spring.stiffness,
                                 tuple(b for b in ("approach", "retract") if b in rows))
        except ValueError:
            break
        if _resolved(ip.headline(), target, step):
            break
        added = 0
        # the turning points only: the pull-off is the run's own peak (below), a landing's
        # interpolation enters no headline number but the hysteresis, judged by its estimate
        for branch, lo, hi in ip.brackets():
            if (branch, lo, hi) in done or hi - lo <= REFINE_MIN_FRACTION * step:
                continue
            done.add((branch, lo, hi))
            a, b = ends(branch, lo, hi)
            if a is None or b is None:
                continue
            have = np.asarray(rows[branch]["d_m"], float)
            for d in np.linspace(lo, hi, REFINE_STATES + 2)[1:-1]:
                # a fresh state where the branch has one already would read as a turn of z
                # (two states at one d): the bracket's middle is often a computed state
                if np.any(np.abs(have - d) <= 1e-6 * (hi - lo)):
                    continue
                st = state_between(problem, a, b, float(d), scene)
                if st is None:
                    continue
                pool[branch].append(st)
                rows[branch]["d_m"].append(st.d)
                rows[branch]["F_ex_N"].append(state_forces(problem, st)[2])
                rows[branch]["F_tail_N"].append(tail_force(problem, st.d))
                added += 1
        fresh += added
        if not added:
            break
    if fresh:
        before = list(res.warnings)
        numbers = instrument_numbers(res, spring, arrays())
        if numbers:
            res.headline.update(numbers)
            # the sharpened reading's warnings replace the first reading's: the same drive and
            # range, so the same warnings, but the first one's numbers (a jump read between
            # the sweep's states) would contradict the headline read from the fresh states
            fresh_warnings = res.warnings[len(before):]
            res.warnings[:] = [w for w in before if not w.startswith("instrument:")] \
                + fresh_warnings
        else:
            res.warnings[:] = before         # the sharpened reading failed: the first stands
    _pull_off_at_the_peak(res, problem)
    return fresh


def _pull_off_at_the_peak(res, problem):
    """The largest tension the instrument records is the contact's largest tension wherever
    the instrument holds that state (dF/dd = 0 > -k there): the peak the run located by its
    own bounded search (:func:`femadh.runner.estimates.refine_peak`) plus the tail there,
    when the instrument's retract path passes that separation and its own largest reading is
    an interior state there, not a jump's fold. Sharper than sampling a narrow peak (Fig 3's sigma-gap adhesion peak is ~0.1 nm wide)."""
    from ..contact.forces import tail_force

    hl, ins = res.headline, res.instrument
    ret = ins["paths"].get("retract")
    if ret is None or "instrument_pull_off_N" not in hl or "d_at_max_adhesion_m" not in hl:
        return
    d = hl["d_at_max_adhesion_m"]
    tail = tail_force(problem, d)
    F = hl["max_adhesion_N"] + tail
    held = [dk for dk, kind in zip(ret["d_m"], ret["kind"]) if kind == "point"]
    # the readout's largest tension is an interior state of the path (not a jump's fold),
    # and the peak lies where the path holds the contact: the same maximum, sampled
    i = int(np.argmax(ret["F_N"]))
    if held and min(held) <= d <= max(held) and ret["kind"][i] == "point":
        # the two readings of one maximum (the path's states, the bounded search) differ by
        # at least their errors: that difference is the pull-off's resolution, never zero
        sampled = hl["instrument_pull_off_N"]
        hl["instrument_pull_off_N"] = float(F)
        ins["resolution"]["pull_off_N"] = max(abs(F - sampled),
                                              ins["resolution"].get("pull_off_N", 0.0))
        ins["pull_off_tail"] = _tail_share(problem, d, tail, hl["max_adhesion_N"], sampled)
    else:
        # read elsewhere on the path (a jump's fold): the tail there, no identity with the
        # max adhesion (another state)
        d_p = float(ret["d_m"][i])
        ins["pull_off_tail"] = _tail_share(problem, d_p, tail_force(problem, d_p))


def _tail_share(problem, d, tail, max_adhesion=None, sampled=None):
    """summary.json "instrument" "pull_off_tail": what the pull-off holds beyond the headline's
    max adhesion. The spring holds the whole sphere, so its force is F_ex (the analysis disk,
    r <= a, the max adhesion's basis) plus F_tail = -2 pi R U(b(a; d)) beyond a (exact for
    the undeformed paraboloid; the deformation there is ~F / (pi E* a), 4e-12 m on the AFM
    tip's 5-nm gap at a). With the pull-off at the max adhesion's state (``max_adhesion``
    given): pull-off - max adhesion = F_tail(d_at_max_adhesion), the identity the terminal
    prints; ``sampled`` is the path's own reading of that maximum (fresh states, F_ex + F_tail
    each), an independent check of it."""
    out = {"d_m": float(d), "F_tail_N": float(tail),
           "analysis_radius_m": float(problem.grid.radius),
           "at_max_adhesion": max_adhesion is not None}
    if max_adhesion is not None:
        out["max_adhesion_N"] = float(max_adhesion)
        out["sampled_pull_off_N"] = float(sampled)
    return out


def _resolved(hl, target, step):
    """Whether every instrument number but the hysteresis is read to ``target`` relative
    (forces relative to themselves, positions relative to max(|value|, the sweep step))."""
    for name in INSTRUMENT_NUMBERS:
        if name == "hysteresis_J" or name not in hl:
            continue
        r = hl.get(f"{name}_resolution", 0.0)
        scale = abs(hl[name]) if name.endswith("_N") else max(abs(hl[name]), step)
        if r > target * scale:
            return False
    return True
