"""The landing of a smooth law (no sigma-gap) whose Newton polish stalls at a lattice-trapped
contact edge: the corrector from the descent's minimum with its contact edge moved by the
fewest nodes (femadh.contact.landing._smooth_edges), so the landing does not follow the
Green operator's last bits (validation/results/landrobust.md)."""
import numpy as np
import pytest

import femadh
from femadh.contact import landing
from femadh.contact.linalg import disk_size
from femadh.scene.build import build_operator, build_problem

# The 100-node GW slider of tests/test_topography.py (its McCool numbers at the 50-nm cutoff
# written out, bit for bit the scene's), softening 6.3x a node's stiffness: lattice-trapped
SCENE = """
[scene]
name = "gw-landing"
[sphere]
radius = "2 mm"
[materials]
disk = { youngs_modulus = "163 GPa", poisson_ratio = 0.3 }
slider = { youngs_modulus = "83 GPa", poisson_ratio = 0.21 }
[effects.lennard_jones]
hamaker = "1e-19 J"
equilibrium_distance = "0.165 nm"
[effects.asperity_contact]
model = "greenwood-williamson"
rms_height = "2.341304346808563e-22 m"
mean_height = "3.7190741955208803e-22 m"
asperity_radius = "684690.5078242959 m"
density = "180426514275236.9 m^-2"
surface_energy = "0.06 J/m^2"
[solver]
nodes = 100
[sweep]
start = "2 nm"
stop = "1 nm"
step = "0.5 nm"
"""
#: the separation (m) of that run's landing after its approach fold (at d = 1.05811 nm)
D_LAND = 1.0576171874999996e-09


@pytest.fixture(scope="module")
def scene(tmp_path_factory):
    path = tmp_path_factory.mktemp("gw") / "s.toml"
    path.write_text(SCENE)
    return femadh.load_scene(path)


def _land(scene, operator):
    pb = build_problem(scene, operator=operator)
    st = landing.land(pb, D_LAND, np.zeros(pb.grid.n), tol=scene.tolerance,
                      max_iter=scene.max_iter)
    return pb, st


def _contact_nodes(pb, w):
    return disk_size(landing._smooth_contact(pb, pb.contour(D_LAND) - w))


def test_stalled_smooth_landing_lands_next_to_the_descent(scene, monkeypatch):
    """From the flat surface at D_LAND, main's operator: the descent settles on 35 contact
    nodes (a stable energy minimum) where the collocation form's root has vanished; Newton
    from it ran 200 iterations to a residual of 1.9e2 m (measured; the landing failed). The
    fallback lands on a converged, stable state one node beyond the descent's edge - the
    nearest edge, not the deepest (two nodes beyond: 37 nodes, 3 % lower energy)."""
    op = build_operator(scene)
    monkeypatch.setattr(landing, "SMOOTH_EDGES", False)
    _, stalled = _land(scene, op)
    assert not (stalled.converged and stalled.stable)       # the stall, reproduced
    monkeypatch.setattr(landing, "SMOOTH_EDGES", True)
    pb, st = _land(scene, op)
    assert st.converged and st.stable and st.residual <= scene.tolerance
    w_descent, _ = landing._lm_descent(pb, D_LAND, np.zeros(pb.grid.n), 0.5 * 0.165e-9,
                                       roundoff=False)
    m = _contact_nodes(pb, w_descent)
    assert m == 35
    assert _contact_nodes(pb, st.w) == m + 1
    assert pb.energy(st.w, D_LAND) < pb.energy(w_descent, D_LAND)


def test_smooth_landing_does_not_follow_the_operators_last_bits(scene):
    """K perturbed by -4..4 ulps per entry (a fixed pattern; without the fallback the landing
    fails on it: residual 8.6e-5 m after 200 iterations) lands on main's operator's state.
    Measured over 8 such patterns: max |w - w_main| <= 6.4e-20 m (one landed by Newton alone
    to its tolerance, the rest 1e-23-1e-21 m); tolerance: the states' own, 1e-19 m."""
    op = build_operator(scene)
    _, ref = _land(scene, op)
    K = np.array(op.stiffness)
    op2 = build_operator(scene)
    eps = np.finfo(float).eps
    op2._stiffness = np.asfortranarray(
        K * (1 + eps * np.random.default_rng(4).integers(-4, 5, K.shape)))
    pb, st = _land(scene, op2)
    assert st.converged and st.stable
    assert float(np.max(np.abs(st.w - ref.w))) <= scene.tolerance
