"""Commands to the worker, and what MIDI controls do.

A command is a tuple ``(kind, value, sent)``: ``sent`` is ``time.monotonic()``
when it was made (CLOCK_MONOTONIC is one clock for every process on Linux, so
the worker can measure the command-to-effect latency: from ``sent`` to the
start of the first block run with the new setting). The worker applies
commands at block boundaries, in order.

Kinds and values:

    source        estimator name or a pseudo-source (model/sources.py: LVT_SENSOR, TRUE)
    fmax          N (clamped to the safety ceiling)
    hand_target   m (switches the gesture to "live")
    bowing        bool
    gesture       gesture name
    reset_string  None
    volume        linear gain 0..4
    mute          bool
    learn         control name: bind it to the next MIDI control that moves
    clear_fault   None: unlatch a safety fault (the experimenter's decision)
    stall         seconds: a drill that stops the worker answering, to test the watchdog
    stop          None

MIDI actions map a control (see midi.ControlMap) to a command. The default
for live use (``default_actions``): knob 1 sets F_max through the app's one
knob law (model/fmax_knob.py, the paper's logarithmic map of Sec. 8.2) over
``LIVE_RANGE``, knob 2 the volume, and pad i selects the i-th velocity source
of the scene.
"""

import time

from studyapp.errors import ParameterError
from studyapp.model.fmax_knob import KNOB_MAX, LIVE_RANGE, fmax_from_knob

KINDS = (
    "source", "fmax", "hand_target", "bowing", "gesture", "reset_string", "volume", "mute",
    "learn", "clear_fault", "stall", "stop",
)


def command(kind, value=None, sent=None):
    if kind not in KINDS:
        raise ParameterError(f"command {kind!r}: allowed are {', '.join(KINDS)}")
    return (kind, value, time.monotonic() if sent is None else sent)


def default_actions(sources, fmax_range=LIVE_RANGE):
    """``{control: action}`` for live use: knob1 F_max, knob2 volume, pad i the i-th source."""
    actions = {"knob1": ("fmax_log", *fmax_range), "knob2": ("volume",)}
    for i, name in enumerate(list(sources)[:8], start=1):
        actions[f"pad{i}"] = ("source", name)
    return actions


def action_command(action, value, sent):
    """The command an action makes from a control value in [0, 1], or ``None`` (e.g. a pad released)."""
    kind = action[0]
    if kind == "fmax_log":
        return command("fmax", fmax_from_knob(value * KNOB_MAX, action[1], action[2]), sent)
    if kind == "fmax_linear":
        return command("fmax", action[1] + value * (action[2] - action[1]), sent)
    if kind == "volume":
        return command("volume", value, sent)
    if kind == "source":
        return command("source", action[1], sent) if value > 0 else None
    if kind == "bowing":
        return command("bowing", value > 0, sent)
    if kind == "hand_target":
        return command("hand_target", action[1] + value * (action[2] - action[1]), sent)
    raise ParameterError(f"MIDI action {kind!r}: allowed are fmax_log, fmax_linear, volume, source, bowing, hand_target")
