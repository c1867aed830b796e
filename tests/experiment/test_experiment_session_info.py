"""Session information: experimenter, session number and notes stored and exported; the order row set
explicitly picks that row of each task's Latin square; bad values are one line, exit 2, nothing enrolled."""

import json
import math
from pathlib import Path

import pytest

from studyapp.cli import main
from studyapp.errors import UserError
from studyapp.experiment.export import export_responses
from studyapp.experiment.latin_square import balanced_latin_square, participant_row, task_seed
from studyapp.experiment.protocol import load_protocol, parse_protocol
from studyapp.experiment.session import Session
from tests.experiment.experiment_fake_loop import run_simulated

ROOT = Path(__file__).resolve().parents[2]
DEMO = ROOT / "protocols" / "demo.toml"
SINCLAIR = ROOT / "protocols" / "sinclair2014.toml"


def _run(tmp_path, *extra, participant="P1"):
    return main(["run", "--protocol", str(DEMO), "--participant", participant, "--headless",
                 "--simulated-participant", "--results", str(tmp_path), *extra])


def test_the_fields_are_stored_in_session_json_and_exported(tmp_path, capsys):
    assert _run(tmp_path, "--experimenter", "Dr. O'Neil", "--session-number", "12",
                "--notes", "Left headphone loose; fixed.\nRoom 2.", "--order-row", "4") == 0
    assert "order row 4 of 6 (set)" in capsys.readouterr().err
    (path,) = tmp_path.glob("demo/P1/*/session.json")
    info = json.loads(path.read_text())
    assert (info["experimenter"], info["session_number"], info["notes"]) == (
        "Dr. O'Neil", 12, "Left headphone loose; fixed.\nRoom 2.")
    assert (info["order_row"], info["order_rows"], info["order_row_source"]) == (4, 6, "set")
    assert _run(tmp_path, participant="P2") == 0  # nothing given: empty fields, the enrolment's row
    frame = export_responses(tmp_path)
    first, second = frame[frame.participant == "P1"], frame[frame.participant == "P2"]
    assert set(first.experimenter) == {"Dr. O'Neil"} and set(first.session_number) == {12}
    assert set(first.order_row) == {4} and set(second.order_row) == {1}  # P2 is the second to enrol
    assert second.experimenter.isna().all() and second.session_number.isna().all()
    assert "notes" not in frame.columns  # kept in session.json only


@pytest.mark.parametrize("option, value, words", [
    ("--experimenter", "rm -rf /;", "experimenter 'rm -rf /;': allowed is a short name"),
    ("--experimenter", "x" * 41, "allowed is a short name"),
    ("--session-number", "0", "session number '0': allowed is a whole number from 1 to 999"),
    ("--session-number", "1000", "from 1 to 999"),
    ("--session-number", "two", "session number 'two'"),
    ("--notes", "n" * 2001, "notes: 2001 characters: allowed is at most 2000"),
    ("--notes", "bell\x07", "notes: control character"),
    ("--order-row", "6", "order row '6': allowed is 0 to 5"),
    ("--order-row", "-1", "allowed is 0 to 5"),
    ("--order-row", "first", "order row 'first'"),
])
def test_bad_values_are_one_line_exit_2_and_nothing_is_enrolled(tmp_path, capsys, option, value, words):
    assert _run(tmp_path, option, value) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and err.startswith("studyapp: error: ") and words in err
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("row", [0, 5, 17, 71])
def test_an_order_row_picks_that_row_of_each_tasks_latin_square(tmp_path, row):
    protocol = load_protocol(SINCLAIR)
    session = Session.create(protocol, "P9", tmp_path, order_row=row)
    session.close()
    rating = [t for t in session.schedule if t.task == "rating" and t.phase == "trial"]  # not practice
    adjustment = [t for t in session.schedule if t.task == "adjustment" and t.phase == "trial"]
    square = balanced_latin_square(protocol.task("rating").conditions, task_seed(protocol.seed, "rating"))
    assert len(square) == 8 and list(rating[0].conditions) == participant_row(square, row)
    square = balanced_latin_square(protocol.task("adjustment").conditions, task_seed(protocol.seed, "adjustment"))
    assert len(square) == 18  # 9 conditions: a Williams square and its reversal
    for repetition in range(protocol.task("adjustment").trials):
        block = adjustment[9 * repetition:9 * repetition + 9]
        assert [t.condition for t in block] == list(square[(row + repetition) % 18])
    assert session.info["order_rows"] == math.lcm(8, 18) == 72


def test_the_enrolment_row_is_what_it_always_was_and_an_order_row_repeats_it(tmp_path):
    protocol = load_protocol(DEMO)
    for index in range(3):
        made = Session.create(protocol, f"E{index}", tmp_path / "auto")
        made.close()
        again = Session.create(protocol, "X", tmp_path / f"set{index}", order_row=index)
        again.close()
        assert made.info["order_row"] == index and made.info["order_row_source"] == "enrolment"
        assert made.schedule == again.schedule


def test_resume_keeps_the_stored_order_row_and_refuses_new_fields(tmp_path):
    protocol = load_protocol(DEMO)
    session = Session.create(protocol, "R1", tmp_path, experimenter="AB", order_row=3)
    run_simulated(session, trials=1)
    session.close()
    with pytest.raises(UserError, match="order row 2: session .* has order row 3"):
        Session.resume(protocol, "R1", tmp_path, order_row=2)
    with pytest.raises(UserError, match="experimenter: set when a session starts"):
        Session.resume(protocol, "R1", tmp_path, experimenter="CD")
    resumed = Session.resume(protocol, "R1", tmp_path, order_row=3, experimenter=None, session_number=None, notes="")
    resumed.close()
    assert resumed.info["experimenter"] == "AB"


def test_an_order_row_beyond_a_protocols_squares_is_refused_before_the_folder_is_made(tmp_path):
    text = DEMO.read_text().replace('conditions = ["LOWPASS", "LEVANT", "LVT"]\ntrials', 'conditions = ["LOWPASS", "LVT"]\ntrials')
    protocol = parse_protocol(text, "two.toml")
    with pytest.raises(UserError, match=r"allowed is 0 to 5 for two.toml \(its Latin squares: rating 6 rows, "
                                        r"adjustment 2 rows\)"):
        Session.create(protocol, "P1", tmp_path, order_row=6)
    assert list(tmp_path.iterdir()) == []
