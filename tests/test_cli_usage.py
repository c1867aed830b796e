"""A malformed command line is one line on stderr and exit code 2, like every other user error."""

import pytest

from studyapp.cli import main


@pytest.mark.parametrize("argv, words", [
    (["live", "--rate", "x"], "argument --rate: invalid float value: 'x' (see 'studyapp live --help')"),
    (["simulate", "--fmax"], "argument --fmax: expected one argument"),
    (["bench", "loop", "--speed", "9"], "unrecognized arguments: --speed 9"),
    (["nope"], "argument COMMAND: invalid choice: 'nope'"),
])
def test_usage_errors_are_one_line_and_exit_code_2(argv, words, capsys):
    assert main(argv) == 2
    captured = capsys.readouterr()
    err = captured.err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("studyapp: error: ") and words in err[0]
    assert captured.out == ""


def test_help_and_version_still_exit_0(capsys):
    with pytest.raises(SystemExit) as stop:
        main(["--version"])
    assert stop.value.code == 0 and capsys.readouterr().out.startswith("studyapp ")
