"""The experimenter console (pytest-qt, offscreen): it builds, the scope receives data, the emergency stop zeroes force."""

import time

import numpy as np
import pytest

from tests.gui.conftest import wait_until

pytest.importorskip("pytestqt")

pytestmark = pytest.mark.gui

FMAX_STEP = 56  # knob 1 position for F_max ~1 N on the preview's live knob (model.fmax_knob, LIVE_RANGE)


def bow_preview(console, qapp):
    """Bow the preview engine at ~1 N with the scripted strokes, through the console's controls."""
    from studyapp.model.fmax_knob import LIVE_RANGE, fmax_from_knob

    assert 0.9 < fmax_from_knob(FMAX_STEP, *LIVE_RANGE) < 1.1
    console.turn_knob(0, FMAX_STEP)
    console.set_gesture("strokes")
    console.set_bowing(True)
    c = console.controller
    wait_until(qapp, lambda: c.engine.status()["fmax"] > 0.9, 10)


def telemetry_after(console, qapp, seconds):
    """Every telemetry block the console receives during the next ``seconds``, joined."""
    blocks = []
    callback = console.controller.events.telemetry.connect(lambda block: blocks.append(block))
    try:
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            qapp.processEvents()
            time.sleep(0.005)
    finally:
        console.controller.events.telemetry.disconnect(callback)
    assert blocks, "no telemetry arrived"
    return {key: np.concatenate([b[key] for b in blocks]) for key in ("force", "velocity_lvt", "position")}


def test_console_builds_with_its_parts(idle_console):
    console = idle_console
    c = console.controller
    assert "Demonstration" in console.windowTitle()
    assert console.setup.protocol_path.endswith("demo.toml")
    assert len(console.knobs.dials) == 8 and len(console.knobs.pads) == 8
    tabs = [console.tabs.tabText(i) for i in range(console.tabs.count())]
    assert tabs == ["Live", "Analysis", "Log"]
    assert console.stop_button.text() == "EMERGENCY STOP" and console.stop_button.isEnabled()
    assert console.start_button.isEnabled() and not console.abort_button.isEnabled()
    # the apparatus lines say what the engine found, and what it fell back to
    info = c.engine.info
    audio, midi = console.setup.audio.text(), console.setup.midi.text()
    if info["audio"] == "null":
        assert "no sound (null sink)" in audio
        assert "audio:" in audio  # the engine's own reason (no PortAudio device here)
    else:
        assert info["audio"] in audio
    if info["midi"] == "none":
        assert "on-screen knobs" in midi and "MIDI:" in midi
    else:
        assert info["midi"] in midi
    assert "simulated 1-DOF device" in console.setup.device.text()
    assert "5000 Hz" in console.setup.engine.text()
    assert console.status.labels["engine"].text().startswith("Engine: running")


def test_status_bar_shows_the_loop(idle_console, qapp):
    console = idle_console
    wait_until(qapp, lambda: console.status.labels["rate"].text().startswith("Loop"), 5)
    status = console.controller.engine.status()
    rate_text = console.status.labels["rate"].text()
    assert f"{status['rate']:,.0f} Hz" in rate_text
    for key, word in (("load", "Load"), ("misses", "Deadline misses"), ("underruns", "Audio underruns"),
                      ("faults", "Faults")):
        assert console.status.labels[key].text().startswith(word)
    # a knob turned on screen: the worker applies it and measures its knob-to-effect latency
    # (the shared console's earlier knob turns already filled the label: wait for this turn's latency in it)
    console.turn_knob(1, 90)
    label = console.status.labels["knob"]
    latency = console.controller.latency
    wait_until(qapp, lambda: latency.last is not None and f"{1e3 * latency.last:.1f} ms" in label.text(), 5)
    assert label.text().startswith("Knob → effect") and 0 < latency.last < 1.0


def test_scope_receives_data_and_draws_it(idle_console, qapp, tmp_path):
    console = idle_console
    scope = console.scope
    bow_preview(console, qapp)
    before = scope.buffer.end
    # half a second of bowing, and a full window (1 s at 5 kHz) in the buffer
    wait_until(qapp, lambda: scope.buffer.end > before + 2500 and scope.buffer.count >= 5000, 10)
    assert set(scope.traces) >= {"velocity_lvt", "source_velocity", "string_velocity", "force",
                                 "estimate:LOWPASS", "estimate:LEVANT", "estimate:LVT"}
    # the buffer holds what the engine wrote: the scope's newest samples are the ring's
    engine = console.controller.engine
    newest = scope.buffer.latest(200)
    ring = engine.telemetry(since=scope.buffer.end - 200)
    np.testing.assert_array_equal(newest[scope.buffer.channels.index("force")], ring["force"][:200])
    # the drawn curves: about two points per pixel column, spanning the window, bowing at ~1 N
    wait_until(qapp, lambda: scope.traces["force"][0].getData()[0] is not None, 5)
    scope.redraw()
    x, y = scope.traces["force"][0].getData()
    assert x[0] >= -scope.seconds.value() - 1e-9 and x[-1] <= 0.0
    assert x[-1] - x[0] > 0.9 * scope.seconds.value()
    assert 0.5 < np.max(np.abs(y)) <= 1.05
    # freeze: the curves stop changing while samples keep arriving; resume: they move again
    scope.freeze_button.click()
    assert scope.frozen and scope.freeze_button.text() == "Resume"
    frozen = scope.traces["force"][0].getData()[1].copy()
    end = scope.buffer.end
    wait_until(qapp, lambda: scope.buffer.end > end + 500, 5)
    np.testing.assert_array_equal(scope.traces["force"][0].getData()[1], frozen)
    scope.freeze_button.click()
    assert not scope.frozen
    wait_until(qapp, lambda: not np.array_equal(scope.traces["force"][0].getData()[1], frozen), 5)
    # window 0.1 .. 5 s
    assert scope.seconds.minimum() == pytest.approx(0.1) and scope.seconds.maximum() == pytest.approx(5.0)
    # save to PNG
    path = scope.save_png(tmp_path / "scope.png")
    from PySide6.QtGui import QImage

    image = QImage(str(path))
    assert not image.isNull() and image.width() > 300 and image.height() > 200
    console.set_bowing(False)


def test_emergency_stop_zeroes_force(idle_console, qapp):
    console = idle_console
    c = console.controller
    bow_preview(console, qapp)
    assert np.max(np.abs(telemetry_after(console, qapp, 0.3)["force"])) > 0.3
    engine = c.host.engine
    pressed_at = engine.ring.committed  # samples written before the click
    console.stop_button.click()
    assert c.emergency and console.state_label.text().startswith("Emergency stop (operator): force off")
    assert engine.force_output == 0.0
    wait_until(qapp, lambda: engine.status()["fault_latched"], 2)
    assert engine.status()["force_scale"] == 0.0
    wait_until(qapp, lambda: engine.status()["fmax"] == 0.0, 2)  # the F_max command follows the shared word
    # from here on the device gets no force at all, whatever the participant does
    console.knobs.dials[0].setValue(100)  # refused: the knobs are disabled and the controller ignores them
    assert not console.knobs.isEnabled()
    telemetry_after(console, qapp, 0.4)
    # the worker reads the force-enable word after each block and latches: from the first block it
    # runs latched (force scale 0) every sample has no force. On a loaded machine the GUI thread may
    # handle the click some blocks after ``pressed_at`` was read, so the bound is in time, not blocks.
    after = engine.telemetry(since=pressed_at)
    assert after["end"] - after["start"] > 1000
    # (a block's row carries the scale set after it ran, so the latching block itself may have force)
    block = engine.info["block"]
    latched = np.flatnonzero(after["force_scale"] == 0.0)[0]
    assert latched < 0.1 * engine.config.rate
    assert np.all(after["force"][latched + block:] == 0.0)
    assert engine.status()["fmax"] == 0.0
    assert console.pause_button.text() == "Resume" and not console.start_button.isEnabled()
    # the experimenter clears it: force may flow again (still F_max 0 until someone turns it up)
    console.pause_button.click()
    wait_until(qapp, lambda: c.state in ("idle", "finished", "aborted"), 5)
    assert not engine.status()["fault_latched"] and engine.status_block.force_enable
    bow_preview(console, qapp)
    assert np.max(np.abs(telemetry_after(console, qapp, 0.3)["force"])) > 0.3
    console.set_bowing(False)


def test_escape_is_the_emergency_stop_in_every_window(idle_console, qapp, qtbot):
    from PySide6.QtCore import Qt

    console = idle_console
    c = console.controller
    for window in (console, console.participant_window):
        window.show()
        window.activateWindow()
        qtbot.keyClick(window, Qt.Key.Key_Escape)
        assert c.emergency
        assert c.engine.status_block.force_enable is False
        c.clear_emergency()
        wait_until(qapp, lambda: c.state in ("idle", "finished", "aborted"), 5)
    console.participant_window.hide()
