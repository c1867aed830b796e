"""A session copied to another folder is one session: export and analyse count it once (issue 41, item 14).

On main ``cp -r P1/SESSION P1/SESSION2`` doubled every response in ``export``
(14 from 7, no warning) and ``analyse`` ran on them; a copied participant folder
warned but still doubled. A session is named by its log's CRC-checked
``session_created`` record, so each copy is reported in one line naming both
folders and its responses are counted once."""

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest

from studyapp.analysis.responses import load_responses
from studyapp.experiment.export import export_responses
from studyapp.experiment.protocol import load_protocol
from studyapp.experiment.session import Session
from tests.experiment.demo_protocol import trials_only_demo
from tests.experiment.experiment_fake_loop import run_simulated

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture
def study(tmp_path):
    protocol = load_protocol(trials_only_demo(tmp_path))
    results = tmp_path / "results"
    folders = []
    for participant in ("C01", "C02"):
        session = Session.create(protocol, participant, results)
        run_simulated(session)
        session.close()
        folders.append(session.folder)
    return protocol, results, folders


def _counts(frame):
    return frame.groupby("participant").size().to_dict()


def test_a_copied_session_and_a_copied_participant_folder_count_once(study):
    _, results, (first, second) = study
    alone = _counts(export_responses(results, []))
    shutil.copytree(first, first.with_name(first.name + "2"))
    shutil.copytree(second.parent, second.parent.with_name("C02copy"))
    problems = []
    frame = export_responses(results, problems)
    assert _counts(frame) == alone and not frame.duplicated(["participant", "session", "step", "knob"]).any()
    copies = [p for p in problems if "a copy of session" in p]
    assert len(copies) == 2 and all("\n" not in p for p in copies)
    assert any(p.startswith(f"{first.with_name(first.name + '2')}:") and f"in {first}" in p for p in copies)
    copied = second.parent.with_name("C02copy") / second.name
    assert any(p.startswith(f"{copied}:") and f"in {second}" in p for p in copies)
    analysed, _ = load_responses(results, [])
    assert analysed.groupby("participant").size().to_dict() == _counts(export_responses(results, []).query("not practice"))


def test_a_copy_taken_mid_session_loses_to_the_session_that_went_on(tmp_path):
    protocol = load_protocol(trials_only_demo(tmp_path))
    results = tmp_path / "results"
    session = Session.create(protocol, "C03", results)
    run_simulated(session, trials=2).finish("interrupted")
    session.close()
    early = tmp_path / "early-copy" / "C03" / session.folder.name
    shutil.copytree(session.folder, early)
    session = Session.resume(protocol, "C03", results)
    run_simulated(session)
    session.close()
    shutil.copytree(early, results / protocol.study / "C03" / "backup")
    problems = []
    frame = export_responses(results, problems)
    assert frame["step"].nunique() == len(session.schedule) and not frame.duplicated(["step", "knob"]).any()
    assert any(p.startswith(str(results / protocol.study / "C03" / "backup")) and f"in {session.folder}" in p
               for p in problems)


def test_export_cli_reports_the_copy_and_writes_each_response_once(study, tmp_path):
    _, results, (first, _) = study
    shutil.copytree(first, first.with_name(first.name + "2"))
    out = tmp_path / "x.csv"
    done = subprocess.run([sys.executable, "-m", "studyapp", "export", str(results), "-o", str(out)],
                          capture_output=True, text=True, timeout=120, stdin=subprocess.DEVNULL,
                          env={**os.environ, "PYTHONPATH": str(ROOT)})
    assert done.returncode == 0, done.stderr
    warned = [line for line in done.stderr.splitlines() if "a copy of session" in line]
    assert len(warned) == 1 and str(first) in warned[0]
    written = pd.read_csv(out)
    assert not written.duplicated(["participant", "session", "step", "knob"]).any()
