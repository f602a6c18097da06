"""The adaptive loop completes the deferred estimate of the trial it keeps only
(femadh.runner.estimates.estimate_errors' ``defer``; that a completed estimate is the whole
one bit for bit: tests/test_estimate_members.py)."""
from conftest import adaptive_scene
from femadh.runner import adaptive, estimates
from femadh.runner.result import ContactResult


def test_the_adaptive_loop_completes_the_trial_it_keeps_only():
    """A scripted loop at 1e-2: trial 1 misses (estimate 5x the target), trial 2 meets it.
    Each trial is run deferring by the target (estimates.deferring); the superseded trial's
    rest is never made, the kept trial's once (its breakdown the completed one)."""
    calls, asked = [], []

    def fake(trial, out_dir, **kw):
        asked.append(estimates.deferred_target())
        k = len(asked)
        res = ContactResult(trial.name, trial, status="converged")
        res.timings["total_s"] = 0.01
        res.branches = {"approach": {"r_c_m": [0.0]}}
        res.grid = {"members": ["r h", "r^2 h"]}
        F, rel = 1e-5, (5e-2 if k == 1 else 5e-3)
        res.headline = {"max_adhesion_N": F, "F_ex_deepest_N": F, "F_LJ_deepest_N": F}
        res.estimates = {"max_adhesion_N": {"total": rel * F, "tail": 0.0}}

        def rest():
            calls.append(k)
            return {**res.estimates, "jump_out_d_m": {"total": 1e-12}}
        res.pending_estimate = rest
        return res

    res = adaptive.run_adaptive(adaptive_scene(accuracy=1e-2), None, run=fake)
    assert res.status == "converged" and res.accuracy["met"]
    assert asked == [1e-2, 1e-2]
    assert calls == [2]
    assert res.estimates["jump_out_d_m"] == {"total": 1e-12}
    assert res.pending_estimate is None
