"""The participant's knobs and pads in a live session: routing, pickup, page settle, latency. No Qt.

Every control, MIDI or on screen, goes to the worker (an on-screen one as a
``Control`` command, through the apparatus), which applies its action through
the mapping in force: the preview's outside a session, the trial's during one
(apparatus.py). The worker reports each control back (``events.Applied``,
tagged with the trial's number); ``take`` hands those of the current trial to
the runner, which logs them and keeps the task's state, after telling the
trial's loop what the worker applied (engine_loop.py: the worker is the one
writer of what its knobs set). A held trial's, a stale trial's, or the
preview's while a session starts reach no task; an ended attempt's control
that the worker applied (its report came back after an emergency stop or a
restart began the next attempt) is logged as ``late_control`` and reaches no
task. The knob positions shown are
the worker's (``Applied.value``).

Pickup. A physical knob that sets a level acts only once it has passed
through the level in force (the worker's soft takeover, engine/pickup.py): at
a trial start (F_max 0) and after a pause. Until then the worker reports it
``pending_pickup`` and the ``pickup`` event is announced (the views show
"turn the knob down to pick up"); the task never sees it. Once it acts, a
``pickup`` record (control, trial, when: the trial's clock in s, ignored: the
messages it took) goes to the session log.

Page settle. A page shown less than ``PAGE_SETTLE_S`` ago ignores the
participant's press: the second press of a double press on a trial's confirm
pad would otherwise end the page that follows it unread (logged, not
announced).

Latency. Each control's knob-to-effect latency (knob_latency.py) is shown
and, per trial, logged as a ``knob_latency`` record.
"""

from studyapp.engine import commands as cmd
from studyapp.engine.events import Learned
from studyapp.experiment import records
from studyapp.live.knob_latency import KnobLatency
from studyapp.model.controls import knob_step, knob_value

PAGE_SETTLE_S = 0.5  # s a page shows before the participant can end it


def control_index(name, prefix):
    """0 for ``knob1`` with prefix ``knob``; None for another kind of control."""
    rest = name[len(prefix):]
    return int(rest) - 1 if name.startswith(prefix) and rest.isdigit() else None


class Controls:
    def __init__(self, live):
        self.live = live  # the controller: its state, runner, apparatus, clock and events
        self.latency = KnobLatency()
        self.sent = 0  # on-screen controls sent to the worker ...
        self.taken = 0  # ... and reported back by it (a player may wait for its own)
        self._pickup = {}  # control -> messages ignored while it waits for pickup
        self._page_shown = 0.0  # the controller's clock when the current page appeared

    # on screen ----------------------------------------------------------------------------------------
    def knob(self, index, value):
        """Knob ``index`` (from 0) moved to ``value`` (0..127) on screen: to the worker, as MIDI would."""
        self._send(cmd.Control(f"knob{index + 1}", knob_value(int(value))))

    def pad(self, index):
        """Pad ``index`` (from 0) pressed on screen."""
        self._send(cmd.Control(f"pad{index + 1}", 1.0))

    def _send(self, control):
        if self.live.accepting:
            self.live.apparatus.send(control)
            self.sent += 1

    def engine_replaced(self):
        self.taken = self.sent  # the old engine reports nothing more

    # pages --------------------------------------------------------------------------------------------
    def page_appears(self):
        self._page_shown = self.live.clock()

    def page_age(self):
        """Seconds since the current page appeared."""
        return self.live.clock() - self._page_shown

    def settling(self, control):
        """True (and logged) for the participant's press on a page shown less than PAGE_SETTLE_S ago."""
        since = self.page_age()
        if since >= PAGE_SETTLE_S:
            return False
        self.live.runner.log(records.press_too_soon(control, since))
        return True

    # what the worker took -------------------------------------------------------------------------------
    def take(self, record):
        """A control the worker took (``events.Applied``): show it; the current trial's go to the runner."""
        if isinstance(record, Learned):
            self.live.message(f"MIDI: {record.control} bound to {record.binding}")
            return
        try:
            self._route(record, control_index(record.control, "knob"), control_index(record.control, "pad"))
        finally:
            if record.origin == "screen":
                self.taken += 1

    def _route(self, record, knob, pad):
        live = self.live
        runner = live.runner
        ours = runner is not None and runner.task is not None and record.trial == live.trial_serial
        preview = record.trial == 0 and live.at_rest
        if not (ours or preview):
            self._log_late(record, knob)
            return
        if self._picked_up(record, knob, ours):
            return
        if record.latency is not None:
            self.latency.add(record.latency, record.origin)
        if knob is not None:
            live.events.knob.emit(index=knob, value=knob_step(record.value))
        for command in record.commands:
            if isinstance(command, cmd.SetVolume):  # the preview's volume knob: the one volume record follows
                live.volume_applied(command.gain, record.arrived)
        if not ours:
            return
        if runner.loop is not None:
            runner.loop.applied(record.commands)
        if knob is not None:
            live.take_records(runner.knob(knob, knob_step(record.value)))
        elif pad is not None and record.value > 0:
            if runner.trial.page is not None and self.settling(record.control):
                return
            live.take_records(runner.pad(pad))

    def _log_late(self, record, knob):
        """An ended attempt's control that the worker applied: logged, given to no task."""
        runner = self.live.runner
        if runner is None or not 0 < record.trial < self.live.trial_serial or record.pending_pickup:
            return
        if knob is not None and record.commands:
            runner.log(records.late_control(record.control, knob_step(record.value)))
        elif knob is None and record.value > 0:
            runner.log(records.late_control(record.control, 1))

    def _picked_up(self, record, knob, ours):
        """Follow a knob's pickup; True while it waits for it (the task must not see it)."""
        events = self.live.events
        if record.pending_pickup:
            waiting = record.control in self._pickup
            self._pickup[record.control] = self._pickup.get(record.control, 0) + 1
            if not waiting:
                down = record.value > record.pickup_target
                events.pickup.emit(control=record.control, index=knob, pending=True,
                                   text=f"turn the knob {'down' if down else 'up'} to pick up")
            return True
        ignored = self._pickup.pop(record.control, None)
        if ignored is not None:
            events.pickup.emit(control=record.control, index=knob, pending=False, text="")
            if ours:
                runner = self.live.runner
                runner.log(records.pickup(record.control, runner.trial.trial, getattr(runner.task, "elapsed", None),
                                          ignored))
        return False

    # a step ends -----------------------------------------------------------------------------------------
    def log_latency(self):
        record = self.latency.take()
        if record is not None and self.live.runner is not None:
            self.live.runner.log(record)

    def forget_pickups(self):
        """A new mapping: a knob waiting for pickup waits for the new level (announced by its next message)."""
        for control in self._pickup:
            self.live.events.pickup.emit(control=control, index=control_index(control, "knob"), pending=False,
                                         text="")
        self._pickup = {}
