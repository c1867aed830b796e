"""The Apparatus panel's device (issue 29, item 5), over a fake engine host and a fake prediction: the choice
(simulated, or a link remembered in the settings), the handshake, health and latency a ``DeviceInfo`` and a
``DeviceHealth`` bring, the rig check's table and verdict, and the warning at Start that must be accepted
(No keeps the session from starting; Yes starts it, with the device in session.json and the warning in the log)."""

import json
import threading

import pytest
from PySide6.QtCore import QSettings
from PySide6.QtWidgets import QMessageBox

from studyapp.engine.events import DeviceHealth, DeviceInfo
from tests.gui.conftest import DEMO, answer_question, wait_until
from tests.live.test_rig_check import INFO

pytest.importorskip("pytestqt")

pytestmark = pytest.mark.gui

PAPER = {"LOWPASS": 3.94, "LEVANT": 3.35, "LVT": 8.16}  # latency 0 (1 seed, 2 s; tests/live/test_rig_check.py)
AT_1MS = {"LOWPASS": 2.89, "LEVANT": 2.89, "LVT": 3.09}


def fake_predict(req, progress=None):
    assert threading.current_thread() is not threading.main_thread()  # off the GUI thread
    for done, name in enumerate(req.conditions, 1):
        progress(done, len(req.conditions), name)
    return AT_1MS if req.rig.latency > 0 else PAPER


@pytest.fixture
def device_console(qapp, tmp_path, monkeypatch):
    from studyapp.gui import device_panel
    from studyapp.gui.console import Console
    from studyapp.live.controller import SessionController
    from tests.live.fakes import FakeHost

    store = QSettings(str(tmp_path / "settings.ini"), QSettings.Format.IniFormat)
    monkeypatch.setattr(device_panel, "settings", lambda: store)
    controller = SessionController(audio="null", midi="none", make_host=FakeHost)
    console = Console(controller, predict=fake_predict)
    console.timer.stop()  # polled by hand
    controller.events.status.disconnect(console._on_status)  # the fake engine has no loop readouts for the status bar
    console.show()
    assert console.choose_protocol(str(DEMO))
    console.setup.participant.setText("DEV01")
    console.setup.results.setText(str(tmp_path / "results"))
    yield console, store
    if console.isVisible():
        console.abort_session()
        console.close()


def run_engine(console, qapp, drained=()):
    """The fake engine comes up (its device's records drained at the same poll)."""
    host = console.controller.host
    console.controller.poll()  # "starting": the rig check starts
    host.drain = lambda: list(drained)
    host.state = "running"
    console.controller.poll()
    host.drain = lambda: []


def test_the_panel_shows_the_device_the_prediction_and_start_warns(device_console, qapp, qtbot):
    console, store = device_console
    panel = console.device_panel
    run_engine(console, qapp)
    assert "simulated 1-DOF device" in panel.summary.text() and "latency 0" in panel.summary.text()
    wait_until(qapp, lambda: panel.table.isVisibleTo(console) and panel.table.rowCount() == 3, 10)
    assert [panel.table.item(r, 0).text() for r in range(3)] == ["LVT", "LOWPASS", "LEVANT"]
    assert panel.table.item(0, 1).text() == "8.16 N"
    assert "LVT 2.07x the best estimator (LOWPASS)" in panel.check.text() and "at least 1.5x" in panel.check.text()

    panel.kind.setCurrentText("link")
    panel.link.setText("/tmp/studyapp-device")
    panel.use.click()
    assert console.controller.apparatus.device == "/tmp/studyapp-device"
    assert (store.value("device/kind"), store.value("device/link")) == ("link", "/tmp/studyapp-device")
    console.controller.poll()
    assert "waiting for the handshake" in panel.summary.text()
    run_engine(console, qapp, [DeviceInfo(INFO), DeviceHealth(2, {"frames": 900, "samples": 900, "late": 3}, {})])
    text = panel.summary.text()
    for said in ("studyapp emulator", "serial EMU-0042", "protocol v1", "firmware 1.0", "5000 Hz",
                 "position (m)", "velocity (m/s)", "calibration: handshake", "5 samples = 1.00 ms",
                 "0.05 ms median, 0.40 ms p99"):
        assert said in text, said
    assert panel.health.text().startswith("trial 2: 900 frames") and "3 late" in panel.health.text()
    wait_until(qapp, lambda: "below 1.5x" in panel.check.text(), 10)
    assert "LVT 1.07x the best estimator (LOWPASS)" in panel.check.text() and "1.00 ms" in panel.check.text()
    assert panel.table.rowCount() == 3

    answer_question(console, qtbot, QMessageBox.StandardButton.No)
    assert console.start_session(seed=1) is None
    assert not console.controller.in_session and "not accepted" in console.setup.error.text()
    answer_question(console, qtbot, QMessageBox.StandardButton.Yes)
    session = console.start_session(seed=1)
    assert session is not None and console.controller.in_session
    assert "1.00 ms" in console.log.toPlainText() and "started anyway" in console.log.toPlainText()
    stored = json.loads((session.folder / "session.json").read_text())["device"]
    assert stored == {"kind": "link", "link": "/tmp/studyapp-device", "info": INFO}
    events = [json.loads(line) for line in (session.folder / "events.jsonl").read_text().splitlines()]
    check = next(e for e in events if e["type"] == "rig_check")
    assert check["started_anyway"] and check["warning"].startswith("warning: at this rig's link latency of 5 samples (1.00 ms")
    assert check["prediction"] == AT_1MS and check["lvt_margin"] == pytest.approx(3.09 / 2.89)


def test_a_simulated_rig_starts_without_a_question(device_console, qapp, monkeypatch):
    console, _ = device_console
    run_engine(console, qapp)
    monkeypatch.setattr(console, "confirm", lambda *a: pytest.fail("asked on a rig that keeps the effect"))
    session = console.start_session(seed=2)
    assert session is not None
    assert json.loads((session.folder / "session.json").read_text())["device"] == {"kind": "simulated",
                                                                                   "latency_ms": 0.0}


def _endless(ended, started=None):
    import time

    def endless(req, progress=None):
        if started is not None:
            started.set()
        try:
            while True:
                progress(0, 1, "LVT")
                time.sleep(0.01)
        finally:
            ended.set()
    return endless


def _request(latency):
    from studyapp.live import rig_check

    return rig_check.Request(("LVT",), {}, rig_check.Rig("link", 5000.0, latency), "hash")


def test_a_running_prediction_stops_when_cancelled(qapp):
    """The console cancels its prediction when it closes: its pool would otherwise wait for it."""
    from studyapp.gui.rig_prediction import RigPrediction

    ended, started = threading.Event(), threading.Event()
    prediction = RigPrediction(_endless(ended, started))
    prediction.run(_request(5))
    assert prediction.busy and started.wait(60.0)
    prediction.cancel()
    assert ended.wait(60.0) and prediction.pool.waitForDone(60_000)
    assert not prediction.busy


def test_a_request_no_longer_current_stops_its_job_and_a_queued_one_never_runs(qapp):
    """Another device chosen while a prediction runs: the stale job stops at its next report (at the lowest
    priority on a busy machine, left to finish it held the one thread for minutes), and one queued behind
    it and made stale in turn never calls ``predict``."""
    from studyapp.gui.rig_prediction import RigPrediction

    ended, started = threading.Event(), threading.Event()
    calls = []
    endless = _endless(ended, started)

    def predict(req, progress=None):
        calls.append(req.rig.latency_samples)
        return endless(req, progress) if req.rig.latency_samples == 5 else {"LVT": 8.0}

    prediction = RigPrediction(predict)
    shown = []
    prediction.finished.connect(lambda req, p: shown.append((req.rig.latency_samples, p)))
    prediction.run(_request(5))
    assert started.wait(60.0)
    prediction.run(_request(7))  # queued behind the running job on the one thread
    prediction.run(_request(9))  # 7 goes stale before it starts
    assert ended.wait(60.0)
    wait_until(qapp, lambda: shown, 60)
    assert shown == [(9, {"LVT": 8.0})] and calls == [5, 9]
    assert prediction.pool.waitForDone(60_000)


def test_one_consoles_prediction_never_waits_for_anothers(qapp):
    """Each ``RigPrediction`` has its own thread: a console's quick check is not queued behind another's
    (a clean-clone run at load 4 timed out waiting for rows that were quick, behind the tests' shared console)."""
    from studyapp.gui.rig_prediction import RigPrediction

    ended, started = threading.Event(), threading.Event()
    busy = RigPrediction(_endless(ended, started))
    quick = RigPrediction(lambda req, progress=None: {"LVT": 8.0})
    shown = []
    quick.finished.connect(lambda req, p: shown.append(p))
    for _ in range(4):  # more than the machine's cores: the application's pool would hold them all
        busy.run(_request(5))
        busy.run(_request(6))
    assert started.wait(60.0)
    quick.run(_request(5))
    wait_until(qapp, lambda: shown, 60)
    assert shown == [{"LVT": 8.0}] and busy.busy
    busy.cancel()
    assert ended.wait(60.0) and busy.pool.waitForDone(60_000)
