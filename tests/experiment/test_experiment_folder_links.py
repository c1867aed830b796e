"""No file is written through a folder planted as a link under the results folder (issue 41, item 13).

On main ``run`` with ``RESULTS/demo/P9`` a link to E (or ``RESULTS/demo`` a link)
exited 0 and wrote ``.lock`` and the whole session into E. Now the start is
refused with one line naming the link, exit 2, and nothing is written anywhere."""

import os
import subprocess
import sys
from pathlib import Path

import pytest

from studyapp.errors import UserError
from studyapp.experiment.protocol import load_protocol
from studyapp.experiment.session import Session
from tests.experiment.demo_protocol import trials_only_demo
from tests.experiment.experiment_fake_loop import run_simulated

ROOT = Path(__file__).resolve().parents[2]


def _tree(folder):
    return sorted(str(p.relative_to(folder)) for p in Path(folder).rglob("*"))


def _run(results, *extra):
    return subprocess.run([sys.executable, "-m", "studyapp", "run", "--protocol", str(ROOT / "protocols" / "demo.toml"),
                           "--participant", "P9", "--simulated-participant", "--headless", "--results", str(results),
                           *extra], capture_output=True, text=True, timeout=120, stdin=subprocess.DEVNULL,
                          env={**os.environ, "PYTHONPATH": str(ROOT)})


@pytest.mark.parametrize("linked", ["demo/P9", "demo"])
def test_run_into_a_linked_participant_or_study_folder_is_refused_and_writes_nothing(tmp_path, linked):
    results, elsewhere = tmp_path / "R", tmp_path / "E"
    elsewhere.mkdir()
    (results / linked).parent.mkdir(parents=True, exist_ok=True)
    (results / linked).symlink_to(elsewhere)
    before = _tree(results)
    for extra in ((), ("--resume",)):
        done = _run(results, *extra)
        assert done.returncode == 2, done.stderr
        lines = done.stderr.strip().splitlines()
        assert len(lines) == 1 and "Traceback" not in done.stderr
        assert f"{results / linked}: a link to {elsewhere}" in lines[0] and "allowed is" in lines[0]
        assert _tree(elsewhere) == [] and _tree(results) == before


def test_resume_of_a_session_folder_planted_as_a_link_is_refused(tmp_path):
    protocol = load_protocol(trials_only_demo(tmp_path))
    results = tmp_path / "results"
    session = Session.create(protocol, "L01", results)
    run_simulated(session, trials=1).finish("interrupted")
    session.close()
    moved = tmp_path / "elsewhere"
    os.replace(session.folder, moved)
    session.folder.symlink_to(moved)
    log = moved / "events.jsonl"
    before = log.read_bytes()
    with pytest.raises(UserError) as refused:
        Session.resume(protocol, "L01", results)
    assert f"{session.folder}: a link to {moved}" in str(refused.value)
    assert log.read_bytes() == before
