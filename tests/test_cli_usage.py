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


def test_every_command_module_is_registered_and_none_is_skipped():
    """cli/__init__.py imports each command's module: a missing one fails at once instead of being skipped."""
    import pkgutil

    import studyapp.cli as cli

    modules = {m.name for m in pkgutil.iter_modules(cli.__path__)}
    with_register = {name for name in modules if hasattr(__import__(f"studyapp.cli.{name}", fromlist=["register"]),
                                                           "register")}
    assert {m.__name__.rpartition(".")[2] for m in cli.COMMANDS} == with_register


@pytest.mark.parametrize("argv, words", [
    (["simulate", "--fmax", "1", "--seed", "-1", "-o", "x.npz"], "argument --seed: '-1': allowed is an integer"),
    (["bench", "live", "--block-ms", "nan"], "argument --block-ms: 'nan' is not a finite number"),
    (["bench", "memory", "--rows", "1_0"], "argument --rows: invalid int value: '1_0'"),
])
def test_numbers_are_checked_on_every_sub_command(argv, words, capsys):
    assert main(argv) == 2
    assert words in capsys.readouterr().err
