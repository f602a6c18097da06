"""A reduced member's state where Newton from the fine run's carried state converges to a
saddle (femadh.runner.members._Member._off_saddle).

The case: the stiction map's point sigma = 0.489 nm, p/psat 0.15 on its first trial's grid
(13.48 nm in a 5.885-um band, grading 0.294 um, a = 28.3 um, 532 nodes), approach only
-4.2 -> -5 nm. Its 19.06-nm member (376 nodes), solved at d = -5 nm from the fine state
carried to its grid, converges to a saddle: the first free nodes beyond the contact edge,
0.05-0.2 nm above sigma, have two minima and Newton's full steps land between them. On the
whole map point this sent the member to be traced whole (205 s of the trial's 469 s)."""
import copy
import warnings

import numpy as np
import pytest

import femadh
from femadh.contact import solve_state
from femadh.discretisation.moving import interpolate_state
from femadh.errors import MeshResolutionWarning
from femadh.runner import estimates, members, sink as sinkmod
from femadh.scene import build_problem, scene_from_dict


def _scene():
    base = femadh.load_scene("validation/scenes/paper1_slider_meniscus.toml")
    raw = copy.deepcopy(base.raw)
    raw["effects"]["asperity_gap"]["sigma"] = "0.488888888889 nm"
    raw["effects"]["capillary"]["relative_pressure"] = 0.15
    raw["sweep"].update(start="-4.2 nm", stop="-5 nm", step="0.4 nm", directions=["approach"])
    raw["solver"]["grid"] = {"spacing": "13.476257835942904 nm",
                             "band": "5.885253560406169 um",
                             "grading": "0.2942626780203085 um"}
    raw["solver"]["analysis_radius"] = "28.28427124746190 um"
    return scene_from_dict(raw, base.path, bare_numbers=False)


def _traced(scene):
    """(result, sink) of the scene traced whole (no members)."""
    got = {}
    orig = sinkmod.Sink.close

    def close(self):
        got["sink"] = self
        return orig(self)

    with pytest.MonkeyPatch.context() as mp, warnings.catch_warnings():
        warnings.simplefilter("ignore", MeshResolutionWarning)
        mp.setattr(sinkmod.Sink, "close", close)
        res = femadh.run(scene, progress=False, figures=False, estimate="peak")
    assert res.status == "converged"
    return res, got["sink"]


@pytest.fixture(scope="module")
def case():
    sc = _scene()
    _, sink = _traced(sc)
    fine = build_problem(sc)
    _, mem, _ = estimates.coarser_members(sc, fine)
    label, member = mem[0]
    assert label == "spacing 19.06 nm"
    return sc, fine, sink, member


def test_the_carried_state_converges_to_a_saddle(case):
    sc, fine, sink, member = case
    p = build_problem(member)
    snap = sink.committed["approach"][-1]
    w0, a0 = interpolate_state(fine, p, snap.d, snap.w)
    st = solve_state(p, snap.d, w0, tol=sc.tolerance, max_iter=sc.max_iter, active0=a0)
    assert st.converged and not st.stable
    # one negative eigenvalue of the energy Hessian on the free nodes, its mode at the
    # contact edge (the first free nodes)
    free = ~st.active
    H = p.energy_hessian(st.h, free)
    ev, vec = np.linalg.eigh(0.5 * (H + H.T))
    assert ev[0] < 0 < ev[1]
    first_free = np.flatnonzero(free)[np.argmax(np.abs(vec[:, 0]))]
    assert first_free - np.flatnonzero(st.active)[-1] <= 3


def test_the_member_state_is_its_whole_traces(case, monkeypatch):
    """The landed member state is the member's own traced state at d = -5 nm (the member
    traced whole over the fine run's sweep; on the full map sweep, 4 -> -5 nm, measured
    8e-15 nm apart) and the member without the landing is not reduced."""
    sc, fine, sink, member = case
    m = members._Member(member, fine, member, build_problem(member))
    snaps = sink.committed["approach"]
    st = m.state("approach", snaps, len(snaps) - 1)
    assert st.converged and st.stable
    res_m, sink_m = _traced(member)
    whole = sink_m.last["approach"]
    assert whole.d == st.d
    gap = m.problem.contour(st.d) - whole.w
    # the same equilibrium to the solver's tolerance: every node within 1e-6 of its gap
    # (measured 2.3e-12 of the gap, 1.3e-12 nm)
    assert np.max(np.abs(st.w - whole.w) / gap) <= 1e-6
    monkeypatch.setattr(members, "LAND_SADDLE", False)
    m2 = members._Member(member, fine, member, build_problem(member))
    with pytest.raises(members._NotReduced):
        m2.state("approach", snaps, len(snaps) - 1)


def test_a_landing_on_another_contact_set_is_refused(case, monkeypatch):
    """The descent's minimum must keep the saddle's contact set: the node of two minima
    moved to sigma changes its gap 10 % (0.5435 -> 0.489 nm), within off_branch's quarter of
    every gap, so a stable state with that node (and the nodes it pulls) in contact passes
    the branch test: Newton from the carried state with the saddle's first two free nodes
    held converges to a stable state on 209 contact nodes (the saddle's and the basin's
    minimum's: 208), off_branch False, F_ex 2.17e-3 from the right state (measured). With
    the landing replaced by that state the member must not be reduced (traced whole), not
    given it. (The genuine landing keeps the 208: test_the_member_state_is_its_whole_traces.)"""
    from femadh.contact import landing
    from femadh.contact.forces import state_forces
    from femadh.runner.peak import off_branch

    sc, fine, sink, member = case
    snaps = sink.committed["approach"]
    snap = snaps[-1]
    p = build_problem(member)
    w0, a0 = interpolate_state(fine, p, snap.d, snap.w)
    saddle = solve_state(p, snap.d, w0, tol=sc.tolerance, max_iter=sc.max_iter, active0=a0)
    assert saddle.converged and not saddle.stable
    held = saddle.active.copy()
    held[np.flatnonzero(~saddle.active)[:2]] = True
    other = solve_state(p, snap.d, w0, tol=sc.tolerance, max_iter=sc.max_iter, active0=held)
    # the case: another stable equilibrium, on a larger contact set, that off_branch passes
    assert other.converged and other.stable
    assert int(saddle.active.sum()) == 208 and int(other.active.sum()) == 209
    assert not off_branch(p, snap.d, other.w, w0)
    f_other = state_forces(p, other)[2]
    m = members._Member(member, fine, member, build_problem(member))
    f_right = state_forces(m.problem, m.state("approach", snaps, len(snaps) - 1))[2]
    assert abs(f_other / f_right - 1) > 1e-3         # measured 2.17e-3
    monkeypatch.setattr(landing, "land", lambda *a, **k: other)
    m2 = members._Member(member, fine, member, build_problem(member))
    with pytest.raises(members._NotReduced):
        m2.state("approach", snaps, len(snaps) - 1)
