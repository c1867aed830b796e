"""A valid protocol of 531 KB starts a session (issue 33, item 6).

On main its text is stored twice in session.json (the text, and the page in the
settings), over session.json's 1 MB read limit, and the app called its own new
file "damaged"."""

from studyapp.experiment.export import export_responses
from studyapp.experiment.protocol import load_protocol
from studyapp.experiment.session import Session
from tests.experiment.demo_protocol import DEMO
from tests.experiment.experiment_fake_loop import run_simulated


def test_a_531_kb_protocol_starts_a_session_without_a_note(tmp_path):
    text = DEMO.read_text()
    long_page = "A welcome that goes on. " * 22_000  # 528 KB of page text
    text = text.replace('text = "That is all. Thank you!"', f'text = "{long_page}"', 1)
    path = tmp_path / "long.toml"
    path.write_text(text)
    assert 500_000 < path.stat().st_size < 600_000
    protocol = load_protocol(path)
    session = Session.create(protocol, "L01", tmp_path / "results")
    try:
        assert session.notes == []
        assert (session.folder / "session.json").stat().st_size > 1 << 20
        run_simulated(session, trials=1)
    finally:
        session.close()
    problems = []
    export_responses(tmp_path / "results", problems)
    assert problems == []
    resumed = Session.resume(protocol, "L01", tmp_path / "results")
    try:
        assert resumed.notes == []
    finally:
        resumed.close()
