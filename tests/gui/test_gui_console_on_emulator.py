"""The console on a device on a link, end to end (issue 29, item 5): ``studyapp device-emulator`` on a pty, the
console's engine on it (``EngineConfig(device=path)``), its ``DeviceInfo`` shown in the Apparatus panel, an
adjustment trial answered through the engine (bowed first: a confirm above the F_max heard is refused, issue 31),
and session.json, the engine's record (its recording's
metadata) and the export carrying the device."""

import json

import pytest

from studyapp.device.emulator_process import EmulatorProcess
from studyapp.experiment.export import export_responses
from tests.gui.conftest import ENGINE_START, wait_until

pytest.importorskip("pytestqt")

# alone: the engine, paced by the emulator's real-time clock, must feed the device's watchdog through a whole
# trial; at a load of 5-11 the same engine path in `studyapp live` fell 200 ms behind and the device reported
# WATCHDOG (tests/device/test_live_device.py, issue 39)
pytestmark = [pytest.mark.gui, pytest.mark.alone]

PROTOCOL = """
[study]
name = "devcheck"
tasks = ["adjustment"]
seed = 1

[apparatus]
rate = 5000.0

[adjustment]
conditions = ["LVT"]
trials = 1
ceiling = 40.0
decades = 2.0
instructions = "Turn the knob, press the pad."
"""


def keeps(req, progress=None):
    return {"LVT": 8.0, "LOWPASS": 4.0}


def test_the_console_runs_on_the_emulator_and_the_records_carry_the_device(qapp, tmp_path):
    from studyapp.gui.console import Console
    from studyapp.live.controller import SessionController

    protocol = tmp_path / "devcheck.toml"
    protocol.write_text(PROTOCOL)
    link = tmp_path / "device"
    # a generous watchdog and silence: this test is about the console's path, not about holding 1 ms when shared
    with EmulatorProcess(link, "--watchdog-ms", 200):
        controller = SessionController(audio="null", midi="none", device=str(link), hang_timeout=0.5)
        controller.apparatus.device_options = {"device_latency": 10, "device_silence": 0.5}
        console = Console(controller, predict=keeps)
        console.show()
        try:
            assert console.choose_protocol(str(protocol))
            wait_until(qapp, lambda: controller.engine is not None or controller.host.state == "failed", ENGINE_START)
            assert controller.host.state == "running", console.log.toPlainText()[-2000:]
            wait_until(qapp, lambda: "serial EMU-0000" in console.device_panel.summary.text(), 30)
            summary = console.device_panel.summary.text()
            assert "studyapp emulator" in summary and "10 samples = 2.00 ms" in summary
            assert "calibration: handshake" in summary and "ms median" in summary
            # the rows come from the breakdown prediction, computed off the GUI thread: seconds idle, more under load
            wait_until(qapp, lambda: console.device_panel.table.rowCount() == 2, 120)
            console.setup.participant.setText("EMU01")
            console.setup.results.setText(str(tmp_path / "results"))
            session = console.start_session(seed=3)
            assert session is not None, console.setup.error.text()
            wait_until(qapp, lambda: controller.playing and controller.runner.trial is not None, ENGINE_START)
            console.turn_knob(0, 40)
            wait_until(qapp, lambda: controller.runner.task.fmax > 0, 30)
            # nothing is confirmed that was not heard (issue 31): bow until this F_max has sounded, then confirm
            console.set_bowing(True)
            wait_until(qapp, lambda: controller.runner.task.heard_fmax >= controller.runner.task.fmax, 30)
            console.press_pad(0)
            wait_until(qapp, lambda: controller.state == "finished", 30)
        finally:
            console.shut_down()
    info = json.loads((session.folder / "session.json").read_text())
    device = info["device"]
    assert device["kind"] == "link" and device["link"] == str(link)
    assert device["info"]["serial"] == "EMU-0000" and device["info"]["latency_ms"] == pytest.approx(2.0)
    assert device["info"]["round_trip_ms"]["median"] > 0
    events = [json.loads(line) for line in (session.folder / "events.jsonl").read_text().splitlines()]
    engine = next(e for e in events if e["type"] == "engine")
    assert engine["paced"] == "device" and engine["device"]["serial"] == "EMU-0000"
    assert any(e["type"] == "device_health" for e in events)
    frame = export_responses(tmp_path / "results")
    assert len(frame) == 1
    row = frame.iloc[0]
    assert (row.device, row.device_serial, row.device_latency_ms) == ("studyapp emulator", "EMU-0000", 2.0)
