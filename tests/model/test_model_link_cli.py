"""``--latency``, ``--packet``, ``--jitter`` on ``breakdown`` and ``simulate`` (issue 29 item 1), in samples as on
every command line (issue 41 item 6: they were seconds here, samples in ``live`` and ``bench``): the outputs say the
link, bad values are one line and exit 2 with nothing written; the console's prediction function."""

import csv
import json
import math

import pytest

from studyapp.cli import main
from studyapp.io import recording
from studyapp.model import breakdown, link_prediction
from studyapp.model.link import LinkSpec

LINK = ["--latency", "2", "--packet", "5", "--jitter", "1"]  # samples at 5 kHz: 0.4 ms, 1 ms, 0.2 ms


@pytest.fixture
def seen_links(monkeypatch):
    """Every trial stable (inf at once); records the link each trial ran with."""
    links = []

    def is_broken(source, fmax, link=None, **kwargs):
        links.append(link)
        return False

    monkeypatch.setattr(breakdown, "is_broken", is_broken)
    return links


def test_breakdown_outputs_say_the_link(seen_links, tmp_path, capsys):
    assert main(["breakdown", "--source", "LVT", "--seeds", "2", *LINK, "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert (doc["latency"], doc["packet"], doc["jitter"]) == (0.0004, 0.001, 0.0002)
    assert set(seen_links) == {LinkSpec(latency=0.0004, packet=0.001, jitter=0.0002)}
    out_csv, out_md = tmp_path / "b.csv", tmp_path / "b.md"
    assert main(["breakdown", "--source", "LVT", "--seeds", "2", *LINK, "-o", str(out_csv)]) == 0
    (row,) = csv.DictReader(out_csv.open())
    assert [float(row[k]) for k in ("latency", "packet", "jitter")] == [0.0004, 0.001, 0.0002]
    assert main(["breakdown", "--source", "LVT", "--seeds", "2", *LINK, "-o", str(out_md)]) == 0
    text = out_md.read_text()
    assert ("behind a link (`studyapp.model.link`): latency 2 samples (0.4 ms), packet 5 samples (1 ms), jitter 1 "
            "samples (0.2 ms).") in text
    assert "--latency 2 --packet 5 --jitter 1 -o" in text  # the command that regenerates it
    assert main(["breakdown", "--source", "LVT", "--seeds", "1", "-o", str(out_md)]) == 0
    assert "on an ideal link" in out_md.read_text() and "--latency" not in out_md.read_text()


def test_simulate_records_the_link_in_the_metadata(tmp_path):
    out = tmp_path / "s.npz"
    assert main(["simulate", "--fmax", "2", "--duration", "0.05", "--latency", "1", "--packet", "5",
                 "-o", str(out)]) == 0
    link = recording.load(out).meta["link"]
    assert link == {"latency": 0.0002, "packet": 0.001, "jitter": 0.0, "loss": 0.0, "latency_samples": 1,
                    "packet_samples": 5, "jitter_samples": 0}
    assert main(["simulate", "--fmax", "2", "--duration", "0.05", "-o", str(out)]) == 0
    assert recording.load(out).meta["link"]["latency_samples"] == 0


@pytest.mark.parametrize("argv, words", [
    (["--latency", "-1"], "--latency -1: allowed is a whole number of samples from 0 to 5000 (1 s at 5000 Hz)"),
    (["--packet", "5001"], "--packet 5001: allowed is a whole number of samples from 0 to 5000"),
    (["--jitter", "inf"], "--jitter inf: allowed is a whole number of samples"),
    (["--latency", "soon"], "--latency 'soon': allowed is a whole number of samples"),
    (["--latency", "0.0004"], "--latency 0.0004: allowed is a whole number of samples from 0 to 5000 (1 s at 5000 Hz); "
                              "0.0004 s would be 2"),
    (["--rate", "10000", "--packet", "2.5"], "--packet 2.5: allowed is a whole number of samples from 0 to 10000 (1 s "
                                             "at 10000 Hz)"),
])
def test_simulate_refuses_bad_link_values(tmp_path, capsys, argv, words):
    assert main(["simulate", "--duration", "0.05", *argv, "-o", str(tmp_path / "s.npz")]) == 2
    captured = capsys.readouterr()
    err = captured.err.strip().splitlines()
    assert len(err) == 1 and words in err[0], captured.err
    assert list(tmp_path.iterdir()) == []


def test_predict_runs_each_condition_alone_behind_the_link(monkeypatch):
    calls = []

    def fake(source, seed=0, estimators=None, link=None, **kwargs):
        calls.append((source, seed, estimators, link))
        return {"LVT": 6.0, "LOWPASS": 4.0, "KALLEV": 3.0, "TRUE": math.inf}[source] + seed

    monkeypatch.setattr(link_prediction, "breakdown_fmax", fake)
    progress = []
    params = {"LOWPASS": {"cutoff_hz": 256.0}, "KALLEV": {"q": 1.0}}
    got = link_prediction.predict(["LOWPASS", "KALLEV", "LVT", "TRUE"], 0.0002, 5000.0, seeds=3,
                                  estimators=params, progress=lambda *a: progress.append(a))
    assert got == {"LOWPASS": 5.0, "KALLEV": 4.0, "LVT": 7.0, "TRUE": math.inf}  # medians over seeds 0-2
    assert {c[3] for c in calls} == {LinkSpec(latency=0.0002)}
    assert [c[2] for c in calls if c[0] == "LOWPASS"] == [{"LOWPASS": {"cutoff_hz": 256.0}}] * 3
    assert [c[2] for c in calls if c[0] == "LVT"] == [{}] * 3
    assert progress[-1] == (12, 12, "TRUE") and len(progress) == 12
    assert link_prediction.lvt_margin(got) == pytest.approx(7.0 / 5.0)
    assert not link_prediction.keeps_effect(got)
    assert link_prediction.keeps_effect({"LVT": 8.3, "LOWPASS": 3.9, "TRUE": 21.6})
    assert math.isnan(link_prediction.lvt_margin({"LVT": 8.3}))
