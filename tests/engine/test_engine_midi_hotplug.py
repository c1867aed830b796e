"""MIDI hot-plug (issue 15, item 4) on a real (dummy-driver) JACK server: an engine started with
``--midi first`` and no controller waits for one; a port that appears afterwards is connected within
the rescan period and its control changes arrive; one that goes away is reported and waited for again.
Also the parsing of ``jack_lsp -p -t``."""

import time

import pytest

from studyapp.engine.config import EngineConfig
from studyapp.engine.engine import Engine
from studyapp.engine.midi import RESCAN
from tests.engine.waiting import wait_for

pytestmark = [pytest.mark.jack, pytest.mark.alone]  # a real-time guarantee: a loaded machine delays the reader

RATE = 5000.0


def virtual_controller(name):
    import rtmidi

    out = rtmidi.MidiOut(rtmidi.API_UNIX_JACK, name)
    out.open_virtual_port("knobs")
    return out


def test_a_controller_plugged_in_after_the_start_is_picked_up_and_its_knobs_act(jack_server):
    notices = []
    engine = Engine(EngineConfig(rate=RATE, source="LVT", fmax=0.0, midi="first"), on_notice=notices.append).start()
    out = None
    try:
        assert engine.info["midi"].startswith("none yet (JACK)") and f"within {RESCAN:g} s" in engine.info["midi"]
        out = virtual_controller("hotplug-box")
        plugged = time.monotonic()
        wait_for(lambda: "hotplug-box:knobs" in engine.status()["midi"], timeout=RESCAN + 3.0)
        assert time.monotonic() - plugged < RESCAN + 1.0  # picked up within one rescan period (and a margin)
        assert engine.status()["midi"] == "hotplug-box:knobs (JACK)"
        wait_for(lambda: any("hotplug-box:knobs plugged in" in n.text for n in notices), timeout=2.0)
        for value in (0, 100):  # knob 1: seen at 0 (the level in force, picked up at once), then turned up
            out.send_message([0xB0, 1, value])
            time.sleep(0.15)
        controls = []
        wait_for(lambda: controls.extend(engine.controls()) or len(controls) >= 2, timeout=5.0)
        assert [(c.control, round(127 * c.value), c.origin) for c in controls] == [("knob1", 0, "midi"),
                                                                                 ("knob1", 100, "midi")]
        wait_for(lambda: engine.status()["fmax"] > 0.0, timeout=2.0)
        # unplugged: let go, and waited for again
        out.close_port()
        wait_for(lambda: engine.status()["midi"].startswith("none yet"), timeout=RESCAN + 3.0)
        wait_for(lambda: any("hotplug-box:knobs was unplugged" in n.text for n in notices), timeout=2.0)
    finally:
        if out is not None:
            out.delete()
        summary = engine.stop()
    assert summary["midi_messages"] == 2 and summary["faults"] == []


JACK_LSP = """system:capture_1
\tproperties: output,physical,terminal,
\t32 bit float mono audio
system:playback_1
\tproperties: input,physical,terminal,
\t32 bit float mono audio
box:knobs
\tproperties: output,
\t8 bit raw midi
studyapp-7:studyapp MIDI in
\tproperties: input,
\t8 bit raw midi
"""


def test_only_midi_output_ports_count_as_controllers(monkeypatch):
    import subprocess

    from studyapp.engine import midi_hotplug

    monkeypatch.setattr(subprocess, "run", lambda *a, **k: subprocess.CompletedProcess(a, 0, JACK_LSP, ""))
    assert midi_hotplug.midi_outputs() == ["box:knobs"]
