"""A fold's decision is cut short only where the corrector goes round a cycle of contact
*sets* (:func:`femadh.contact.snap.cycling`): the corrector's history holds each
iteration's set, and two different sets of one size are not a cycle."""
import numpy as np

from conftest import FIG4_TOL, fig4_problem, fig4_sweeps
from femadh.contact import snap
from femadh.contact.complementarity import solve_complementarity

N = 532
#: residuals of a measured decision on the sigma = 0.489 nm slider's retract (532 nodes, the
#: micro-fold at 1.2884 nm; validation/results/snap_cost.md), each repeating to 6e-6
#: relative two iterations later from the third on
RESIDUALS = (2.6511e-21, 1.3992e-15, 1.5452737311835257e-15, 1.3988823954798885e-15,
             1.5452641917231115e-15, 1.3988824008565625e-15, 1.5452641915163163e-15,
             1.3988823985818158e-15)


def _set(nodes):
    mask = np.zeros(N, bool)
    mask[list(nodes)] = True
    return mask


def _history(sets):
    """A corrector history going through ``sets`` (masks) at the measured residuals."""
    return [(r, int(s.sum()), False, s.tobytes()) for r, s in zip(RESIDUALS, sets)]


def test_a_cycle_of_sets_is_one_and_sets_of_the_same_sizes_are_not():
    """The disks of 73 and 72 nodes in turn (a node let go and taken back, the measured
    decision) are a cycle. A corrector that goes 73, 72, 73, 72, ... nodes at the same
    residuals but through other sets - the 73rd node let go and the 74th taken in its place
    at every other iteration, so the set two iterations later is another of the same size
    - is none (its size alone read as a cycle before); nor one whose 72-node set moves
    over by a node each time."""
    disk73, disk72 = _set(range(73)), _set(range(72))
    swapped = _set(list(range(72)) + [73])           # 73 nodes: the 73rd out, the 74th in
    assert int(swapped.sum()) == 73 and not np.array_equal(swapped, disk73)
    assert snap.cycling(_history([disk73, disk72] * 4))
    assert not snap.cycling(_history([disk73, disk72, swapped, disk72] * 2))
    moving = [_set(range(73)) if k % 2 == 0 else _set(set(range(73)) - {72 - k // 2})
              for k in range(8)]
    assert [int(s.sum()) for s in moving] == [73, 72] * 4
    assert not snap.cycling(_history(moving))


def test_the_corrector_history_holds_each_iterations_contact_set():
    """Each iteration of :func:`solve_complementarity` records the contact set it iterated
    on: as many nodes as it counts, unchanged where it says so, and at convergence the
    returned state's own set. On the Fig 4 disk 0.2 nm further in from its last approach
    state, from that state's surface and set (measured: 23 -> 27, 28, 27, 26, 25 contact
    nodes in the first iterations)."""
    p = fig4_problem(100)
    ap, _ = fig4_sweeps(p)
    st = ap.states[-1]
    stats = {"history": []}
    new = solve_complementarity(p, st.d - 0.2e-9, st.w, tol=FIG4_TOL, max_iter=40,
                                active0=st.active, stats=stats)
    assert new.converged
    sets = [np.frombuffer(key, bool) for *_, key in stats["history"]]
    assert [int(s.sum()) for s in sets] == [m for _, m, _, _ in stats["history"]]
    assert np.array_equal(sets[0], st.active)
    assert np.array_equal(sets[-1], new.active)
    changed = [not same for _, _, same, _ in stats["history"]]
    assert any(changed)
    for k, ch in enumerate(changed[:-1]):
        assert np.array_equal(sets[k], sets[k + 1]) != ch
