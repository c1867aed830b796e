"""Commands to the worker, and what MIDI controls do.

A command is a small frozen dataclass; every one carries ``sent``, the
``time.monotonic()`` when it was made (CLOCK_MONOTONIC is one clock for every
process on Linux, so the worker can measure the command-to-effect latency:
from ``sent`` to the start of the first block run with the new setting). The
worker applies commands at block boundaries, in order, through a handler table
(``worker.Worker.HANDLERS``: one method per command type).

Commands whose fields could stop the worker or latch a fault (``InstallActions``,
``SetHandTarget``, ``SetFmax``, ``SetVolume``) check them when made, and the worker checks them again when
it obeys them (a command from a pipe was never made here): a bad one is a
warning, never a dead worker (issue 41, item 17).

An action (model/controls.py: ``FmaxKnob``, ``Select``, ...) maps a control
(see midi.ControlMap) to commands (``action_commands``). The worker applies
them itself, in and out of a session, through the mapping in force:
``default_actions`` outside a session (knob 1 sets F_max through the app's one
knob law, ``FmaxKnob``: the paper's logarithmic map of Sec. 8.2, over
``LIVE_RANGE``; knob 2 the volume; pad i selects the i-th velocity source of
the scene), the trial's mapping during one (``InstallActions``). An on-screen
knob reaches the same mapping as a ``Control`` command, so a knob takes one
route whatever the hand turned.
"""

import math
import time
from dataclasses import dataclass, field

from studyapp.engine.signal_chain import volume_gain
from studyapp.errors import ParameterError
from studyapp.model.controls import (
    KNOB_MAX, LIVE_RANGE, Bowing, FmaxKnob, FmaxLinear, HandTarget, Select, Source, Volume, as_action, as_actions,
    hand_target, knob_step, number,
)


@dataclass(frozen=True)
class Command:
    sent: float = field(default_factory=time.monotonic, kw_only=True, compare=False)  # equal commands: same content


@dataclass(frozen=True)
class SetSource(Command):
    name: str  # an active estimator or a pseudo-source (model/sources.py: LVT_SENSOR, TRUE)


@dataclass(frozen=True)
class SetFmax(Command):
    newtons: float  # clamped to the safety ceiling by the worker, which owns it; refused here below 0 or not finite

    def __post_init__(self):
        number("F_max", self.newtons, 0.0, math.inf, "a number of newtons from 0 up (the worker clamps it to its "
               "ceiling)")


@dataclass(frozen=True)
class SetHandTarget(Command):
    metres: float  # switches the gesture to "live"; at most HAND_REACH from the centre (model/limits.py)

    def __post_init__(self):
        hand_target(self.metres)


@dataclass(frozen=True)
class SetBowing(Command):
    on: bool


@dataclass(frozen=True)
class SetGesture(Command):
    name: str


@dataclass(frozen=True)
class ResetString(Command):
    """The string at rest, the stability monitor afresh, the trial clock at 0."""


@dataclass(frozen=True)
class SetVolume(Command):
    gain: float  # linear, 0..VOLUME_GAIN_MAX (signal_chain.py)

    def __post_init__(self):
        volume_gain(self.gain)


@dataclass(frozen=True)
class SetMute(Command):
    on: bool


@dataclass(frozen=True)
class MidiPort(Command):
    """The parent connected the controller ``name`` to the worker's waiting MIDI inlet ("" when it went away)."""

    name: str


@dataclass(frozen=True)
class ReferenceTone(Command):
    """The headphone level check's sine tone (issue 15): ``hz`` at ``level_dbfs`` (peak, dB re full scale)
    in place of the string's sound; ``level_dbfs`` None ends it and gives the string back."""

    hz: float = 1000.0
    level_dbfs: float | None = None


@dataclass(frozen=True)
class RecordAudio(Command):
    """Keep what the participant hears in the WAV file ``path`` (the first free of ``audio.wav``,
    ``audio-2.wav``, ...: never overwritten; engine/audio/recorder.py); None stops recording. The
    WAV file and ``audio_cues.csv`` get the permissions ``mode`` (participant data: the session's
    files' mode, experiment/data_modes.py), whatever the umask."""

    path: str | None
    mode: int = 0o600


@dataclass(frozen=True)
class AudioCue(Command):
    """A trial boundary in the recording (a row of ``audio_cues.csv``), at the block where it is applied."""

    step: int
    task: str
    trial: int
    event: str  # "start" or "end"


@dataclass(frozen=True)
class Learn(Command):
    control: str  # bind it to the next MIDI control that moves


@dataclass(frozen=True)
class ClearFault(Command):
    """Unlatch a safety fault (the experimenter's decision)."""


@dataclass(frozen=True)
class Stall(Command):
    seconds: float  # a drill that stops the worker answering, to test the watchdog


@dataclass(frozen=True)
class Stop(Command):
    pass


@dataclass(frozen=True)
class InstallActions(Command):
    """The ``{control: action}`` mapping (model/controls.py) from now on; ``trial`` tags the controls it applies.

    ``positions``: the rating knobs' positions (``{control: 0..127}``, a rated
    knob's level for pickup) from now on; None keeps the worker's (a pause).
    """

    actions: dict
    trial: int = 0
    positions: dict | None = None

    def __post_init__(self):
        object.__setattr__(self, "actions", as_actions(self.actions))  # typed and checked, whichever spelling
        check_install(self)


def check_install(install):
    """Raise ``ParameterError`` unless ``install``'s ``trial`` is a whole number (a tag: negative for a pause)
    and its ``positions`` None or {control name: knob step 0..127}; checked where it is made and where the
    worker obeys it."""
    if not isinstance(install.trial, int) or isinstance(install.trial, bool):
        raise ParameterError(f"trial = {install.trial!r}: allowed is a whole number")
    positions = install.positions
    if positions is None:
        return
    if not isinstance(positions, dict) or not all(
            isinstance(c, str) and isinstance(k, int) and not isinstance(k, bool) and 0 <= k <= KNOB_MAX
            for c, k in positions.items()):
        raise ParameterError(f"knob positions {positions!r}: allowed is {{control name: step 0..{KNOB_MAX}}}")


@dataclass(frozen=True)
class Control(Command):
    """An on-screen control moved to ``value`` in [0, 1]: applied as if it came from MIDI."""

    control: str
    value: float


def default_actions(sources, fmax_range=LIVE_RANGE):
    """``{control: action}`` for live use: knob1 F_max, knob2 volume, pad i the i-th source."""
    actions = {"knob1": FmaxKnob(*fmax_range), "knob2": Volume()}
    for i, name in enumerate(list(sources)[:8], start=1):
        actions[f"pad{i}"] = Source(name)
    return actions


def action_commands(action, value, sent):
    """The commands an action (model/controls.py) makes from a control value in [0, 1] (none, e.g. for a
    pad released); its compact spelling ``(kind, *fields)`` is read too."""
    match as_action(action):
        case FmaxKnob() as knob:
            return (SetFmax(knob.fmax(knob_step(value)), sent=sent),)
        case FmaxLinear() as linear:
            return (SetFmax(linear.fmax(value), sent=sent),)
        case Volume() as volume:
            return (SetVolume(volume.gain(value), sent=sent),)
        case Source(name):
            return (SetSource(name, sent=sent),) if value > 0 else ()  # a pad: pressed, not released
        case Select(condition, fmax):
            # a rating knob: any movement selects its condition, at the task's F_max when one is given
            return (SetSource(condition, sent=sent),) + (() if fmax is None else (SetFmax(fmax, sent=sent),))
        case Bowing():
            return (SetBowing(value > 0, sent=sent),)
        case HandTarget() as hand:
            return (SetHandTarget(hand.metres(value), sent=sent),)
