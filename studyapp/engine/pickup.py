"""The worker's control routing: a knob or pad (MIDI or on screen) -> its action -> commands, with soft takeover.

Every control takes one route, in and out of a session: the mapping installed
last (``commands.InstallActions``; ``commands.default_actions`` until then)
names its action (model/controls.py), ``commands.action_commands`` turns the
control's value into commands, and the worker applies them at the block
boundary and reports an ``events.Applied`` (what was done, the latency, the
mapping's ``trial`` tag).

Soft takeover ("pickup"): a physical knob acts only once it has passed through
the level in force. A MIDI knob has no motor: when a trial starts (F_max back
to 0) or a pause ends, the knob is still where the hand left it, and its first
message would jump the level to that position (issue 14: LEVANT straight to
3.29 N, above its breakdown). So a knob whose action sets a level (F_max,
volume, a rating) takes effect only when its movement covers the knob position
``target`` of the level in force: with ``previous`` its last position seen (any
mapping, held or not; None if never seen) and ``value`` the new one, it acts
when

    min(previous, value) <= target <= max(previous, value)    (|value - target| <= 2 without a previous)

A knob that set the level itself keeps acting (its previous position is the
target); one whose level was changed by anything else (a new trial, a pause,
an on-screen knob) must first be turned through the new level. Positions are
knob steps (0..127). On-screen knobs show the level itself and need no pickup.

A knob never seen (a new engine: the first start, a resume, a restart) sends
its first message only once it moves, so it cannot land on the level it rests
at: an LPD8 knob resting at 0 turned up first sends 1. Without a previous
position a knob therefore acts when its first value is within
``PICKUP_SLACK`` = 2 steps of the level (one step, and a second one
coalesced into the same block, midi.coalesce): a knob resting at either end,
or at the level anywhere between, is picked up, and the largest jump this
allows is two steps: from 0 to F_max(2) = 0.41 N on the shipped protocols' two-decade
knob, or 7.6 % of F_max above its bottom). Before issue 31 it waited for exactly
the level, and a knob at the bottom never acted.
"""

import math

from studyapp.engine import commands as cmd
from studyapp.engine import events as ev
from studyapp.engine.midi import coalesce
from studyapp.model.controls import (
    KNOB_MAX, FmaxKnob, FmaxLinear, Select, Volume, as_action, as_actions, knob_step, knob_value,
)

LEVEL_ACTIONS = (FmaxKnob, FmaxLinear, Volume, Select)


PICKUP_SLACK = 2  # knob steps: a knob never seen may have moved this far off the level in its first message


def passes_through(target, previous, value):
    """True when a knob moving from ``previous`` (None: unknown) to ``value`` reaches ``target``."""
    if previous is None:
        return abs(value - target) <= PICKUP_SLACK
    return min(previous, value) <= target <= max(previous, value)


def level_position(action, fmax, volume, rating=None):
    """The knob step (0..127) of the level ``action`` sets, as it is now; None when it has no level yet.

    ``fmax`` (N) and ``volume`` (linear gain) are the worker's; ``rating`` the
    rating knob's position (None: not rated yet, so nothing can jump).
    """
    match as_action(action):
        case FmaxKnob() as knob:
            return knob.step(fmax)
        case FmaxLinear(low, high):
            return _step((fmax - low) / (high - low))
        case Volume() as law:
            return _step(law.value_of_gain(volume))
        case Select():
            return rating
    return None


def _step(fraction):
    return min(max(knob_step(fraction), 0), KNOB_MAX)


def _valid_control(control, value):
    return (isinstance(control, str) and isinstance(value, (int, float)) and not isinstance(value, bool)
            and math.isfinite(value) and 0.0 <= value <= 1.0)


class ControlRouting:
    """The worker's side of the controls (mixed into ``worker.Worker``, whose loop, sink, MIDI input,
    control map and events it uses).

    State: ``actions`` (the mapping in force), ``trial`` (its tag), ``knob_seen``
    (each MIDI control's last step, whatever the mapping: for pickup),
    ``ratings`` (each rating knob's step: the level its ``Select`` sets).
    """

    def init_controls(self, actions):
        self.actions = actions
        self.trial = 0
        self.knob_seen = {}
        self.ratings = {}

    def install(self, c):
        """``InstallActions``: the mapping, its tag and (unless None) the rating knobs' positions from now on.

        Checked again here (``ParameterError``, a warning from ``apply``): a command that came through the
        pipe was never checked by its maker, and a bad knob law would kill the worker at the next knob move."""
        actions = as_actions(c.actions)
        cmd.check_install(c)
        self.actions = actions
        self.trial = int(c.trial)
        if c.positions is not None:
            self.ratings = dict(c.positions)

    def take_midi(self):
        """The MIDI messages received since the last block, coalesced (midi.py), each control to its action."""
        received = self.midi.poll()
        self.status.set(midi_messages=self.midi.received)
        for msg, arrived, block in coalesce(received):
            learning = self.cmap.learning
            hit = self.cmap.lookup(msg)
            if hit is None:
                continue
            control, value = hit
            if learning is not None and self.cmap.learning is None:
                self.events.put(ev.Learned(control, self.cmap.to_dict()[control]))
            self.control(control, value, arrived, block)

    def control(self, control, value, arrived, block, origin="midi"):
        """A control moved (MIDI, or on screen): apply its action, tell the parent.

        A value that is not a number in [0, 1] (``Control("knob1", inf)``) is refused with a notice: on main
        it killed the worker (OverflowError in ``knob_step``)."""
        if not _valid_control(control, value):
            self.notice(f"control {control!r} = {value!r} ignored: allowed is a control name and a value from "
                        "0 to 1", "warning", "controls")
            return
        action = self.actions.get(control)
        step = knob_step(value)
        target = self._pickup_target(control, action, step) if origin == "midi" else None
        commands = cmd.action_commands(action, value, arrived) if action and target is None else ()
        latency = None
        for command in commands:
            latency = self.apply(command)
        if commands and isinstance(action, Select):
            self.ratings[control] = step
        self.events.put(ev.Applied(control, value, arrived, latency, self.k - block, self.k, self.trial,
                                   commands, origin, pending_pickup=target is not None,
                                   pickup_target=None if target is None else knob_value(target)))

    def _pickup_target(self, control, action, step):
        """The knob step a physical knob must pass through before it acts; None when it acts now."""
        previous, self.knob_seen[control] = self.knob_seen.get(control), step
        if not isinstance(action, LEVEL_ACTIONS):
            return None
        volume = self.sink.gain.volume if isinstance(action, Volume) else None
        target = level_position(action, self.loop.fmax, volume, self.ratings.get(control))
        if target is None or passes_through(target, previous, step):
            return None
        return target
