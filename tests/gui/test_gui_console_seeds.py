"""The console's Start button seeds a session exactly as ``studyapp run`` does (issue 14, item 3).

Qt's ``clicked`` signal carries ``checked``; passed on as the seed, it gave every session started
from the console the seed 0."""

import json

import numpy as np
import pytest
from PySide6.QtCore import Qt

from studyapp.cli import main as cli
from tests.gui.conftest import DEMO

pytest.importorskip("pytestqt")

pytestmark = pytest.mark.gui

STUDY_SEED = 3
PROTOCOL = f"""
[study]
name = "seeds"
title = "Seeds"
tasks = ["rating"]
seed = {STUDY_SEED}

[apparatus]
rate = 5000.0

[rating]
conditions = ["LVT", "BDIFF"]
fmax = 1.0
instructions = "Rate the knobs."
"""
PARTICIPANTS = ("P01", "P02")


def seeds_in(results):
    return {p: json.loads(next((results / "seeds" / p).glob("*/session.json")).read_text())["seed"]
            for p in PARTICIPANTS}


def test_two_participants_started_from_the_console_get_the_command_lines_seeds(idle_console, qtbot, tmp_path, capsys):
    console = idle_console
    c = console.controller
    protocol = tmp_path / "seeds.toml"
    protocol.write_text(PROTOCOL)
    assert console.choose_protocol(str(protocol))
    gui_results = tmp_path / "gui"
    console.setup.results.setText(str(gui_results))
    try:
        for participant in PARTICIPANTS:
            console.setup.participant.setText(participant)
            qtbot.mouseClick(console.start_button, Qt.MouseButton.LeftButton)
            assert c.state == "starting", console.setup.error.text()
            console.abort_session()
            assert c.state == "aborted"
    finally:
        assert console.choose_protocol(str(DEMO))  # the next test's idle_console waits for its engine

    cli_results = tmp_path / "cli"
    for participant in PARTICIPANTS:
        assert cli(["run", "--protocol", str(protocol), "--participant", participant, "--headless",
                    "--simulated-participant", "--results", str(cli_results)]) == 0
    capsys.readouterr()

    from_console, from_cli = seeds_in(gui_results), seeds_in(cli_results)
    assert from_console == from_cli
    assert from_console["P01"] != from_console["P02"]
    # the documented derivation (docs/experiment.md): numpy's SeedSequence of (study seed, enrolment index)
    assert [from_console[p] for p in PARTICIPANTS] == [
        int(np.random.SeedSequence([STUDY_SEED, index]).generate_state(1)[0]) for index in range(2)]
