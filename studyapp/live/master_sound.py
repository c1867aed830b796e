"""The experimenter's master volume and mute for a session: what the console's sound controls hold.

They send the engine's existing commands (``SetVolume`` with a linear gain,
``SetMute``; engine/audio/sinks.py applies them, ramped, before the rest of the
audio chain), so this adds no second volume stage. The console sets the
volume in decibels, -40 to 0 dB (gain 10^(dB/20), 0.01 to 1): an
attenuator, never louder than the chain's own full level. The setting
belongs to the console, not to an engine: every engine that comes up (a
session's, a restarted one, the preview after it) gets it again
(``commands``). During a session every change is logged as an event,
``{"type": "volume", "db": ..., "gain": ...}`` or ``{"type": "mute", "on": ...}``.
"""

import math

from studyapp.engine import commands as cmd
from studyapp.errors import UserError
from studyapp.experiment import records

DB_RANGE = (-40.0, 0.0)


class MasterSound:
    def __init__(self):
        self.db = 0.0
        self.muted = False

    @property
    def gain(self):
        return 10.0 ** (self.db / 20.0)

    def set_db(self, db):
        """Set the volume (dB, in ``DB_RANGE``); returns the event to log."""
        low, high = DB_RANGE
        if not (isinstance(db, (int, float)) and math.isfinite(db) and low <= db <= high):
            raise UserError(f"volume {db!r} dB: allowed is {low:g} to {high:g} dB")
        self.db = float(db)
        return records.volume(self.db, self.gain)

    def set_muted(self, on):
        self.muted = bool(on)
        return records.mute(self.muted)

    def commands(self):
        """The commands that give an engine this setting."""
        return cmd.SetVolume(self.gain), cmd.SetMute(self.muted)
