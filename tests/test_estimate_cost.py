"""The estimate's reduced members solve only the states their numbers are read at: the
contact radius at zero force from the fine run's sign-change interval alone where the
member's F_ex changes sign there too, and no deepest state where the members placed by its
contact edge give that state's grid part (femadh.runner.members, femadh.runner.estimates)."""
import copy
from types import SimpleNamespace
import warnings

import pytest

import femadh
from conftest import fig4_banded
from femadh.errors import MeshResolutionWarning
from femadh.runner import estimates, members
from femadh.scene import scene_from_dict

SCENES = "validation/scenes"
R_C = ("r_c_at_zero_force_approach_m", "r_c_at_zero_force_retract_m")


def _fig3_banded():
    """The Fig 3 scene on the banded grid its accuracy 1e-2 run ends on (58 nodes, spacing
    136.7 nm in a 6.56-um band, a = 25.3 um), its sweep as the scene's: F_ex changes sign on
    both branches."""
    base = femadh.load_scene(f"{SCENES}/paper1_fig3.toml")
    raw = copy.deepcopy(base.raw)
    raw["solver"].pop("accuracy", None)
    raw["solver"].pop("nodes", None)
    raw["solver"]["analysis_radius"] = "25.3e-6 m"
    raw["solver"]["grid"] = {"spacing": "136.7e-9 m", "band": "6.5625e-6 m",
                             "grading": "0.328e-6 m"}
    return scene_from_dict(raw, base.path, bare_numbers=False)


def _run(scene, pair, lock_only, locked=True):
    with pytest.MonkeyPatch.context() as mp, warnings.catch_warnings():
        warnings.simplefilter("ignore", MeshResolutionWarning)
        mp.setattr(members, "ZERO_FORCE_PAIR_FIRST", pair)
        mp.setattr(estimates, "LOCKED_DEEPEST_ONLY", lock_only)
        if not locked:
            mp.setattr(estimates, "deepest_locked", lambda *a, **k: None)
        return femadh.run(scene, progress=False, figures=False)


@pytest.fixture(scope="module")
def runs():
    sc = _fig3_banded()
    return {"both": _run(sc, True, True), "window": _run(sc, False, True),
            "deepest": _run(sc, True, False), "unplaced": _run(sc, True, True, locked=False)}


def _solves(res):
    return [m["solves"] for m in res.grid["member_solves"]]


class _FakeMember:
    """A member whose states are given: F_ex and r_c by the fine run's state index; records
    which states were asked for."""

    def __init__(self, f, r):
        self.f, self.r, self.asked = f, r, []

    def state(self, branch, snaps, k):
        self.asked.append(k)
        return SimpleNamespace(d=snaps[k].d, r_c=self.r[k], k=k)

    def f_ex(self, st):
        return self.f[st.k]


def _zero_force(f_fine, f_member, pair):
    d = [1e-9 - 0.2e-9 * k for k in range(len(f_fine))]
    r = [1e-6 * (1 + k) for k in range(len(f_fine))]
    res = SimpleNamespace(branches={"approach": {"F_ex_N": f_fine, "r_c_m": r}})
    snaps = {"approach": [SimpleNamespace(d=x) for x in d]}
    m = _FakeMember(f_member, r)
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(members, "ZERO_FORCE_PAIR_FIRST", pair)
        rc = members._zero_force_radius(m, res, snaps, "approach")
    return rc, m.asked


def test_zero_force_radius_reads_the_sign_change_interval_first():
    """The fine run's F_ex changes sign between states 3 and 4. A member whose F_ex changes
    sign there too: its crossing from those two states alone (linear in F_ex, as the
    headline's), the four-state window's value; a member whose crossing moved one interval
    back: the window's neighbours are solved and give it."""
    f_fine = [3.0, 2.0, 1.0, 0.5, -0.5, -1.0, -2.0]
    same = [3.0, 2.0, 1.0, 0.25, -0.75, -1.0, -2.0]
    rc, asked = _zero_force(f_fine, same, True)
    assert asked == [3, 4]
    assert rc == pytest.approx(4e-6 + 0.25 * 1e-6, rel=1e-12, abs=0)
    rc4, asked4 = _zero_force(f_fine, same, False)
    assert asked4 == [2, 3, 4, 5] and rc4 == rc
    moved = [3.0, 2.0, 0.5, -0.25, -0.75, -1.0, -2.0]
    rc, asked = _zero_force(f_fine, moved, True)
    assert asked[:2] == [3, 4] and sorted(set(asked)) == [2, 3, 4, 5]
    assert rc == pytest.approx(3e-6 + 0.5 / 0.75 * 1e-6, rel=1e-12, abs=0)
    assert _zero_force(f_fine, moved, False)[0] == rc
    # no sign change near the fine run's: not guessed (the member is traced whole)
    with pytest.raises(members._NotReduced):
        _zero_force(f_fine, [3.0, 2.0, 1.0, 0.5, 0.4, 0.3, -2.0], True)


def test_zero_force_radius_of_the_reduced_members_as_the_window_gave(runs):
    """On the Fig 3 run both branches change sign: fewer member solves with the interval
    first, the same crossings - each zero-force radius's grid part equal to the four-state
    window's to the solver tolerance (measured: 7.7e-18 and 3.4e-17 m of a -112-nm grid
    part, 3e-10 of it: the states' Newton paths differ by the factorisation they reuse)."""
    a, b = runs["both"], runs["window"]
    assert a.status == b.status == "converged"
    assert all(m["reduced"] for m in a.grid["member_solves"])
    assert all(x < y for x, y in zip(_solves(a), _solves(b)))
    for k in R_C:
        ga, gb = a.estimates[k]["grid"], b.estimates[k]["grid"]
        assert abs(ga - gb) <= 3e-9 * abs(gb), (k, ga, gb)     # 10x the measured
        assert ga != 0.0


def test_members_skip_the_deepest_state_when_placed_members_give_it(runs):
    """With the edge-placed members the family's members do not solve the deepest state
    (one solve less each) and the forces there keep the placed members' grid part, bit for
    bit; without placed members the family's members solve it and give that grid part."""
    a, b, c = runs["both"], runs["deepest"], runs["unplaced"]
    assert "deepest_member_spacings_m" in a.grid
    assert [x + 1 for x in _solves(a)] == _solves(b)
    for k in ("F_LJ_deepest_N", "F_ex_deepest_N"):
        assert a.estimates[k]["grid"] == b.estimates[k]["grid"]
    # no placed members: the family's members' deepest state (one solve each, as before)
    assert "deepest_member_spacings_m" not in c.grid
    assert _solves(c) == _solves(b)
    for k in ("F_LJ_deepest_N", "F_ex_deepest_N"):
        assert "grid" in c.estimates[k]
        assert c.estimates[k]["grid"] != a.estimates[k]["grid"]


def test_headline_numbers_do_not_depend_on_the_reductions(runs):
    """The reductions change what the estimate solves, never the run's own numbers."""
    ref = runs["window"].headline
    for res in (runs["both"], runs["deepest"], runs["unplaced"]):
        for k, v in ref.items():
            if not k.endswith("_error") and isinstance(v, float) and v == v:
                assert res.headline[k] == v, k


def _fig4_folds():
    """The Fig 4 slider (sigma = 0.5 nm) on an explicit banded grid (30 nm in a 5.9-um band,
    a = 12.6 um), swept 1.4 -> 0.8 nm and back: its jump-in (1.11 nm) and pull-off
    (1.18 nm), each a member fold search."""
    return fig4_banded("1.4 nm", "0.8 nm")


def _counted_run(scene, stall):
    """The run and the Newton iterations of the solves made through
    complementarity.solve_complementarity (the members' states, fold searches and peak
    searches; the sweep's stepping holds its own reference)."""
    from femadh.contact import complementarity

    orig = complementarity.solve_complementarity
    its = []

    def spy(*a, **kw):
        st = kw.setdefault("stats", {})
        before = st.get("iterations", 0)
        out = orig(*a, **kw)
        its.append(st.get("iterations", 0) - before)
        return out
    with pytest.MonkeyPatch.context() as mp, warnings.catch_warnings():
        warnings.simplefilter("ignore", MeshResolutionWarning)
        mp.setattr(complementarity, "solve_complementarity", spy)
        mp.setattr(members, "FOLD_DECISION_STALL", stall)
        res = femadh.run(scene, progress=False, figures=False)
    return res, sum(its)


def test_fold_decisions_stopped_on_stagnation_find_the_same_folds():
    """A member's fold decision (the trial one lattice step beyond its last state) gives up
    when its corrector stagnates instead of running to max_iter: the same folds, landings
    and estimate bit for bit, in fewer iterations (measured here, 2 folds per member: 326 -> 202
    Newton iterations outside the sweep)."""
    sc = _fig4_folds()
    full, it_full = _counted_run(sc, False)
    cut, it_cut = _counted_run(sc, True)
    assert full.status == cut.status == "converged"
    assert all(m["reduced"] for m in cut.grid["member_solves"])
    assert len(full.jumps) == 2
    for k in ("jump_in_d_m", "jump_out_d_m", "hysteresis_J"):
        assert "grid" in full.estimates[k]
        assert cut.estimates[k] == full.estimates[k], k
    assert _solves(cut) == _solves(full)
    assert it_cut < it_full, (it_cut, it_full)
