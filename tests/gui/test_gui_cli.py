"""``studyapp gui`` refuses bad arguments in one line (exit 2), before any window opens."""

import pytest

from studyapp.cli import build_parser, main


@pytest.mark.parametrize("argv, words", [
    (["gui", "--start"], "--start: allowed only with --participant ID"),
    (["gui", "--screenshot", "console.jpg"], "--screenshot console.jpg: allowed is a file name ending in .png"),
    (["gui", "--measure-scope", "0.1"], "--measure-scope 0.1: allowed is 0.5 to 600 seconds"),
])
def test_bad_arguments_are_one_line(argv, words, capsys):
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert err == f"studyapp: error: {words}"


def test_no_command_means_the_gui():
    parser = build_parser()
    assert "gui" in parser._subparsers._group_actions[0].choices
    args = parser.parse_args(["gui", "--protocol", "p.toml", "--participant", "P01", "--start"])
    assert args.func.__module__ == "studyapp.cli.gui" and args.audio == "device" and args.midi == "first"


def test_no_display_is_one_line(monkeypatch, capsys):
    for name in ("DISPLAY", "WAYLAND_DISPLAY", "QT_QPA_PLATFORM"):
        monkeypatch.delenv(name, raising=False)
    assert main(["gui"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("studyapp: error: no display") and "\n" not in err
