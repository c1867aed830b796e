"""``evaluate --params P -o DIR`` run twice (issue 33, item 6): on main the second run, DIR existing,
crashed with a TypeError (``--params`` is a list, checked as one path)."""

from studyapp.cli import main


def test_evaluate_with_params_into_an_existing_folder_works(short_recording, tmp_path, capsys):
    params = tmp_path / "params.toml"
    params.write_text("[BDIFF]\nsteps = 2\n")
    argv = ["evaluate", str(short_recording), "--params", str(params), "-o", str(tmp_path / "eval")]
    assert main(argv) == 0
    assert main(argv) == 0
    assert "Traceback" not in capsys.readouterr().err
    assert (tmp_path / "eval").is_dir()
