"""Issue 22 item 11: simulated runs are marked, exported as such, and take no real participant's order row.

In the reported study SIM01 was run first and got order row 0, so the first real participant
got row 1. The rule now (studyapp/experiment/enrolment.py): real and simulated participants
are counted apart, so the k-th real participant gets order row k mod L whatever simulated runs
came before or between.
"""

import json

import pytest

from studyapp.experiment.enrolment import enrolled, enrolment_index, is_simulated
from studyapp.experiment.export import COLUMNS, export_responses
from studyapp.experiment.protocol import load_protocol
from studyapp.experiment.session import Session
from tests.experiment.demo_protocol import trials_only_demo

SIMULATED = {"device": "simulated", "participant": "simulated"}
HUMAN = {"participant": "human"}


@pytest.fixture
def protocol(tmp_path):
    return load_protocol(trials_only_demo(tmp_path))


def _create(protocol, folder, participant, apparatus):
    session = Session.create(protocol, participant, folder, apparatus=apparatus)
    info = session.info
    session.log.append({"type": "response", "step": 1, "task": "adjustment", "condition": "LVT", "trial": 1,
                        "fmax": 2.5, "value": 60, "peak_fmax": 3.0, "duration": 4.0})
    session.close()
    return info


def test_simulated_runs_take_no_real_participants_order_row(tmp_path, protocol):
    order = [("SIM01", SIMULATED), ("P01", HUMAN), ("SIM02", SIMULATED), ("P02", HUMAN), ("P03", None)]
    infos = {pid: _create(protocol, tmp_path, pid, apparatus) for pid, apparatus in order}
    rows = infos["P01"]["order_rows"]
    assert [infos[p]["order_row"] for p in ("P01", "P02", "P03")] == [0, 1 % rows, 2 % rows]
    assert [infos[p]["participant_index"] for p in ("P01", "P02", "P03")] == [0, 1, 2]
    assert [infos[p]["order_row"] for p in ("SIM01", "SIM02")] == [0, 1 % rows]  # their own count
    assert [infos[p]["simulated"] for p in ("SIM01", "P01", "SIM02", "P02", "P03")] == [True, False, True, False, False]
    # the same schedule as a study with no simulated run at all
    alone = tmp_path / "alone"
    for pid in ("P01", "P02", "P03"):
        assert _create(protocol, alone, pid, HUMAN)["schedule"] == infos[pid]["schedule"]


def test_sessions_stored_before_the_key_are_read_from_the_apparatus(tmp_path, protocol):
    info = _create(protocol, tmp_path, "SIM01", SIMULATED)
    path = next((tmp_path / protocol.study / "SIM01").glob("*/session.json"))
    stored = json.loads(path.read_text())
    del stored["simulated"]
    path.write_text(json.dumps(stored))
    assert info["simulated"] is True and is_simulated(stored)
    assert enrolled(tmp_path / protocol.study) == {"SIM01": True}
    assert enrolment_index(tmp_path / protocol.study, "P01", simulated=False) == 0
    assert enrolment_index(tmp_path / protocol.study, "SIM02", simulated=True) == 1


def test_an_unreadable_participant_counts_as_real(tmp_path, protocol):
    _create(protocol, tmp_path, "P01", HUMAN)
    broken = tmp_path / protocol.study / "PX" / "2026-01-01T00-00-00"
    broken.mkdir(parents=True)
    (broken / "events.jsonl").write_text("not json\n")
    assert enrolled(tmp_path / protocol.study) == {"P01": False, "PX": False}
    assert enrolment_index(tmp_path / protocol.study, "P02", simulated=False) == 2


def test_export_has_a_simulated_column(tmp_path, protocol):
    _create(protocol, tmp_path, "SIM01", SIMULATED)
    _create(protocol, tmp_path, "P01", HUMAN)
    frame = export_responses(tmp_path)
    assert "simulated" in COLUMNS and frame["simulated"].dtype == bool
    assert dict(zip(frame["participant"], frame["simulated"])) == {"P01": False, "SIM01": True}
