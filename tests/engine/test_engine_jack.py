"""The engine on a real (dummy-driver) JACK server: PortAudio output paced by JACK's clock, and
JACK MIDI control changes from a second process."""

import subprocess
import sys
import textwrap
import time

import numpy as np
import pytest

from studyapp.engine import commands as cmd
from studyapp.model.fmax_knob import LIVE_RANGE, fmax_from_knob
from studyapp.engine.config import EngineConfig
from studyapp.engine.engine import Engine

pytestmark = pytest.mark.jack

RATE = 5000.0


@pytest.mark.alone  # another real-time engine on the same two cores wakes this one late (1 underrun in 10 s)
def test_ten_seconds_of_audio_at_48_khz_from_a_5_khz_loop_without_underruns(jack_server):
    config = EngineConfig(rate=RATE, source="LVT", fmax=1.0, audio="device")
    engine = Engine(config).start()
    try:
        assert engine.info["paced"] == "audio"
        assert "JACK" in engine.info["audio"] and "48000 Hz" in engine.info["audio"]
        time.sleep(10.0)
        snap = engine.status()
        assert snap["audio_paced"]
    finally:
        summary = engine.stop()
    assert summary["seconds"] >= 10.0
    assert summary["audio_underruns"] == 0
    assert summary["audio_xruns"] == 0
    assert summary["deadline_misses"] == 0
    # paced by the device: the loop ran at its rate as measured on the audio clock
    assert summary["achieved_rate"] == pytest.approx(RATE, rel=0.02)
    assert summary["audio_frames"] >= 10.0 * 48000 * 0.98
    assert summary["faults"] == []


SENDER = textwrap.dedent("""
    import sys, time
    import rtmidi
    out = rtmidi.MidiOut(rtmidi.API_UNIX_JACK, "knob-box")
    ports = out.get_ports()
    port = [i for i, name in enumerate(ports) if "studyapp MIDI in" in name]
    if not port:
        sys.exit("no studyapp port among " + repr(ports))
    out.open_port(port[0])
    time.sleep(0.2)
    for value in sys.argv[1:]:   # a pause between messages: each reaches its own block
        out.send_message([0xB0, 1, int(value)])   # control change 1 (knob 1), channel 1
        time.sleep(0.15)
    time.sleep(0.15)
    out.close_port()
    out.delete()
""")


def test_a_control_change_from_another_process_sets_fmax_within_one_block(jack_server):
    config = EngineConfig(rate=RATE, source="LVT", fmax=0.0, midi="virtual")
    engine = Engine(config).start()
    try:
        assert "JACK" in engine.info["midi"]
        block = engine.info["block"]
        # the knob is first seen at 0, the level in force: picked up at once (engine/pickup.py)
        sender = subprocess.run([sys.executable, "-c", SENDER, "0", "100"], capture_output=True, text=True,
                                timeout=60)
        assert sender.returncode == 0, sender.stderr
        controls = wait_for_controls(engine, 2)
        assert [c.pending_pickup for c in controls] == [False, False]
        applied = controls[1]
        expected = fmax_from_knob(100, *LIVE_RANGE)
        assert applied.control == "knob1" and applied.value == pytest.approx(100 / 127)
        assert applied.origin == "midi" and applied.blocks_late <= 1
        assert 0 < applied.latency < 1.0  # from the message's arrival to a later block start, well within the wait
        time.sleep(0.05)
        assert engine.status()["fmax"] == pytest.approx(expected)
        assert engine.status()["midi_messages"] == 2
        # the telemetry agrees: F_max changed exactly at the start of the block that applied it
        tel = engine.telemetry(since=0)
        change = np.flatnonzero(np.diff(tel["fmax"])) + 1
        assert len(change) == 1
        assert tel["start"] + change[0] == applied.block * block
        assert tel["fmax"][change[0]] == pytest.approx(expected)
    finally:
        summary = engine.stop()
    assert summary["midi_messages"] == 2 and summary["midi_overflows"] == 0


def wait_for_controls(engine, n, timeout=5.0):
    controls = []
    end = time.monotonic() + timeout
    while len(controls) < n and time.monotonic() < end:
        controls += engine.controls()
        time.sleep(0.01)
    assert len(controls) == n, f"{len(controls)} of {n} control events reached the engine"
    return controls


def test_a_knob_left_high_at_a_trial_start_raises_fmax_only_once_turned_down_through_zero(jack_server):
    ceiling, decades = 40.0, 2.0
    config = EngineConfig(rate=RATE, source="LVT", fmax=0.0, midi="virtual")
    engine = Engine(config).start()
    try:
        # the previous trial left the knob at 100 and F_max there
        engine.send(cmd.InstallActions({"knob1": ("fmax_log", ceiling, decades)}, trial=1))
        engine.send(cmd.SetFmax(fmax_from_knob(100, ceiling, decades)))
        sender = subprocess.run([sys.executable, "-c", SENDER, "100"], capture_output=True, text=True, timeout=60)
        assert sender.returncode == 0, sender.stderr
        assert not wait_for_controls(engine, 1)[0].pending_pickup
        # a new trial: F_max 0, its mapping; the knob, still high, is turned down, through 0, then up
        engine.send(cmd.SetFmax(0.0))
        engine.send(cmd.InstallActions({"knob1": ("fmax_log", ceiling, decades)}, trial=2))
        sender = subprocess.run([sys.executable, "-c", SENDER, "101", "60", "0", "50"], capture_output=True,
                                text=True, timeout=60)
        assert sender.returncode == 0, sender.stderr
        controls = wait_for_controls(engine, 4)
        assert [round(c.value * 127) for c in controls] == [101, 60, 0, 50]
        assert [c.pending_pickup for c in controls] == [True, True, False, False]
        assert [c.pickup_target for c in controls] == [0.0, 0.0, None, None]
        assert [len(c.commands) for c in controls] == [0, 0, 1, 1] and {c.trial for c in controls} == {2}
        time.sleep(0.05)
        assert engine.status()["fmax"] == pytest.approx(fmax_from_knob(50, ceiling, decades))
        # the telemetry of trial 2: F_max held at 0 until the knob's message at 50, never above
        tel = engine.telemetry(since=0)
        fmax = tel["fmax"][tel["trial"] == 2]
        first = int(np.argmax(fmax > 0))
        assert (fmax[:first] == 0).all() and fmax[first:] == pytest.approx(fmax_from_knob(50, ceiling, decades))
        assert tel["start"] + int(np.flatnonzero(tel["trial"] == 2)[first]) == controls[3].block * engine.info["block"]
    finally:
        engine.stop()


SYSEX_THEN_KNOB = SENDER.replace("    for value in sys.argv[1:]:",
                                 "    out.send_message([0xF0, 0x7E, 0x01])   # a SysEx never terminated\n"
                                 "    time.sleep(0.15)\n"
                                 "    for value in sys.argv[1:]:")


def test_an_unterminated_sysex_does_not_silence_midi(jack_server):
    # issue 33, item 4: on main one F0 7E 01 silenced MIDI for good (rtmidi's JACK input held every later
    # event as part of that SysEx, and SysEx was ignored): knob 1 no longer moved F_max, without a notice
    engine = Engine(EngineConfig(rate=RATE, source="LVT", fmax=0.0, midi="virtual")).start()
    try:
        sender = subprocess.run([sys.executable, "-c", SYSEX_THEN_KNOB, "0", "100"], capture_output=True, text=True,
                                timeout=60)
        assert sender.returncode == 0, sender.stderr
        controls = wait_for_controls(engine, 2)
        assert [c.value for c in controls] == [0.0, pytest.approx(100 / 127)]
        time.sleep(0.05)
        assert engine.status()["fmax"] == pytest.approx(fmax_from_knob(100, *LIVE_RANGE))
    finally:
        engine.stop()


def test_a_control_value_that_is_not_a_number_in_range_is_refused_with_a_notice():
    # issue 33, item 4: on main Control("knob1", inf) killed the worker with an OverflowError
    notices = []
    engine = Engine(EngineConfig(rate=RATE, source="LVT", fmax=1.0, midi="none"),
                    on_notice=notices.append).start()
    try:
        for value in (float("inf"), float("nan"), -1.0, 2.0, "x"):
            engine.send(cmd.Control("knob1", value))
        engine.send(cmd.Control("knob1", 0.5))
        controls = wait_for_controls(engine, 1)
        assert controls[0].value == 0.5 and engine.alive
        assert sum("ignored: allowed is a control name and a value from 0 to 1" in n.text for n in notices) == 5
    finally:
        engine.stop()
