"""``studyapp gui`` refuses bad arguments in one line (exit 2), before any window opens."""

import pytest

from studyapp.cli import build_parser, main


@pytest.mark.parametrize("argv, words", [
    (["gui", "--start"], "--start: allowed only with --participant ID"),
    (["gui", "--screenshot", "console.jpg"], "--screenshot console.jpg: allowed is a file name ending in .png"),
    (["gui", "--measure-scope", "0.1"], "--measure-scope 0.1: allowed is 0.5 to 600 seconds"),
    (["gui", "--size", "1366"], "--size 1366: allowed is WIDTHxHEIGHT in pixels, from 800x600 to 7680x4320"),
    (["gui", "--size", "640x480"], "--size 640x480: allowed is WIDTHxHEIGHT in pixels, from 800x600 to 7680x4320"),
    (["gui", "--size", "8000x600"], "--size 8000x600: allowed is WIDTHxHEIGHT in pixels, from 800x600 to 7680x4320"),
    (["gui", "--size", "axb"], "--size axb: allowed is WIDTHxHEIGHT in pixels, from 800x600 to 7680x4320"),
])
def test_bad_arguments_are_one_line(argv, words, capsys):
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert err == f"studyapp: error: {words}"


def test_no_command_means_the_gui():
    parser = build_parser()
    args = parser.parse_args(["gui", "--protocol", "p.toml", "--participant", "P01", "--start"])
    assert args.func.__module__ == "studyapp.cli.gui" and args.audio == "device" and args.midi == "first"


def test_no_display_is_one_line(monkeypatch, capsys):
    for name in ("DISPLAY", "WAYLAND_DISPLAY", "QT_QPA_PLATFORM"):
        monkeypatch.delenv(name, raising=False)
    assert main(["gui"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("studyapp: error: no display") and "\n" not in err


@pytest.mark.parametrize("text, size", [("1366x768", (1366, 768)), ("800x600", (800, 600)),
                                        ("7680X4320", (7680, 4320)), ("1920×1080", (1920, 1080))])
def test_size_reads_width_and_height(text, size):
    from studyapp.cli.gui import parse_size

    assert parse_size(text) == size
