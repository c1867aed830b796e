"""A MIDI flood through the real path (a second process -> JACK MIDI -> the worker -> the parent), issue 14
item 6: control changes are coalesced per block and none is lost; events the ring overwrites are counted."""

import json
import subprocess
import sys
import textwrap
import time
from collections import Counter

import pytest

from studyapp.engine.config import EngineConfig
from studyapp.engine.engine import Engine
from studyapp.engine.event_ring import SLOTS
from studyapp.engine.midi_flood import KNOBS, SENDER
from studyapp.model.fmax_knob import LIVE_RANGE, fmax_from_knob

pytestmark = [pytest.mark.jack, pytest.mark.alone]  # a real-time guarantee: a loaded machine delays the reader

RATE = 5000.0
FLOOD_RATE = 10_000.0  # control changes per second, the flood
FLOOD_SECONDS = 0.3


@pytest.fixture(scope="module")
def engine(jack_server):
    """One engine for both tests (starting one costs seconds); each test reads its own deltas."""
    engine = Engine(EngineConfig(rate=RATE, source="LVT", fmax=0.5, audio="null", midi="virtual")).start()
    yield engine
    engine.stop()


def _collect(engine, sender):
    controls = []
    while sender.poll() is None:
        controls += engine.controls()
        time.sleep(0.02)
    out, err = sender.communicate()
    assert sender.returncode == 0, err
    time.sleep(0.1)
    return controls + engine.controls(), out


def test_a_control_change_flood_is_coalesced_per_block_and_every_final_value_reaches_the_loop(engine):
    before = engine.status()
    sender = subprocess.Popen([sys.executable, "-c", SENDER, str(FLOOD_RATE), str(FLOOD_SECONDS), str(KNOBS)],
                              stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    controls, out = _collect(engine, sender)
    sent = json.loads(out)
    after = engine.status()
    assert after["midi_messages"] - before["midi_messages"] == sent["sent"] == int(FLOOD_RATE * FLOOD_SECONDS)
    assert after["events_dropped"] == before["events_dropped"] == 0
    # coalesced: at most one control event per knob per block
    per_block = Counter((c.control, c.block) for c in controls)
    assert max(per_block.values()) == 1
    assert len(controls) < sent["sent"]
    # no control lost: each knob's last event carries the last value sent on it, and the loop has it
    last = {c.control: c.value for c in controls}
    assert last == {f"knob{k}": value / 127 for k, value in ((int(k), v) for k, v in sent["final"].items())}
    assert after["fmax"] == pytest.approx(fmax_from_knob(sent["final"]["1"], *LIVE_RANGE))


PADS = textwrap.dedent("""
    import sys, time
    import rtmidi
    out = rtmidi.MidiOut(rtmidi.API_UNIX_JACK, "pad-box")
    port = [i for i, name in enumerate(out.get_ports()) if "studyapp MIDI in" in name]
    out.open_port(port[0])
    time.sleep(0.2)
    for i in range(int(sys.argv[1])):
        out.send_message([0x90, 36, 1 + i % 127])  # pad 1 pressed: every press is an event of its own
    time.sleep(0.3)
    out.close_port()
""")


def test_events_the_ring_overwrites_are_counted_as_dropped(engine):
    presses = 4 * SLOTS  # a burst the parent cannot read in time: many blocks' worth of events in one
    before = engine.status()
    sender = subprocess.Popen([sys.executable, "-c", PADS, str(presses)], stdout=subprocess.PIPE,
                              stderr=subprocess.PIPE, text=True)
    # the parent's event reader is held while the whole burst arrives (a parent a whole ring behind): the ring
    # must overwrite however fast the machine is (an idle reader kept up with the burst and dropped nothing)
    with engine._event_lock:
        _, err = sender.communicate(timeout=60)
        time.sleep(0.3)
    assert sender.returncode == 0, err
    controls = engine.controls()
    # on a loaded machine the worker may still be turning the burst's last messages into events: read until the
    # counts stop moving (at most 5 s), not after a fixed pause
    end, last = time.monotonic() + 5.0, None
    while True:
        after = engine.status()
        received = after["midi_messages"] - before["midi_messages"]
        dropped = after["events_dropped"] - before["events_dropped"]
        now = (received, dropped, len(controls))
        if now == last or time.monotonic() > end:
            break
        last = now
        time.sleep(0.2)
        controls += engine.controls()
    assert all(c.control == "pad1" for c in controls)
    assert received > SLOTS  # JACK may itself drop some of a burst: count what arrived
    # each press the worker received made one control event: those the parent missed are counted
    assert dropped > 0 and dropped + len(controls) == received
