"""Events from the worker to the parent: typed records, each with a ``level``.

``level`` is ``info``, ``warning`` or ``error``: how a console shows the
record, never read from its text. ``topic`` names what a notice is about
(``audio``, ``midi``; empty for anything else), so a view can keep the
latest word on each device without parsing the text.
"""

from dataclasses import dataclass

LEVELS = ("info", "warning", "error")


@dataclass(frozen=True)
class Notice:
    text: str
    level: str = "info"
    topic: str = ""


@dataclass(frozen=True)
class Fault:
    """A safety fault raised in the worker (the force is held at zero while it is latched)."""

    text: str
    when: float  # time.monotonic()
    level: str = "error"


@dataclass(frozen=True)
class Failed:
    """The worker stopped on an exception."""

    text: str  # one line
    trace: str
    level: str = "error"


@dataclass(frozen=True)
class Ready:
    info: dict
    level: str = "info"


@dataclass(frozen=True)
class Applied:
    """A control (MIDI or on-screen) reached the worker and its action, if any, was applied.

    ``arrived``: the message's arrival (``time.monotonic()``); ``latency``: from
    then to the start of the block that applied the action (None without an
    action); ``blocks_late``: block boundaries it waited for; ``block``: that
    block's number; ``trial``: the mapping's tag (``InstallActions.trial``);
    ``commands``: what the action did; ``origin``: ``midi`` or ``screen``;
    ``pending_pickup``: a physical knob that has not yet passed through the
    level in force (soft takeover, engine/pickup.py), so it did nothing;
    ``pickup_target``: that level's knob position, in [0, 1] like ``value``.
    """

    control: str
    value: float
    arrived: float
    latency: float | None
    blocks_late: int
    block: int
    trial: int
    commands: tuple = ()
    origin: str = "midi"
    pending_pickup: bool = False
    pickup_target: float | None = None
    level: str = "info"


@dataclass(frozen=True)
class Learned:
    control: str
    binding: dict
    level: str = "info"


@dataclass(frozen=True)
class Stopped:
    summary: dict
    level: str = "info"


@dataclass(frozen=True)
class DeviceInfo:
    """A device on a link was armed (at the start, after a re-arm): its ``info`` (link_device.LinkDevice.info)."""

    info: dict
    level: str = "info"


@dataclass(frozen=True)
class DeviceHealth:
    """A link device's frame counts over trial ``trial`` (``health``) and since the link opened (``totals``).

    Keys (link_device.HEALTH): frames, samples, corrupt, lost, missing, late, faults, clamped.
    """

    trial: int
    health: dict
    totals: dict
    level: str = "info"
