"""MIDI: the LPD8 factory map, protocol maps, learn mode, knob scales, the callback queue, and the
one-line fallback without a back-end. Messages come from mido fake ports (mido.ports.BaseInput)."""

import os
import threading

import mido
import pytest

from studyapp.engine import commands
from studyapp.engine.midi import ControlMap, MidiInput, coalesce, open_input
from studyapp.errors import ParameterError
from studyapp.model.fmax_knob import LIVE_RANGE, fmax_from_knob


class FakeInput(mido.ports.BaseInput):
    """A mido input port that yields scripted messages (mido's own pattern for back-end-free tests)."""

    def __init__(self, messages):
        self._script = list(messages)
        super().__init__("fake")

    def _receive(self, block=True):
        if self._script:
            self._messages.append(self._script.pop(0))


def _mapped(cmap, messages):
    port = FakeInput(messages)
    return [cmap.lookup(m) for m in port.iter_pending()]


def test_lpd8_factory_map_knobs_cc_1_to_8_and_pads_notes_36_to_43_on_channel_1():
    cmap = ControlMap.lpd8()
    knobs = [mido.Message("control_change", channel=0, control=i, value=127 * (i % 2)) for i in range(1, 9)]
    pads = [mido.Message("note_on", channel=0, note=n, velocity=90) for n in range(36, 44)]
    got = _mapped(cmap, knobs + pads)
    assert got[:8] == [(f"knob{i}", float(i % 2)) for i in range(1, 9)]
    assert got[8:] == [(f"pad{i}", 1.0) for i in range(1, 9)]
    assert _mapped(cmap, [
        mido.Message("control_change", channel=0, control=1, value=64),
        mido.Message("note_off", channel=0, note=36),
        mido.Message("note_on", channel=0, note=37, velocity=0),
        mido.Message("control_change", channel=1, control=1, value=64),  # channel 2: not the LPD8's
        mido.Message("control_change", channel=0, control=9, value=64),
        mido.Message("pitchwheel", channel=0, pitch=100),
    ]) == [("knob1", 64 / 127), ("pad1", 0.0), ("pad2", 0.0), None, None, None]


def test_a_protocol_map_replaces_the_factory_one():
    cmap = ControlMap.from_protocol({"rating": {"cc": 7, "channel": 2}, "next": {"note": 60}})
    assert _mapped(cmap, [
        mido.Message("control_change", channel=1, control=7, value=127),
        mido.Message("note_on", channel=0, note=60, velocity=1),
        mido.Message("control_change", channel=0, control=1, value=5),
    ]) == [("rating", 1.0), ("next", 1.0), None]
    assert cmap.to_dict() == {"rating": {"cc": 7, "channel": 2}, "next": {"note": 60, "channel": 1}}


@pytest.mark.parametrize("mapping, field", [
    ({"a": {"cc": 200}}, "0..127"), ({"a": {"cc": 1, "channel": 0}}, "1..16"),
    ({"a": {"cc": 1, "note": 2}}, "exactly one"), ({"a": {"cc": 1, "chan": 1}}, "chan"), ([1], "table"),
])
def test_bad_protocol_maps_name_the_problem(mapping, field):
    with pytest.raises(ParameterError, match=field):
        ControlMap.from_protocol(mapping)


def test_learn_mode_binds_the_next_control_that_moves():
    cmap = ControlMap.lpd8()
    cmap.learn("knob1")
    assert cmap.lookup(mido.Message("pitchwheel", pitch=5)) is None  # not a control: keeps learning
    assert cmap.learning == "knob1"
    assert cmap.lookup(mido.Message("control_change", channel=3, control=20, value=127)) == ("knob1", 1.0)
    assert cmap.learning is None
    assert cmap.to_dict()["knob1"] == {"cc": 20, "channel": 4}
    assert cmap.lookup(mido.Message("control_change", channel=0, control=1, value=127)) is None  # old binding gone
    cmap.learn("knob2")
    cmap.lookup(mido.Message("note_on", channel=0, note=36, velocity=9))  # steals pad1's note
    assert "pad1" not in cmap.to_dict() and cmap.to_dict()["knob2"] == {"note": 36, "channel": 1}


def test_knob_one_uses_the_one_knob_law_over_the_live_range():
    actions = commands.default_actions(["LVT"])
    for step in (0, 1, 64, 127):
        value = commands.action_commands(actions["knob1"], step / 127, sent=0.0)[0].newtons
        assert value == pytest.approx(fmax_from_knob(step, *LIVE_RANGE))
    assert commands.action_commands(actions["knob1"], 1 / 127, 0.0)[0].newtons == pytest.approx(0.1)
    assert commands.action_commands(actions["knob1"], 1.0, 0.0)[0].newtons == pytest.approx(20.0)


def test_default_actions_drive_the_engine_commands():
    actions = commands.default_actions(["KALLEV", "LOWPASS", "LVT"])
    made = commands.action_commands
    assert made(actions["knob1"], 100 / 127, sent=1.0) == (
        commands.SetFmax(pytest.approx(fmax_from_knob(100, *LIVE_RANGE)), sent=1.0),)
    assert made(actions["pad2"], 1.0, 2.0) == (commands.SetSource("LOWPASS", sent=2.0),)
    assert made(actions["pad2"], 0.0, 2.0) == ()  # releasing a pad does nothing
    assert made(actions["knob2"], 0.5, 2.0) == (commands.SetVolume(0.5, sent=2.0),)
    # a rating knob selects its condition whatever its position, even at the bottom, at the task's F_max
    assert made(("select", "LVT", 1.0), 0.0, 3.0) == (commands.SetSource("LVT", sent=3.0),
                                                      commands.SetFmax(1.0, sent=3.0))
    assert "pad4" not in actions


def test_the_callback_only_queues_raw_bytes_and_the_engine_drains_in_order():
    midi = MidiInput("fake", "UNIX_JACK")
    sent = [[0xB0, 1, v] for v in range(100)]

    def rtmidi_thread():  # python-rtmidi calls back with ([bytes], delta time) and the user data
        for i, m in enumerate(sent):
            midi.block = i // 10
            midi._callback((m, 0.001), None)

    thread = threading.Thread(target=rtmidi_thread)
    thread.start()
    thread.join(5)
    got = midi.poll()
    assert [m for m, _, _ in got] == sent
    assert [b for _, _, b in got] == [i // 10 for i in range(100)]
    times = [t for _, t, _ in got]
    assert times == sorted(times)
    assert midi.received == 100 and midi.poll() == []


def test_a_block_keeps_only_the_last_value_of_each_controller_and_every_note():
    cc = lambda channel, number, value: [0xB0 | channel, number, value]  # noqa: E731
    note_on = lambda note: [0x90, note, 100]  # noqa: E731
    received = [
        (cc(0, 1, 10), 1.0, 7), (cc(0, 2, 5), 1.1, 7), (note_on(36), 1.2, 7), (cc(0, 1, 20), 1.3, 7),
        (cc(1, 1, 99), 1.4, 7),  # the same number on channel 2 is another controller
        (note_on(36), 1.5, 8), (cc(0, 2, 6), 1.6, 8), (cc(0, 1, 30), 1.7, 8), ([0xF8], 1.8, 8), ([0xB0], 1.9, 8),
    ]
    got = coalesce(received)
    expected = [
        (mido.Message("control_change", channel=0, control=1, value=30), 1.7, 8),  # where knob 1 first moved
        (mido.Message("control_change", channel=0, control=2, value=6), 1.6, 8),
        (mido.Message("note_on", channel=0, note=36, velocity=100), 1.2, 7),
        (mido.Message("control_change", channel=1, control=1, value=99), 1.4, 7),
        (mido.Message("note_on", channel=0, note=36, velocity=100), 1.5, 8),  # both presses kept
        (mido.Message("clock"), 1.8, 8),
    ]  # the torn [0xB0] is left out
    assert got == expected
    assert coalesce([]) == []


def test_without_a_backend_one_line_says_so_and_nothing_leaks_to_stderr(capfd, monkeypatch):
    # a JACK server name nobody runs, and no ALSA sequencer on these machines
    monkeypatch.setenv("JACK_DEFAULT_SERVER", f"nobody-{os.getpid()}")
    monkeypatch.setenv("JACK_NO_START_SERVER", "1")
    if os.path.exists("/dev/snd/seq"):
        pytest.skip("this machine has an ALSA sequencer")
    lines = []
    assert open_input("virtual", say=lines.append) is None
    assert len(lines) == 1
    assert lines[0].startswith("MIDI: no input opened") and "JACK" in lines[0] and "ALSA" in lines[0]
    assert "on-screen knobs" in lines[0]
    assert capfd.readouterr().err == ""
    assert open_input("none", say=lines.append) is None and len(lines) == 1
