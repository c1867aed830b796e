"""MIDI: the LPD8 factory map, protocol maps, learn mode, knob scales, polling rtmidi's queue, and the
one-line fallback without a back-end. Messages come from mido fake ports (mido.ports.BaseInput)."""

import os
import time

import mido
import numpy as np
import pytest

from studyapp.engine import commands
from studyapp.engine.midi import ControlMap, MidiInput, arrival_times, coalesce, open_input
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
    (fmax,) = made(actions["knob1"], 100 / 127, sent=1.0)
    assert type(fmax) is commands.SetFmax and fmax.sent == 1.0
    assert fmax.newtons == pytest.approx(fmax_from_knob(100, *LIVE_RANGE))
    assert made(actions["pad2"], 1.0, 2.0) == (commands.SetSource("LOWPASS", sent=2.0),)
    assert made(actions["pad2"], 0.0, 2.0) == ()  # releasing a pad does nothing
    # the volume knob on the console's law, dB-linear from -40 dB to 0 dB: halfway is -20 dB
    (volume,) = made(actions["knob2"], 0.5, 2.0)
    assert type(volume) is commands.SetVolume and volume.sent == 2.0 and volume.gain == pytest.approx(0.1)
    # a rating knob selects its condition whatever its position, even at the bottom, at the task's F_max
    assert made(("select", "LVT", 1.0), 0.0, 3.0) == (commands.SetSource("LVT", sent=3.0),
                                                      commands.SetFmax(1.0, sent=3.0))
    assert "pad4" not in actions


class FakeRtMidiIn:
    """python-rtmidi's ``MidiIn`` polled without a callback: ``get_message()`` -> ([bytes], delta time) or None."""

    def __init__(self, messages):
        self.messages = list(messages)

    def get_message(self):
        return self.messages.pop(0) if self.messages else None


def test_arrival_times_go_back_from_the_poll_by_the_delta_times_and_never_before_the_previous_poll():
    rng = np.random.default_rng(14)
    deltas = rng.exponential(0.0004, 50)
    polled, previous = 100.0, 100.0 - 0.002
    got = np.array(arrival_times(list(deltas), polled, previous))
    # closed form: the last at the poll, each earlier one by the sum of the delta times after it
    after = np.concatenate([np.cumsum(deltas[::-1])[::-1][1:], [0.0]])
    np.testing.assert_allclose(got, np.maximum(polled - after, previous), rtol=0, atol=1e-12)
    assert (got >= previous).all() and got[-1] == polled and (np.diff(got) >= 0).all()
    assert arrival_times([0.0, 0.001, 0.002, 0.0005], 10.0, 9.0) == pytest.approx([9.9965, 9.9975, 9.9995, 10.0])
    assert arrival_times([], 10.0, 9.0) == []


def test_the_engine_polls_rtmidis_queue_in_order_with_arrival_times_and_blocks():
    sent = [[0xB0, 1, v] for v in range(100)]
    midi = MidiInput("fake", "UNIX_JACK", rt=FakeRtMidiIn([(m, 0.0) for m in sent[:-2]]))
    midi.new_block(5, time.monotonic())
    before = time.monotonic()
    got = midi.poll()
    assert [m for m, _, _ in got] == sent[:-2]
    assert before <= got[-1][1] <= time.monotonic()  # the last is anchored at the poll
    assert {b for _, _, b in got} == {5}  # all arrived after block 5 began
    assert midi.received == 98 and midi.poll() == []
    # a long delta puts the earlier message before the block began, but never before the previous poll
    midi._rt.messages = [(sent[-2], 0.0), (sent[-1], 10.0)]
    polled_before = midi._polled
    midi.new_block(6, time.monotonic())
    (first, t1, b1), (last, t2, b2) = midi.poll()
    assert (first, last) == (sent[-2], sent[-1])
    assert t1 == polled_before and (b1, b2) == (5, 6) and t2 > t1
    assert midi.received == 100 and midi.overflows == 0


def test_a_poll_that_finds_rtmidis_queue_full_counts_an_overflow():
    midi = MidiInput("fake", "UNIX_JACK", rt=FakeRtMidiIn([([0xB0, 1, v], 0.0) for v in range(8)]), queue_size=8)
    assert len(midi.poll()) == 8 and midi.overflows == 1
    midi._rt.messages = [([0xB0, 1, v], 0.0) for v in range(7)]
    assert len(midi.poll()) == 7 and midi.overflows == 1
    assert MidiInput("closed", "UNIX_JACK").poll() == []


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


def test_raw_bytes_resynchronise_after_an_unterminated_or_cut_message():
    # issue 33, item 4: the next status byte ends an unterminated SysEx, and what follows it counts
    from studyapp.engine.midi_bytes import split

    held = [0xF0, 0x7E, 0x01, 0xB0, 1, 20, 0xF8, 0xB0, 1, 30, 0xF7]  # what rtmidi's JACK input hands over
    assert split(held) == [[0xB0, 1, 20], [0xF8], [0xB0, 1, 30]]
    assert split([0xF0, 1, 2, 0xF7, 0x90, 60, 0xC0, 5, 0xB0, 1, 2, 3, 4, 0xF4, 7, 0xF7]) == [
        [0xF0, 1, 2, 0xF7], [0xC0, 5], [0xB0, 1, 2], [0xB0, 3, 4]]  # a note cut short, running status, junk
    got = coalesce([(held, 1.0, 3)])
    assert [(m.type, m.value) for m, _, _ in got if m.type == "control_change"] == [("control_change", 30)]


def test_an_engines_own_sysex_end_port_is_never_taken_for_a_controller():
    from studyapp.engine.midi import FLUSH_PORT, match_port

    names = [f"studyapp-12:{FLUSH_PORT}", "LPD8:out"]
    assert match_port("first", names) == "LPD8:out" and match_port("studyapp", names) is None
