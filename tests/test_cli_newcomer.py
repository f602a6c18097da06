"""A newcomer's wrong scenes on the command line (a trial on a fresh clone): each mistake is one
line naming the file, the key, the value as written and what was expected - with the unit of
a range's bounds, a misspelt table shown by its keys, TOML's own spelling of a boolean, and a
file that is not TOML named without a key it does not have."""
import subprocess
import sys
from pathlib import Path

import pytest

from femadh.cli import main

ROOT = Path(__file__).resolve().parents[1]
FIG3 = (ROOT / "validation/scenes/paper1_fig3.toml").read_text()


def _check(tmp_path, capsys, text, name="s.toml"):
    """``femadh check`` on ``text``: (exit code, the error lines)."""
    path = tmp_path / name
    path.write_text(text)
    code = main(["check", str(path)])
    err = capsys.readouterr().err.strip().splitlines()
    return code, err, str(path)


def _edit(old, new):
    assert FIG3.count(old) == 1
    return FIG3.replace(old, new)


def test_a_length_out_of_range_names_the_bounds_unit_and_what_it_came_to(tmp_path, capsys):
    code, err, path = _check(tmp_path, capsys, _edit('radius = "2 mm"', 'radius = "2 furlongs"'))
    assert code == 2
    assert err == [f"femadh: error: {path}: [sphere.radius] = '2 furlongs': expected a length "
                   "in (0, 0.1 m]; it is 402.3 m"]


def test_a_sign_error_is_not_padded_with_its_si_value(tmp_path, capsys):
    code, err, path = _check(tmp_path, capsys, _edit('sigma = "1.0 nm"', 'sigma = "-1.0 nm"'))
    assert code == 2
    assert err == [f"femadh: error: {path}: [effects.asperity_gap.sigma] = '-1.0 nm': "
                   "expected a length > 0"]


def test_a_misspelt_table_or_key_is_one_line(tmp_path, capsys):
    """[sweeps] for [sweep]: one line, the unknown table shown by its keys, with the
    suggestion; not a second line that [sweep] is missing nor one per key of it (six in all
    before). Likewise a misspelt required key: no second line that the key is missing."""
    code, err, path = _check(tmp_path, capsys, _edit("[sweep]", "[sweeps]"))
    assert code == 2
    assert err == [
        f"femadh: error: {path}: [sweeps] = (a table of start, stop, step, directions): "
        "expected no such key here; did you mean 'sweep'? allowed keys are effects, "
        "instrument, materials, output, scene, solver, sphere, study, substrate, sweep"]
    code, err, path = _check(tmp_path, capsys, _edit('hamaker = "1e-19 J"',
                                                     'hamaker_constant = "1e-19 J"'))
    assert code == 2
    assert err == [f"femadh: error: {path}: [effects.lennard_jones.hamaker_constant] = "
                   "'1e-19 J': expected no such key here; did you mean 'hamaker'? allowed "
                   "keys are equilibrium_distance, hamaker"]
    # a key nothing resembles still leaves the required one missing: both lines
    code, err, path = _check(tmp_path, capsys, _edit('hamaker = "1e-19 J"', 'A = "1e-19 J"'))
    assert len(err) == 2 and "[effects.lennard_jones.hamaker] = (missing)" in err[1]


def test_a_missing_sphere_or_materials_table_is_one_line(tmp_path, capsys):
    text = _edit('[sphere]\nradius = "2 mm"\nprofile = "paraboloid"            # eq 4\n', "")
    code, err, path = _check(tmp_path, capsys, text)
    assert code == 2
    assert err == [f"femadh: error: {path}: [sphere] = (missing): expected a [sphere] table "
                   "(it is required)"]
    start = FIG3.index("[materials]")
    end = FIG3.index("[effects.lennard_jones]")
    code, err, path = _check(tmp_path, capsys, FIG3[:start] + FIG3[end:])
    assert err == [f"femadh: error: {path}: [materials] = (missing): expected a [materials] "
                   "table (it is required)"]


def test_a_wrong_type_is_shown_as_written(tmp_path, capsys):
    code, err, path = _check(tmp_path, capsys, _edit('step = "0.2 nm"', "step = true"))
    assert code == 2
    assert err == [f"femadh: error: {path}: [sweep.step] = true: expected a length such as "
                   "'2 mm' or '0.165 nm'"]


def test_a_file_that_is_not_toml_or_not_there_is_one_line_without_a_key(tmp_path, capsys):
    code, err, path = _check(tmp_path, capsys, 'radius = "2 mm"\n[[[\n')
    assert code == 2
    assert err == [f"femadh: error: {path}: expected valid TOML (Invalid initial character "
                   "for a key part (at line 2, column 3))"]
    missing = tmp_path / "nowhere.toml"
    assert main(["check", str(missing)]) == 2
    assert capsys.readouterr().err.strip() == (f"femadh: error: {missing}: expected a "
                                               "readable file (No such file or directory)")


def test_help_lists_every_exit_code_the_readme_does():
    """README's exit codes (0, 2-6, 130/143 and 1, a bug) are all in `femadh --help`."""
    out = subprocess.run([sys.executable, "-m", "femadh", "--help"], capture_output=True,
                         text=True, cwd=ROOT).stdout
    epilog = " ".join(out[out.index("exit codes"):].split())
    for code in ("0 done", "2 bad scene", "3 solve failed", "4 output not writable",
                 "5 missing dependency", "6 time limit", "130/143 interrupted",
                 "1 an internal error"):
        assert code in epilog, code


def test_a_celsius_temperature_written_c_names_the_coulomb(tmp_path, capsys):
    """'25 C' is 25 coulomb to pint: the line says so and how Celsius is written."""
    text = (ROOT / "validation/scenes/paper2_ethanol_100nm.toml").read_text()
    assert text.count('temperature = "298.15 K"') == 1
    code, err, path = _check(tmp_path, capsys, text.replace('temperature = "298.15 K"',
                                                            'temperature = "25 C"'))
    assert code == 2
    assert err == [f"femadh: error: {path}: [meniscus.temperature] = '25 C': expected a "
                   "temperature such as '298.15 K', but it has units of C (C is the coulomb: "
                   "Celsius is 'degC')"]


def test_check_names_the_grid_the_run_will_use(capsys):
    """An adaptive scene (no [solver] nodes) is not run on the default node count: `femadh
    check` says 'adaptive grid to accuracy 0.001' (the run then chose 181 nodes for Fig 3),
    not '200 nodes'; an explicit count is printed as given."""
    assert main(["check", str(ROOT / "validation/scenes/paper1_fig3.toml")]) == 0
    out = capsys.readouterr().out
    assert "adaptive grid to accuracy 0.001" in out and "200 nodes" not in out
    assert main(["check", str(ROOT / "validation/scenes/afm_tip_cantilever.toml")]) == 0
    assert ", 150 nodes, green" in capsys.readouterr().out


def test_a_reader_that_goes_away_ends_the_command_quietly():
    """``femadh keys | head -1`` (found by a newcomer trial): the reader closes the pipe
    while femadh still writes; femadh ends quietly with 141, as a program ended by SIGPIPE
    (it was exit 1, "internal error BrokenPipeError ... a bug in femadh")."""
    p = subprocess.Popen([sys.executable, "-m", "femadh", "keys"], stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE)
    p.stdout.close()                        # the reader is gone before femadh writes
    err = p.stderr.read().decode()
    assert p.wait(timeout=60) == 141
    assert err == ""


def test_check_plans_an_adaptive_scenes_first_member(tmp_path, capsys):
    """``femadh check`` reads an adaptive scene's first member off the plan (newcomer trial:
    it said "72 states of 300 nodes, <1 s" for Fig 4 at any accuracy, and passed 1e-5, which
    the run then refused before any solve): Fig 4 at 1e-3 plans 540 nodes (the cohesive
    zone's start), at 1e-4 1766 (the run: 1765 after its trapping check); at 1e-5 even the
    coarsest start needs ~4166 nodes, above the budget of 4000: refused with one line naming
    the key, as the run would refuse it."""
    text = Path("validation/scenes/paper1_fig4.toml").read_text()
    assert text.count("accuracy = 3e-3") == 1
    for acc, nodes in (("1e-3", 540), ("1e-4", 1766)):
        p = tmp_path / f"f4_{acc}.toml"
        p.write_text(text.replace("accuracy = 3e-3", f"accuracy = {acc}", 1))
        assert main(["check", str(p)]) == 0
        assert f"72 states of {nodes} nodes" in capsys.readouterr().out
    p = tmp_path / "f4_1e-5.toml"
    p.write_text(text.replace("accuracy = 3e-3", "accuracy = 1e-5", 1))
    assert main(["check", str(p)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "[solver.accuracy] = 1e-05" in err and "4000" in err


def test_a_resume_of_a_changed_scene_names_the_keys_that_changed(tmp_path, capsys):
    """``femadh run SCENE --resume`` on a folder whose run had other scene keys (a newcomer
    trial: the refusal named no key): one line naming each changed key, dotted as the scene
    writes it, with the run's value and today's, and what to do; restored, the refusal is
    the one of a finished run (the folder is this scene's again). An adaptive scene: the
    folder's run is its grid's trial, whose own keys (the grid, the analysis radius) are not
    the user's."""
    text = _edit("[solver]\n", "[solver]\naccuracy = 1e-2\n").replace('stop = "-5 nm"',
                                                                     'stop = "1 nm"')
    path, out = tmp_path / "s.toml", tmp_path / "out"
    path.write_text(text)
    quick = ["--out", str(out), "--quiet", "--no-estimate", "--no-figures"]
    assert main(["run", str(path), *quick]) == 0
    capsys.readouterr()
    path.write_text(text.replace("accuracy = 1e-2", "accuracy = 5e-3")
                    .replace('sigma = "1.0 nm"', 'sigma = "0.9 nm"'))
    assert main(["run", str(path), *quick, "--resume"]) == 4
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err
    assert ("whose scene has changed since: effects.asperity_gap.sigma was '1.0 nm', is "
            "'0.9 nm' now; solver.accuracy was 0.01, is 0.005 now; it cannot be resumed: "
            "rerun with --overwrite instead of --resume to start again, or restore "
            "effects.asperity_gap.sigma, solver.accuracy to resume it") in err, err
    path.write_text(text)
    assert main(["run", str(path), *quick, "--resume"]) == 4
    assert "it has finished, there is nothing to resume" in capsys.readouterr().err


def test_an_abbreviated_flag_is_refused_and_nothing_is_written(tmp_path, capsys):
    """`femadh run S --overwrit` (a newcomer trial): argparse took the abbreviation for
    --overwrite and replaced the previous run. Every parser refuses abbreviations: exit 2 with
    argparse's usage line; the folder's previous run untouched, a new --out not created."""
    scene = str(ROOT / "validation/scenes/paper1_fig3.toml")
    old = tmp_path / "old"
    old.mkdir()
    (old / "summary.json").write_text('{"status": "converged"}\n')
    for out, flag in ((old, "--overwrit"), (tmp_path / "new", "--resum")):
        with pytest.raises(SystemExit) as e:
            main(["run", scene, "--out", str(out), flag])
        assert e.value.code == 2
        assert f"unrecognized arguments: {flag}" in capsys.readouterr().err
    assert [p.name for p in old.iterdir()] == ["summary.json"]
    assert (old / "summary.json").read_text() == '{"status": "converged"}\n'
    assert not (tmp_path / "new").exists()
    # (the other commands' parsers too: a subcommand's option, the program's own; files
    # that do not exist, so that an abbreviation taken would end in an error, not a study)
    none = str(tmp_path / "none.toml")
    for argv in (["study", "sweep", none, "--vary", "scene.name=a", "--work", "1"],
                 ["topography", none, "--cut", "1 um"], ["--vers"]):
        with pytest.raises(SystemExit) as e:
            main(argv)
        assert e.value.code == 2, argv
    capsys.readouterr()


def test_a_refused_resume_leaves_no_folder_behind(tmp_path, capsys):
    """`--resume` into a folder that holds no run is refused (exit 4) and leaves the file
    system as it was: the folders the call would have created are gone again; a folder
    that was there (empty) stays, without femadh's lock file."""
    scene = str(ROOT / "validation/scenes/paper1_fig3.toml")
    out = tmp_path / "out" / "empty"
    assert main(["run", scene, "--out", str(out), "--resume"]) == 4
    assert capsys.readouterr().err == (f"femadh: error: nothing to resume in {out}: it holds "
                                       "no femadh run\n")
    assert list(tmp_path.iterdir()) == []
    out.mkdir(parents=True)
    assert main(["run", scene, "--out", str(out), "--resume"]) == 4
    assert out.is_dir() and list(out.iterdir()) == []
    capsys.readouterr()


def test_a_finished_folder_is_not_advised_resume(tmp_path):
    """A folder whose run has finished (converged) is refused with --overwrite or another
    --out as the way forward - --resume would only be refused in turn ("it has finished,
    there is nothing to resume"); an unfinished one still advises --resume."""
    from femadh.errors import OutputError
    from femadh.io.run_folder import RunFolder

    for status, resume in (("converged", False), ("interrupted", True), ("failed", True)):
        (tmp_path / "summary.json").write_text(
            f'{{"scene_id": "x", "status": "{status}", "scene": {{"name": "s"}}}}')
        with pytest.raises(OutputError) as e:
            RunFolder(tmp_path, "x", "s")
        msg = str(e.value)
        assert ("use --resume to continue it" in msg) == resume, msg
        assert "--overwrite" in msg and ("--resume" in msg) == resume, msg
    assert msg.endswith("status failed); use --resume to continue it or --overwrite to "
                        "replace it (or give another --out)")
    (tmp_path / "summary.json").write_text(
        '{"scene_id": "x", "status": "converged", "scene": {"name": "s"}}')
    with pytest.raises(OutputError) as e:
        RunFolder(tmp_path, "x", "s")
    assert str(e.value) == (f"{tmp_path} holds the results of a previous run (scene 's', "
                            "status converged); it has finished: use --overwrite to replace "
                            "it or give another --out")


def test_a_unit_in_the_wrong_case_is_not_recognised_and_named(tmp_path, capsys):
    """'2 MM' (pint: 2 megamolar) was "but it has units of MM", as if MM were a length unit.
    The line says the unit is not a length unit, what pint took it for, and the
    unit meant; a unit pint does not know at all ('NM') likewise, one line each."""
    for unit, why in (("MM", "'MM' is not a length unit (pint reads it as "
                               "megamolar); did you mean 'mm'?"),
                      ("NM", "'NM' is not a recognised unit; did you mean 'nm'?"),
                      ("mmm", "'mmm' is not a recognised unit")):
        code, err, path = _check(tmp_path, capsys, _edit('radius = "2 mm"',
                                                         f'radius = "2 {unit}"'))
        assert code == 2
        assert err == [f"femadh: error: {path}: [sphere.radius] = '2 {unit}': expected a "
                       f"length such as '2 mm' or '0.165 nm'; {why}"]
