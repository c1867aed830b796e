"""A real participant's log is never continued by a machine; every response says who gave it (issue 31 item 3)."""

from pathlib import Path

from studyapp.analysis.responses import check_responses
from studyapp.cli import main
from studyapp.experiment.export import export_responses
from studyapp.experiment.protocol import load_protocol
from studyapp.experiment.session import Session
from studyapp.experiment.session_runner import SessionRunner
from studyapp.experiment.session_log import read_events
from studyapp.experiment.simulated_participant import SimulatedParticipant
from tests.experiment.demo_protocol import trials_only_demo
from tests.experiment.experiment_fake_loop import NOISE, THRESHOLD, factory

ROOT = Path(__file__).resolve().parents[2]
DEMO = ROOT / "protocols" / "demo.toml"


def person_started(results):
    """P01's session, begun by a person: the first page acknowledged, then interrupted."""
    protocol = load_protocol(DEMO)
    session = Session.create(protocol, "P01", results, apparatus={"participant": "human"})
    runner = SessionRunner(session, make_loop=factory())
    runner.begin()
    runner.start_trial()
    runner.acknowledge_page("participant")
    runner.finish("interrupted")
    session.close()
    (log,) = Path(results).glob("demo/P01/*/events.jsonl")
    return log


def test_a_simulated_participant_may_not_resume_a_persons_session(tmp_path, capsys):
    log = person_started(tmp_path)
    before = log.read_bytes()
    for extra in (["--headless"], []):  # headless, and the console's path (refused before it opens)
        code = main(["run", "--protocol", str(DEMO), "--participant", "P01", "--resume", "--simulated-participant",
                     "--results", str(tmp_path), *extra])
        err = capsys.readouterr().err.strip()
        assert code == 2 and len(err.splitlines()) == 1 and "real participant" in err, err
        assert log.read_bytes() == before


def test_each_response_says_whether_a_machine_gave_it_and_export_and_analysis_follow_it(tmp_path):
    protocol = load_protocol(trials_only_demo(tmp_path))
    session = Session.create(protocol, "P01", tmp_path, apparatus={"participant": "human"})
    participant = SimulatedParticipant(session.seed, bow_time=0.1, probe_time=0.02)
    # the person's rating, then (an old log, before the refusal) a machine's adjustment trial
    for simulated in (False, True):
        runner = SessionRunner(session, make_loop=factory(NOISE, THRESHOLD), simulated=simulated)
        participant.play_trial(runner, runner.start_trial())
    session.close()
    (log,) = Path(tmp_path).glob("demo/P01/*/events.jsonl")
    responses = [e for e in read_events(log) if e["type"] == "response"]
    assert [r["simulated"] for r in responses] == [False, True]

    rows = export_responses(tmp_path)
    assert list(rows.simulated) == [False] * (len(rows) - 1) + [True]  # per row, not per session
    kept = check_responses(rows, "test")
    assert len(kept) == len(rows) - 1 and kept.attrs["simulated_left_out"] == ["P01"]
    assert len(check_responses(rows, "test", include_simulated=True)) == len(rows)
