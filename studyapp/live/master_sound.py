"""The experimenter's master volume and mute for a session: what the console's sound controls hold.

They send the engine's existing commands (``SetVolume`` with a linear gain,
``SetMute``; engine/audio/sinks.py applies them, ramped, before the rest of the
audio chain), so this adds no second volume stage. The console sets the
volume in decibels, -40 to 0 dB (gain 10^(dB/20), 0.01 to 1): an
attenuator, never louder than the chain's own full level. The preview's
volume knob (knob 2) has the same law (model/controls.py ``Volume``); the
worker applies it, and what it applied becomes this setting (``adopt``), so
the console shows it and every engine that comes up gets it: the volume has
one record, whichever control set it last. "Last" is the worker's order: a
knob's report that comes back after the console sent its own volume, for a
message that arrived before, is stale (the worker applied the console's
after it) and is not adopted. The setting
belongs to the console, not to an engine: every engine that comes up (a
session's, a restarted one, the preview after it) gets it again
(``commands``). During a session every change is logged as an event,
``{"type": "volume", "db": ..., "gain": ...}`` or ``{"type": "mute", "on": ...}``.
"""

import math

from studyapp.engine import commands as cmd
from studyapp.errors import UserError
from studyapp.experiment import records
from studyapp.model.controls import VOLUME_DB, Volume


class MasterSound:
    def __init__(self):
        self.db = 0.0
        self.muted = False
        self.sent = -math.inf  # when the console's volume last went to an engine (time.monotonic)

    @property
    def gain(self):
        return 10.0 ** (self.db / 20.0)

    def set_db(self, db):
        """Set the volume (dB, in ``VOLUME_DB``); returns the event to log."""
        low, high = VOLUME_DB
        if not (isinstance(db, (int, float)) and math.isfinite(db) and low <= db <= high):
            raise UserError(f"volume {db!r} dB: allowed is {low:g} to {high:g} dB")
        self.db = float(db)
        return records.volume(self.db, self.gain)

    def adopt(self, gain, arrived):
        """The worker applied a volume knob's ``gain``, the knob's message having ``arrived`` (monotonic s):
        the setting now, and the event to log; None when the console's own setting went out after that
        message (the worker applied it later, so it holds)."""
        if arrived < self.sent:
            return None
        self.db = Volume.db(Volume.value_of_gain(gain))
        return records.volume(self.db, self.gain)

    def set_muted(self, on):
        self.muted = bool(on)
        return records.mute(self.muted)

    def commands(self):
        """The commands that give an engine this setting (``sent``: when the volume went out)."""
        volume = cmd.SetVolume(self.gain)
        self.sent = volume.sent
        return volume, cmd.SetMute(self.muted)
