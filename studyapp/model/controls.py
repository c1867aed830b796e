"""What a knob or pad does while the engine runs: the typed actions a task gives and the worker applies.

A task type names, per control, an action (``TaskType.knob_actions``:
experiment/tasks); the real-time worker applies it to every value that control
sends (engine/commands.py ``action_commands``, engine/pickup.py). The two
layers never import each other: this module is where they meet.

A control's value v lies in [0, 1]: a MIDI 7-bit value k / 127, an on-screen
knob's step k / 127, a pad pressed (1) or released (0). A knob's *step* is
k = round(127 v) (``knob_step``), its value again v = k / 127
(``knob_value``): the only two conversions between them.

    FmaxKnob(ceiling, decades)   F_max on the app's one knob law (model/fmax_knob.py, the paper's
                                 logarithmic map, Sec. 8.2): F_max = 0 at step 0, else
                                 ceiling * 10^(-decades (127 - k) / 126); applied here only (``fmax``)
    FmaxLinear(low, high)        F_max = low + v (high - low)
    Volume()                     the master volume on the console's law: v dB-linear over VOLUME_DB
                                 (-40 dB at 0, 0 dB at 1), gain 10^(dB/20); applied here only
    Source(name)                 a pad: selects the velocity source ``name`` when pressed
    Select(condition, fmax)      a rating knob: any movement selects ``condition``, at ``fmax`` if given
    Bowing()                     the bow on the string while v > 0
    HandTarget(low, high)        the hand's target position low + v (high - low) (m)

Every action checks its fields when it is made (``check``): a ceiling of 0 or
below, 0 decades, a NaN, an infinity or 1e308 would kill the worker at the next
knob move (``knob_from_fmax``) or send F_max to the clamp. An action that came
through a pipe (unpickled: never made here) is checked again by ``as_actions``
where the worker installs it (issue 41, item 17).

An action also has a compact spelling, the tuple ``(kind, *fields)`` with the
kinds of ``KINDS`` (e.g. ``("fmax_log", 40.0, 2.0)``, ``("select", "KALLEV",
1.0)``); ``as_action`` reads it.
"""

import math
import numbers
from dataclasses import dataclass, fields

from studyapp.errors import ParameterError
from studyapp.model.fmax_knob import KNOB_MAX, LIVE_RANGE, fmax_from_knob, knob_from_fmax
from studyapp.model.limits import FMAX_LIMIT, HAND_REACH, KNOB_DECADES

VOLUME_DB = (-40.0, 0.0)  # the master volume's range: an attenuator, never above the chain's full level

__all__ = ["KNOB_MAX", "LIVE_RANGE", "VOLUME_DB", "FmaxKnob", "FmaxLinear", "Volume", "Source", "Select", "Bowing",
           "HandTarget", "as_action", "as_actions", "knob_step", "knob_value"]


def knob_step(value):
    """The knob step (0..127) of a control value in [0, 1]."""
    return round(value * KNOB_MAX)


def knob_value(step):
    """The control value in [0, 1] of knob step ``step`` (0..127)."""
    return step / KNOB_MAX


def number(what, value, low, high, allowed, above=False):
    """``value`` as a float when it is a finite number in [low, high] (``above``: in (low, high]);
    ``ParameterError`` naming ``what`` and what is ``allowed`` otherwise."""
    ok = isinstance(value, numbers.Real) and not isinstance(value, bool) and math.isfinite(value)
    if not ok or not (low < value if above else low <= value) or value > high:
        raise ParameterError(f"{what} = {value!r}: allowed is {allowed}")
    return float(value)


def _fmax(what, value):
    return number(what, value, 0.0, FMAX_LIMIT, f"an F_max from 0 to {FMAX_LIMIT:g} N")


def hand_target(value):
    """A hand target (m) checked: finite, at most ``HAND_REACH`` from the centre."""
    return number("hand target", value, -HAND_REACH, HAND_REACH,
                  f"a position from {-HAND_REACH:g} to {HAND_REACH:g} m")


class _Checked:
    def __post_init__(self):
        self.check()

    def check(self):
        """Raise ``ParameterError`` for a field out of range; return the action."""
        return self


@dataclass(frozen=True)
class FmaxKnob(_Checked):
    """F_max on the logarithmic knob law over ``decades`` decades up to ``ceiling`` (N)."""

    ceiling: float
    decades: float

    def check(self):
        number("knob ceiling", self.ceiling, 0.0, FMAX_LIMIT, f"an F_max above 0, at most {FMAX_LIMIT:g} N",
               above=True)
        number("knob decades", self.decades, *KNOB_DECADES, f"{KNOB_DECADES[0]:g} to {KNOB_DECADES[1]:g} decades")
        return self

    def fmax(self, step):
        """F_max (N) at knob step ``step`` (0..127): the one place the knob law is applied."""
        return fmax_from_knob(step, self.ceiling, self.decades)

    def step(self, fmax):
        """The knob step whose F_max is nearest ``fmax`` (N): the law's inverse."""
        return knob_from_fmax(fmax, self.ceiling, self.decades)


@dataclass(frozen=True)
class FmaxLinear(_Checked):
    """F_max from ``low`` (value 0) to ``high`` (value 1), N, linearly."""

    low: float
    high: float

    def check(self):
        if _fmax("knob low", self.low) == _fmax("knob high", self.high):
            raise ParameterError(f"knob low = knob high = {self.low!r}: allowed is a range of F_max, two values")
        return self

    def fmax(self, value):
        return self.low + value * (self.high - self.low)


@dataclass(frozen=True)
class Volume:
    """The master volume: the console's slider and a volume knob share this law, so one level has one
    knob position (pickup) and the console shows what a knob set."""

    @staticmethod
    def db(value):
        low, high = VOLUME_DB
        return low + min(max(value, 0.0), 1.0) * (high - low)

    @staticmethod
    def gain(value):
        """The linear gain the sink applies at control value ``value`` (0..1)."""
        return 10.0 ** (Volume.db(value) / 20.0)

    @staticmethod
    def value(db):
        """The control value (0..1) of the volume ``db`` (dB, clipped to VOLUME_DB)."""
        low, high = VOLUME_DB
        return (min(max(db, low), high) - low) / (high - low)

    @staticmethod
    def value_of_gain(gain):
        """The control value (0..1) of a linear ``gain`` (0, silence, is the bottom)."""
        return Volume.value(20.0 * math.log10(gain)) if gain > 0 else 0.0


@dataclass(frozen=True)
class Source(_Checked):
    """A pad: selects the velocity source ``name`` when pressed (an estimator or a pseudo-source)."""

    name: str

    def check(self):
        if not isinstance(self.name, str):
            raise ParameterError(f"source {self.name!r}: allowed is a velocity source's name")
        return self


@dataclass(frozen=True)
class Select(_Checked):
    """A rating knob: any movement selects ``condition``, at ``fmax`` (N) when one is given."""

    condition: str
    fmax: float | None = None

    def check(self):
        if not isinstance(self.condition, str):
            raise ParameterError(f"rated condition {self.condition!r}: allowed is a velocity source's name")
        if self.fmax is not None:
            _fmax("rating F_max", self.fmax)
        return self


@dataclass(frozen=True)
class Bowing:
    """The bow on the string while the control's value is above 0."""


@dataclass(frozen=True)
class HandTarget(_Checked):
    """The hand's target position (m) from ``low`` (value 0) to ``high`` (value 1)."""

    low: float
    high: float

    def check(self):
        hand_target(self.low)
        hand_target(self.high)
        return self

    def metres(self, value):
        return self.low + value * (self.high - self.low)


ACTIONS = (FmaxKnob, FmaxLinear, Volume, Source, Select, Bowing, HandTarget)
KINDS = {"fmax_log": FmaxKnob, "fmax_linear": FmaxLinear, "volume": Volume, "source": Source,
         "select": Select, "bowing": Bowing, "hand_target": HandTarget}


def as_action(action):
    """An action from itself or its compact spelling ``(kind, *fields)``; ``ParameterError`` otherwise."""
    if isinstance(action, ACTIONS):
        return action
    kind = action[0] if isinstance(action, (tuple, list)) and action else action
    make = KINDS.get(kind) if isinstance(kind, str) and kind is not action else None
    if make is None:
        raise ParameterError(f"MIDI action {kind!r}: allowed are {', '.join(KINDS)}")
    try:
        return make(*action[1:])
    except TypeError:
        names = ", ".join(f.name for f in fields(make)) or "nothing"
        raise ParameterError(f"MIDI action {tuple(action)!r}: {kind} takes {names}") from None


def as_actions(mapping):
    """``{control: action}`` with every action read by ``as_action`` and checked (``check``: again for an
    action that came through a pipe, which unpickling never checked); ``ParameterError`` for a bad one."""
    try:
        mapping = dict(mapping)
    except (TypeError, ValueError):
        raise ParameterError(f"control mapping {mapping!r}: allowed is {{control name: action}}") from None
    checked = {}
    for control, action in mapping.items():
        if not isinstance(control, str):
            raise ParameterError(f"control {control!r}: allowed is a control's name")
        action = as_action(action)
        checked[control] = action.check() if isinstance(action, _Checked) else action
    return checked

