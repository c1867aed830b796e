"""The rig check (live/rig_check.py): what is predicted for a protocol, the verdict and its warning line; and the
device the participant held in session.json and the export. Headless.

The prediction itself runs the model (model/link_prediction.py) with reduced seeds and trial length: at latency 0
(the paper's loop) LVT keeps its margin over the estimators, at 1 ms (5 samples at 5 kHz, the link device's default)
it falls below 1.5x and the check warns (issue 29's table: 2.14 and 1.08 at 5 seeds, 5 s).
"""

import json
import math
from pathlib import Path

import pytest

from studyapp.engine.config import EngineConfig
from studyapp.experiment.export import COLUMNS, export_responses
from studyapp.experiment.protocol import load_protocol
from studyapp.experiment.session import Session
from studyapp.live import rig_check
from studyapp.model.link_prediction import MARGIN
from tests.experiment.demo_protocol import trials_only_demo
from tests.experiment.experiment_fake_loop import run_simulated

ROOT = Path(__file__).resolve().parents[2]
DEMO = ROOT / "protocols" / "demo.toml"
SINCLAIR = ROOT / "protocols" / "sinclair2014.toml"
INFO = {"name": "studyapp emulator", "serial": "EMU-0042", "protocol": 1, "firmware": "1.0", "rate": 5000.0,
        "channels": ["position", "acceleration", "velocity"], "calibration": "device",
        "latency_samples": 5, "latency_ms": 1.0, "packet": 1, "round_trip_ms": {"median": 0.05, "p99": 0.4},
        "link": "/tmp/dev"}


def test_the_rig_of_an_engine_config():
    simulated = rig_check.rig_of(EngineConfig(rate=5000.0))
    assert (simulated.kind, simulated.latency, simulated.latency_samples) == ("simulated", 0.0, 0)
    assert not rig_check.needs_check(simulated)
    link = rig_check.rig_of(EngineConfig(rate=5000.0, device="/tmp/dev", device_latency=5))
    assert link.kind == "link" and link.latency == pytest.approx(1e-3) and link.latency_ms == pytest.approx(1.0)
    assert rig_check.needs_check(link)
    assert "on the host, 5 samples (1.00 ms) across the link" in link.words


def test_a_device_that_runs_the_loop_is_the_papers_own_loop():
    rig = rig_check.rig_of(EngineConfig(rate=5000.0, device="/tmp/dev", device_latency=5), loop="device")
    assert (rig.kind, rig.latency, rig.latency_samples) == ("device-loop", 0.0, 0)
    assert not rig_check.needs_check(rig)
    assert rig.words == "the loop runs on the device: the paper's own loop (latency 0)"
    host = rig_check.rig_of(EngineConfig(rate=5000.0, device="/tmp/dev", device_latency=5), loop="host")
    assert host.kind == "link" and host.latency_samples == 5


def test_the_request_is_the_adjustment_tasks_conditions_with_the_protocols_parameters(tmp_path):
    protocol = load_protocol(SINCLAIR)
    rig = rig_check.Rig("link", 5000.0, 5)
    req = rig_check.request(protocol, rig)
    assert req.conditions == tuple(protocol.task("adjustment").conditions) and len(req.conditions) == 9
    assert req.estimators["LOWPASS"] == {"cutoff_hz": 256.0} and req.estimators["LVT"] == {}
    assert req.key == (protocol.sha256, 1e-3, 0.0, 5000.0)
    no_adjustment = tmp_path / "rating.toml"
    no_adjustment.write_text(DEMO.read_text().replace('tasks = ["rating", "adjustment"]', 'tasks = ["rating"]')
                             .split("[adjustment]")[0])
    assert rig_check.request(load_protocol(no_adjustment), rig) is None


def test_the_verdict_its_text_and_warning_line():
    rig = rig_check.Rig("link", 5000.0, 5)
    keeps = rig_check.verdict({"LOWPASS": 3.87, "KALLEV": 2.85, "LVT": 8.29}, rig)
    assert keeps.best == "LOWPASS" and keeps.margin == pytest.approx(8.29 / 3.87)
    assert not keeps.warns and keeps.warning is None and "at least 1.5x" in keeps.text
    warns = rig_check.verdict({"LOWPASS": 2.85, "KALLEV": 2.46, "LVT": 3.09}, rig)
    assert warns.warns and warns.margin == pytest.approx(3.09 / 2.85)
    assert warns.warning == ("warning: at this rig's link latency of 5 samples (1.00 ms at 5000 Hz) the model "
                             "predicts LVT's bowing breakdown at 1.08x the best estimator's (LOWPASS), below 1.5x: "
                             "the paper's effect (LVT nearly twice the estimators) is not expected on this rig. "
                             + rig_check.REMEDY.format(samples=5))
    assert "(now 5)" in warns.warning and "--device-latency SAMPLES" in warns.warning
    alone = rig_check.verdict({"LVT": 3.0}, rig)
    assert math.isnan(alone.margin) and not alone.warns and alone.warning is None
    record = rig_check.record(rig_check.verdict({"LOWPASS": math.inf, "LVT": 3.0}, rig), started_anyway=True)
    assert json.loads(json.dumps(record, allow_nan=False))["prediction"] == {"LOWPASS": None, "LVT": 3.0}
    assert record["lvt_margin"] == 0.0 and record["threshold"] == MARGIN and record["started_anyway"]
    assert rig_check.rows({"LVT": 8.0, "LOWPASS": math.inf, "KALLEV": 2.5}) == [
        ("LOWPASS", "stable to 200 N"), ("LVT", "8.00 N"), ("KALLEV", "2.50 N")]


def test_the_cache_keeps_a_prediction_per_protocol_latency_packet_and_rate():
    protocol = load_protocol(DEMO)
    cache = rig_check.PredictionCache()
    at_1ms = rig_check.request(protocol, rig_check.Rig("link", 5000.0, 5))
    cache.put(at_1ms, {"LVT": 3.0})
    assert cache.get(rig_check.request(protocol, rig_check.Rig("link", 5000.0, 5))) == {"LVT": 3.0}
    assert cache.get(rig_check.request(protocol, rig_check.Rig("link", 5000.0, 1))) is None
    assert cache.get(rig_check.request(protocol, rig_check.Rig("simulated", 5000.0))) is None


def test_predictions_are_kept_on_disk_keyed_as_in_memory(tmp_path):
    # issue 41, item 10: a relaunch (gui --screenshot, run then its console) computed the prediction again
    protocol = load_protocol(DEMO)
    path = tmp_path / "cache" / "rig_predictions.json"
    at_1ms = rig_check.request(protocol, rig_check.Rig("link", 5000.0, 5))
    rig_check.PredictionCache(path).put(at_1ms, {"LVT": 3.09, "LOWPASS": math.inf})
    again = rig_check.PredictionCache(path)  # another launch
    assert again.get(rig_check.request(protocol, rig_check.Rig("link", 5000.0, 5))) == {"LVT": 3.09,
                                                                                       "LOWPASS": math.inf}
    assert again.get(rig_check.request(protocol, rig_check.Rig("link", 5000.0, 1))) is None
    assert again.get(rig_check.request(protocol, rig_check.Rig("link", 2500.0, 5))) is None
    path.write_text("{not json")
    assert rig_check.PredictionCache(path).get(at_1ms) is None  # a damaged file only costs the time


def test_the_cache_lies_under_xdg_cache_home(monkeypatch, tmp_path):
    monkeypatch.delenv("STUDYAPP_RIG_PREDICTIONS")
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    assert rig_check.cache_path() == tmp_path / "studyapp" / "rig_predictions.json"


@pytest.mark.parametrize("samples, warns", [(0, False), (5, True)])
def test_the_model_keeps_the_effect_at_latency_0_and_warns_at_1_ms(samples, warns):
    """The demo's adjustment conditions (LOWPASS, LEVANT, LVT), 1 seed of 2 s trials: at latency 0 LVT's breakdown
    is about twice LOWPASS's (measured 2.07x), at 1 ms about the same (1.07x)."""
    rig = rig_check.Rig("link" if samples else "simulated", 5000.0, samples)
    req = rig_check.request(load_protocol(DEMO), rig)
    seen = []
    prediction = rig_check.predict(req, seeds=1, duration=2.0, progress=lambda *a: seen.append(a))
    assert set(prediction) == {"LOWPASS", "LEVANT", "LVT"} and len(seen) == 3 and seen[-1][:2] == (3, 3)
    verdict = rig_check.verdict(prediction, rig)
    assert verdict.warns is warns, prediction
    assert (verdict.warning is not None) is warns
    assert verdict.margin > 1.8 if not warns else verdict.margin < 1.2


def test_session_json_and_the_export_carry_the_device(tmp_path):
    protocol = load_protocol(trials_only_demo(tmp_path))
    simulated = Session.create(protocol, "S01", tmp_path / "r", seed=1)
    run_simulated(simulated).finish()
    simulated.close()
    linked = Session.create(protocol, "L01", tmp_path / "r", seed=2,
                            device={"kind": "link", "link": "/tmp/dev", "info": INFO})
    run_simulated(linked).finish()
    linked.close()
    assert json.loads((simulated.folder / "session.json").read_text())["device"] == {"kind": "simulated",
                                                                                     "latency_ms": 0.0}
    stored = json.loads((linked.folder / "session.json").read_text())["device"]
    assert stored == {"kind": "link", "link": "/tmp/dev", "info": INFO}
    frame = export_responses(tmp_path / "r")
    assert list(frame.columns) == COLUMNS and COLUMNS[-3:] == ["device", "device_serial", "device_latency_ms"]
    assert COLUMNS[:-3][-1] == "simulated"  # the columns before keep their order
    by = frame.groupby("participant")
    assert set(by.get_group("S01").device) == {"simulated"} and by.get_group("S01").device_serial.isna().all()
    assert set(by.get_group("S01").device_latency_ms) == {0.0}
    assert set(by.get_group("L01").device) == {"studyapp emulator"}
    assert set(by.get_group("L01").device_serial) == {"EMU-0042"} and set(by.get_group("L01").device_latency_ms) == {1.0}


def test_each_response_carries_the_device_of_the_engine_run_that_answered_it(tmp_path):
    # issue 41, item 9: a session started on the emulator and resumed on the simulated device was exported with
    # the emulator on every row, though the resumed runs' engine records had no device
    from studyapp.experiment import records

    protocol = load_protocol(trials_only_demo(tmp_path))
    session = Session.create(protocol, "R01", tmp_path / "r", seed=4,
                             device={"kind": "link", "link": "/tmp/dev", "info": INFO})
    engine = {"rate": 5000.0, "block": 10, "audio": "null", "midi": "none", "paced": "device", "realtime": False}
    session.log.append(records.engine({**engine, "device": INFO}, 4))
    run_simulated(session, trials=2).finish("aborted")
    session.close()
    resumed = Session.resume(protocol, "R01", tmp_path / "r")
    resumed.log.append(records.engine({**engine, "paced": "timer"}, 4))  # the simulated device: no ``device``
    run_simulated(resumed).finish()
    resumed.close()
    frame = export_responses(tmp_path / "r").sort_values("step")
    first, rest = frame[frame.step < 2], frame[frame.step >= 2]
    assert len(first) >= 2 and len(rest) >= 1
    assert set(first.device) == {"studyapp emulator"} and set(first.device_serial) == {"EMU-0042"}
    assert set(first.device_latency_ms) == {1.0}
    assert set(rest.device) == {"simulated"} and rest.device_serial.isna().all()
    assert set(rest.device_latency_ms) == {0.0}
