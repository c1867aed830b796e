"""Issue 22 item 16: the console's notes and master volume/mute, through the controller (fake engine)."""

import pytest

from studyapp.engine import commands as cmd
from studyapp.errors import UserError
from tests.like import Like
from tests.live.test_session_controller import S, controller, log, play_rating, reach, start, up  # noqa: F401


def test_notes_during_and_after_a_session_are_logged_with_the_step(controller):
    c = controller
    with pytest.raises(UserError, match="no session to add a note to"):
        c.add_note("before any session")
    start(c)
    up(c)
    record = c.add_note("participant asked about the knobs")
    assert record["wall"] and record["step"] == c.runner.trial.step
    play_rating(c)
    c.abort()
    c.add_note("aborted: the participant felt unwell")  # after the session, in its log
    notes = [e for e in log(c) if e["type"] == "note"]
    assert [n["text"] for n in notes] == ["participant asked about the knobs", "aborted: the participant felt unwell"]
    assert notes[0]["task"] == "rating" and "step" not in notes[1]
    with pytest.raises(UserError, match="empty"):
        c.add_note("  ")


def test_volume_and_mute_send_the_engines_commands_are_logged_and_survive_a_new_engine(controller):
    c = controller
    c.set_volume(-6.0)
    sent = c.host.engine.sent
    assert sent[-2] == Like(cmd.SetVolume, gain=pytest.approx(10 ** (-6 / 20))) and sent[-1] == cmd.SetMute(False)
    start(c)  # a new engine for the session: it gets the console's volume as it comes up
    up(c)
    engine = c.host.engine
    assert Like(cmd.SetVolume, gain=pytest.approx(10 ** (-6 / 20))) in engine.sent
    c.set_mute(True)
    c.set_volume(-20.0)
    assert engine.sent[-1] == cmd.SetMute(True) and engine.sent[-2] == Like(cmd.SetVolume, gain=pytest.approx(0.1))
    events = [e for e in log(c) if e["type"] in ("mute", "volume")]
    assert [(e["type"], e.get("on"), e.get("db")) for e in events] == [("mute", True, None), ("volume", None, -20.0)]
    assert events[1]["gain"] == pytest.approx(0.1) and all(e["step"] == c.runner.trial.step for e in events)
    for bad in (3.0, -41.0, float("nan")):
        with pytest.raises(UserError, match="allowed is -40 to 0 dB"):
            c.set_volume(bad)


def test_the_preview_volume_knob_sets_the_one_master_volume_the_console_shows_and_a_new_engine_gets(controller):
    c = controller
    shown = []
    c.events.volume.connect(lambda db: shown.append(db))
    c.set_volume(-6.0)
    engine = c.host.engine
    before = len(engine.sent_of(cmd.SetVolume))
    engine.control("knob2", 64 / 127)  # the preview's volume knob, on MIDI: the worker applies it
    c.poll()
    db = -40.0 + 40.0 * 64 / 127  # the console's law: dB-linear from -40 to 0 dB
    assert c.sound.db == pytest.approx(db) and shown == [pytest.approx(db)]
    assert len(engine.sent_of(cmd.SetVolume)) == before + 1  # the worker's own; the parent sends nothing back
    engine.control("knob2", 0.0)
    c.poll()
    assert c.sound.db == -40.0 and c.sound.gain == pytest.approx(0.01)  # the bottom: -40 dB, not silence
    start(c)  # a new engine for the session gets the volume the knob set last
    up(c)
    assert c.host.engine.sent_of(cmd.SetVolume)[0] == Like(cmd.SetVolume, gain=pytest.approx(0.01))


def test_a_volume_knobs_late_report_does_not_undo_the_consoles_later_volume(controller):
    """The worker applied knob 2, then the console's -12 dB: the knob's report, read after, is stale."""
    c = controller
    engine = c.host.engine
    engine.control("knob2", 90 / 127)  # applied by the worker; its report waits ...
    c.set_volume(-12.0)  # ... while the console's volume goes out, and is applied after it
    c.poll()
    assert c.sound.db == -12.0
    assert engine.sent_of(cmd.SetVolume)[-1] == Like(cmd.SetVolume, gain=pytest.approx(10 ** -0.6))
    engine.control("knob2", 90 / 127)  # a turn after it: the knob's level holds now
    c.poll()
    assert c.sound.db == pytest.approx(-40.0 + 40.0 * 90 / 127)
