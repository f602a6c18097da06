"""A run stopped by its own time limit is recorded as such, not as a failure of something
else: a study point stopped by [solver] time_limit says "time limit" (run the study again to
continue it), never that the executor did not run it."""
import json

import femadh
from femadh.studies.sweep import run_study

FIG3 = "validation/scenes/paper1_fig3.toml"


def test_a_study_point_stopped_by_its_time_limit_says_so(tmp_path):
    """Two points of a 60-node Fig 3 study with a 1-ms time limit: each run stops at its
    first safe point; both records say "time limit" with the limit's words, unfinished (a
    second run of the study runs them again), and the study lists them as not converged."""
    sc = femadh.load_scene(FIG3).replace({"solver.nodes": 60, "sweep.step": "0.5 nm",
                                          "sweep.stop": "-3 nm",
                                          "solver.time_limit": "1 ms"})
    out = tmp_path / "st"
    study = run_study(sc, {"effects.asperity_gap.sigma": ["0.9 nm", "1 nm"]}, out,
                      workers=1, progress=False)
    recs = [json.loads(f.read_text()) for f in out.glob("points/*/record.json")]
    assert len(recs) == 2
    for rec in recs:
        assert rec["status"] == "time limit" and not rec["finished"], rec
        assert rec["error"].startswith("time limit 0.001 s reached"), rec["error"]
    assert len(study.failed) == 2
