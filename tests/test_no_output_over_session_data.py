"""No command writes over or inside a session folder, over a session lock, or over its own inputs
(issue 21, items 2 and 3): one line, exit 2, nothing written; ``optimise --checkpoint`` is checked
like ``-o``.

Each case runs ``studyapp ARGV`` in this process, as tests/test_bad_input.py does, on a fresh copy
of a prepared folder (as root, a command that ignored the rule would change it for the next case),
and every file in that folder must keep its bytes.
"""

import os
import shutil
from pathlib import Path

import pytest

from studyapp.cli import main
from tests.test_bad_input import (
    BREAKDOWN, OPTIMISE, PROTOCOL, RUN, SET, SIMULATE, TRADEOFF, UNWRITABLE, _argv, _recording, _results, _tree,
    assert_refused,
)


def _session_data(folder):
    """A results folder with one session holding a response, an audio.wav and an audio_cues.csv, and a recording."""
    _results(folder / "results")
    session = next((folder / "results").glob("demo/p1/*/"))
    (session / "audio.wav").write_bytes(b"RIFF....WAVE")
    (session / "audio-2.wav").write_bytes(b"RIFF....WAVE")
    (session / "audio_cues.csv").write_text("file,sample,seconds,step,task,trial,event\n")
    _recording(folder / "rec.npz")
    return session


@pytest.fixture(scope="module")
def session_template(tmp_path_factory):
    folder = tmp_path_factory.mktemp("session_data")
    session = _session_data(folder)
    return folder, session.relative_to(folder)


S = "{in}/{session}"
SESSION_DATA_CASES = {
    **{f"export-over-{name}": ["export", "{in}/results", "-o", f"{S}/{name}"]
       for name in ("events.jsonl", "session.json", "audio.wav", "audio-2.wav", "audio_cues.csv")},
    "export-into-session": ["export", "{in}/results", "-o", f"{S}/responses.csv"],
    "export-into-new-folder-in-session": ["export", "{in}/results", "-o", f"{S}/new/responses.csv"],
    "export-over-lock": ["export", "{in}/results", "-o", "{in}/results/demo/p1/.lock"],
    "export-over-link-to-events": ["export", "{in}/results", "-o", "{in}/link/events.jsonl"],
    "estimate-into-session": ["estimate", "{in}/rec.npz", "--estimator", "LOWPASS", "-o", f"{S}/audio_cues.csv"],
    "simulate-over-cues": [*SIMULATE, "-o", f"{S}/audio_cues.csv"],
    "simulate-set-session": [*SET, "-o", S],
    "breakdown-into-session": [*BREAKDOWN, "-o", f"{S}/b.csv"],
    "evaluate-into-session": ["evaluate", "{in}/rec.npz", "-o", S],
    "evaluate-into-inputs-folder": ["evaluate", "{in}/rec.npz", "-o", "{in}"],
    "tradeoff-into-session": [*TRADEOFF, "-o", S],
    "analyse-into-session": ["analyse", "{in}/results", "-o", S],
    "analyse-into-its-input": ["analyse", "{in}/results", "-o", "{in}/results"],
    "optimise-into-session": [*OPTIMISE, "{in}/rec.npz", "-o", f"{S}/p.toml"],
    "run-results-in-session": [*RUN, "--results", S, "--protocol", PROTOCOL],
    # optimise --checkpoint (item 3): checked like -o
    "optimise-checkpoint-is-input": [*OPTIMISE, "{in}/rec.npz", "-o", "{out}/p.toml", "--checkpoint", "{in}/rec.npz"],
    "optimise-checkpoint-is-output": [*OPTIMISE, "{in}/rec.npz", "-o", "{out}/p.toml", "--checkpoint", "{out}/p.toml"],
    "optimise-checkpoint-fifo": [*OPTIMISE, "{in}/rec.npz", "-o", "{out}/p.toml", "--checkpoint", "{in}/fifo"],
    "optimise-checkpoint-events": [*OPTIMISE, "{in}/rec.npz", "-o", "{out}/p.toml", "--checkpoint",
                                   f"{S}/events.jsonl"],
    "optimise-checkpoint-dir": [*OPTIMISE, "{in}/rec.npz", "-o", "{out}/p.toml", "--checkpoint", "{in}"],
    "optimise-checkpoint-unwritable": [*OPTIMISE, "{in}/rec.npz", "-o", "{out}/p.toml", "--checkpoint",
                                       UNWRITABLE + "/c.json"],
}


def _contents(folder):
    return {str(p.relative_to(folder)): p.read_bytes() for p in Path(folder).rglob("*")
            if p.is_file() and not p.is_symlink()}


@pytest.mark.parametrize("case", list(SESSION_DATA_CASES))
def test_no_command_writes_over_session_data_or_its_inputs(case, session_template, tmp_path, capsys, monkeypatch):
    template, session = session_template
    inputs = tmp_path / "in"
    shutil.copytree(template, inputs, symlinks=True)
    (inputs / "link").symlink_to(inputs / session)
    os.mkfifo(inputs / "fifo")
    out = tmp_path / "out"
    out.mkdir()
    monkeypatch.chdir(out)
    before = (_tree(inputs), _tree(out)), _contents(inputs)
    argv = [a.replace("{session}", str(session)) for a in SESSION_DATA_CASES[case]]
    code = main(_argv(argv, inputs, out))
    err = capsys.readouterr().err
    assert_refused(code, err, before[0], (_tree(inputs), _tree(out)))
    assert _contents(inputs) == before[1]
