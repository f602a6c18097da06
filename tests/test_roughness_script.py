"""validation/roughness.py stops where a signal stopped one of its runs (the runner returns
such a run "interrupted", and the script's loops used to go on to their next run): one line,
exit 128 + the signal, roughness.md not written."""
import os
import signal

import pytest

from validation import roughness


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT])
def test_a_signal_in_a_run_stops_the_script_in_one_line(tmp_path, monkeypatch, capsys, sig):
    """The signal is sent (a real one, to this process) as the script's first runner call
    starts - eq 20's limit run, the GW statistics and Fig 8 stubbed out as done: that run ends
    "interrupted" at its first safe point, and no other run starts."""
    calls = []
    real = roughness.runner_run

    def first_signalled(scene, **kw):
        calls.append(scene.name)
        if len(calls) == 1:
            os.kill(os.getpid(), sig)
        return real(scene, **kw)
    monkeypatch.setattr(roughness, "runner_run", first_signalled)
    monkeypatch.setattr(roughness, "RESULTS", tmp_path)
    monkeypatch.setattr(roughness, "fig7", lambda: ("", 0.0, [0.0, 0.0], None))
    monkeypatch.setattr(roughness, "fig8", lambda: ([], {}, 0.0))
    assert roughness.main([]) == 128 + sig
    assert len(calls) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and f"interrupted by {signal.Signals(sig).name}" in err[0]
    assert "roughness.md not written" in err[0]
    assert not (tmp_path / "roughness.md").exists()
