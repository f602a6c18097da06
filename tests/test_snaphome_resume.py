"""A run stopped while its contact unzips node by node resumes to the uninterrupted run, bit
for bit: the stepping's snap rhythm (:class:`femadh.contact.snap.SnapRhythm`, its only
memory across grid steps besides the state) is kept on each committed grid state and in the
checkpoint (femadh/runner/checkpoint.py); a checkpoint of an older femadh, without it, still
resumes (a fresh rhythm, as then)."""
from pathlib import Path
import shutil
import signal

import numpy as np
import pytest

from femadh.contact import snap
from femadh.runner import checkpoint
from validation.fault_matrix import ROOT, cli, differences, phase, summary

FLAGS = ("--quiet", "--no-figures", "--no-estimate")
FILES = ("curve.csv", "jumps.csv", "diagnostics.csv", "fields.csv")


def unzipping_scene(folder):
    """The slider + meniscus scene at the stiction map's sigma = 0.489 nm, p/psat = 0.15
    point (validation/results/snap_cost.md) on 120 uniform nodes of a 1.2-nm analysis radius
    (18-nm spacing: coarser, as on 100 nodes of 2 nm, every release is a jump), swept
    1.1 -> 0.5 -> 1.1 nm in 0.2-nm steps (the range must exceed sigma; the retract ends at
    1.1 nm, so a resume from 0.9 nm traces one unzipping grid step, not two: 4.8 instead of
    6.0 CPU-s for the module, measured). Measured: the approach jumps in at 1.097 nm; the
    retract releases 29 contact nodes (98 -> 69) in 21 lattice snaps and no jump, 81 -> 69
    nodes from 0.9 to 1.1 nm, and its 0.9-nm grid state (the 7th committed: four of the approach,
    the retract's 0.5 and 0.7 nm) leaves the rhythm full: three snaps (0.847, 0.868,
    0.888 nm), an aim at 0.9078 nm, as when the sweep was 1.3 -> 0.7 -> 1.3 nm."""
    text = (ROOT / "validation" / "scenes" / "paper1_slider_meniscus.toml").read_text()
    for old, new in (('analysis_radius = { delta = "50 nm" }',
                      'analysis_radius = { delta = "1.2 nm" }\nnodes = 120'),
                     ('sigma = "1.0 nm"', 'sigma = "0.489 nm"'),
                     ("relative_pressure = 0.95", "relative_pressure = 0.15"),
                     ('start = "2 nm"', 'start = "1.1 nm"'),
                     ('stop = "-5 nm"', 'stop = "0.5 nm"')):
        assert text.count(old) == 1, old
        text = text.replace(old, new)
    path = Path(folder) / "unzip.toml"
    path.write_text(text)
    return path


#: the checkpoint's state: the retract's 0.9-nm grid state, the 7th committed (k = 6); its
#: separation to the bit as the sweep computes it (1.1 nm - 0.2 nm in floating point)
K_MID, D_MID = 6, 9.000000000000001e-10


@pytest.fixture(scope="module")
def unzip(tmp_path_factory):
    """The scene, its uninterrupted run's folder, and a run of it stopped by SIGTERM right
    after the retract's 0.9-nm state, inside the next grid step's unzipping."""
    tmp = tmp_path_factory.mktemp("unzip")
    scene = unzipping_scene(tmp)
    assert cli("run", scene, "--out", tmp / "ref", *FLAGS)[0] == 0
    with phase("sweep", signal.SIGTERM) as s:
        s.after = K_MID + 1
        assert cli("run", scene, "--out", tmp / "stopped", *FLAGS)[0] == 143
    return scene, tmp / "ref", tmp / "stopped"


def test_a_run_stopped_mid_unzipping_resumes_bit_for_bit(unzip, tmp_path):
    """The checkpoint holds the stopped state's rhythm (three lattice snaps of the retract,
    an aim), and --resume ends with the uninterrupted run's summary and files, bit for
    bit."""
    scene, ref, stopped = unzip
    out = tmp_path / "out"
    shutil.copytree(stopped, out)
    st = checkpoint.load_checkpoint(out, K_MID, D_MID)
    branch, folds, target, creep_to = st.snap_rhythm
    assert branch == "retract" and len(folds) == 3 and target is not None
    # the last three snaps of the grid step 0.7 -> 0.9 nm, the next expected beyond it
    assert 0.7e-9 < folds[0] < folds[1] < folds[2] < D_MID < target < D_MID + 0.2e-9
    assert cli("run", scene, "--out", out, "--resume", *FLAGS)[0] == 0
    assert differences(summary(ref), summary(out)) == []
    for name in FILES:
        assert (out / name).read_bytes() == (ref / name).read_bytes(), name


def test_an_older_checkpoint_without_the_rhythm_still_resumes(unzip, tmp_path):
    """A checkpoint of an older femadh (no rhythm in it) reads as the state with no rhythm,
    and the run resumes with a fresh one, as it did then: the same states and contact sets
    to the corrector's tolerance - but not to the bit (the trials go elsewhere: the case a
    kept rhythm mends, so the test above tells a kept rhythm from a lost one)."""
    scene, ref, stopped = unzip
    out = tmp_path / "out"
    shutil.copytree(stopped, out)
    path = out / checkpoint.CHECKPOINT
    with np.load(path) as z:
        old = {n: z[n] for n in z.files if not n.startswith("snap_")}
        assert len(old) == len(z.files) - 3
    with open(path, "wb") as f:
        np.savez(f, **old)
    assert checkpoint.load_checkpoint(out, K_MID, D_MID).snap_rhythm is None
    assert cli("run", scene, "--out", out, "--resume", *FLAGS)[0] == 0
    assert summary(out)["status"] == "converged"
    assert (out / "fields.csv").read_bytes() != (ref / "fields.csv").read_bytes()
    a, b = (np.genfromtxt(f / "fields.csv", delimiter=",", names=True, dtype=None,
                          encoding="utf-8") for f in (ref, out))
    assert np.array_equal(a["d_m"], b["d_m"]) and np.array_equal(a["branch"], b["branch"])
    # every node's gap within the scene's Newton tolerance (1e-19 m; measured 7.2e-25 m),
    # the contact sets (the nodes whose elastic pressure is nonzero) the same
    assert np.max(np.abs(a["w_m"] - b["w_m"])) <= 1e-19
    assert np.array_equal(a["P_el_Pa"] != 0, b["P_el_Pa"] != 0)


class _Sink:
    """What :func:`checkpoint.save_checkpoint` reads of a sink."""

    def __init__(self, problem, k, branch, st):
        self.writer, self.problem, self.last_state = object(), problem, (k, branch, st)
        self.peak = None


class _Folder:
    def __init__(self, path):
        self.path = path


def test_the_rhythm_round_trips_and_is_restored_on_its_own_branch_only(unzip, tmp_path):
    """The rhythm round-trips through the checkpoint to the bit (its separations float64,
    an aim of None stays None); the stepping restores it on its own branch only (an
    approach's rhythm says nothing of the retract), a fresh one from None."""
    import femadh
    from femadh.scene import build_problem

    scene, _, stopped = unzip
    st = checkpoint.load_checkpoint(stopped, K_MID, D_MID)
    problem = build_problem(femadh.load_scene(str(scene)))
    for rhythm in (st.snap_rhythm, ("retract", (D_MID,), None, None)):
        st.snap_rhythm = rhythm
        checkpoint.save_checkpoint(_Folder(tmp_path), _Sink(problem, K_MID, "retract", st))
        assert checkpoint.load_checkpoint(tmp_path, K_MID, D_MID).snap_rhythm == rhythm
        same = snap.SnapRhythm.restored(rhythm, "retract")
        assert same.snapshot("retract") == rhythm
        other = snap.SnapRhythm.restored(rhythm, "approach")
        assert other.snapshot("approach") == ("approach", (), None, None)
    assert snap.SnapRhythm.restored(None, "retract").snapshot("retract") == \
        ("retract", (), None, None)
