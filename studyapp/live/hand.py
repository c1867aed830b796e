"""The virtual hand in a live session: the bow on or off the string, the hand's gesture, the mouse's bow pad. No Qt.

The hand moves the handle ``strokes`` (scripted), ``hold`` (held still) or
``live`` (following the participant's bowing surface, the mouse). During a
trial every change goes through the session runner, which logs it and traces
the hand (experiment/hand_trace.py) and passes it to the trial's loop; on a
page (no loop) the bow stays lifted. Outside a session it goes to the preview
engine (through the apparatus). Nothing acts while the participant's
controls do not (paused, emergency stop, no engine).
"""

from studyapp.engine import commands as cmd
from studyapp.errors import UserError
from studyapp.model.limits import CONSOLE_GESTURES


class Hand:
    def __init__(self, live):
        self.live = live  # the controller: whether controls act, the runner, the apparatus, events

    def set_bowing(self, on):
        """Put the bow on the string (True) or lift it (False), with the hand's current gesture."""
        live = self.live
        if not live.accepting:
            return
        if live.playing:
            live.runner.set_bowing(on)  # on a page (no loop) the bow stays lifted
            on = live.runner.bowing
        else:
            live.apparatus.send(cmd.SetBowing(bool(on)))
        live.events.bowing.emit(on=bool(on))

    def set_gesture(self, name):
        """How the virtual hand moves the handle: ``strokes``, ``hold`` or ``live``."""
        if name not in CONSOLE_GESTURES:
            raise UserError(f"gesture {name!r}: allowed are {', '.join(CONSOLE_GESTURES)}")
        live = self.live
        if not live.accepting:
            return
        if live.playing:
            live.runner.set_gesture(name)
        else:
            live.apparatus.send(cmd.SetGesture(name))
        live.events.gesture.emit(name=name)

    def press(self, x_m):
        """The mouse took the bow at ``x_m`` (m): the virtual hand follows it and the bow touches."""
        if not self.live.accepting:
            return
        self.set_gesture("live")
        self._target(x_m)
        self.set_bowing(True)

    def move(self, x_m):
        if self.live.accepting:
            self._target(x_m)

    def release(self):
        self.set_bowing(False)

    def _target(self, x_m):
        if self.live.playing:
            self.live.runner.set_hand_target(x_m)  # followed with the live gesture, and traced
        else:
            self.live.apparatus.send(cmd.SetHandTarget(float(x_m)))
