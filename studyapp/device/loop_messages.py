"""Protocol version 2's messages for a device that runs the loop itself (docs/device-protocol.md, "Version 2").

The paper closed its loop on the device's own processor (Sec. 8.4): the
force for sample k comes from the sensors of sample k. A version 2 device
that does so says it in INFO's loop section (``LoopInfo``: ``loop`` = 1,
the keep-alive watchdog, the CRC-32 of its loop's parameter image and the
estimators its loop runs, in the order CONTROL's source names them). Then:

- the host sends **CONTROL** frames (the loop's settings: source, bowing,
  gain = F_max / peak, force scale, a string reset), each with an ``id``
  and the device sample at which it acts, and **ALIVE** frames (the
  keep-alive, with the sample the host has read through);
- the device streams **TELEMETRY**: per sample its sensors (in INFO's
  channel formats), the loop's force, the force it applied (after its own
  safety), the string's velocity at the bridge (the sound) and the ``id``
  of the CONTROL in effect, so the host's shadow of the loop applies each
  CONTROL at exactly the sample the device did, even a late one.

Everything else (framing, HELLO, ARM, DISARM, START, STOP, PING, STATE,
FAULT) is version 1's (messages.py). ``parse`` here reads both.
"""

import struct
from dataclasses import dataclass
from typing import ClassVar

from studyapp.device import messages as msg
from studyapp.device.errors import ProtocolError
from studyapp.device.messages import HEADER, _body, _check, _check_finite, _check_uint, _short

LOOP_VERSION = 2
CONTROL, ALIVE = 0x89, 0x8A
TELEMETRY = 0x06
# LoopInfo.loop
HOST_LOOP, DEVICE_LOOP = 0, 1
# CONTROL.source below 0: the velocity sensor (the LVT) itself
SOURCE_VELOCITY_SENSOR = -2
MAX_ESTIMATORS = 32
LOOP_HEAD = struct.Struct("<BHIB")
CONTROL_BODY = struct.Struct("<HIbBBdd")
TELEMETRY_HEADER = struct.Struct("<IBB")
TELEMETRY_TAIL = "dddH"  # loop force, applied force, bridge velocity, control id
# TELEMETRY flags: version 1's SENSORS flags
FLAG_ARMED, FLAG_FAULT, FLAG_CLAMPED, FLAG_RAMPING = msg.FLAG_ARMED, msg.FLAG_FAULT, msg.FLAG_CLAMPED, msg.FLAG_RAMPING


@dataclass(frozen=True)
class LoopInfo:
    """INFO's version 2 section: who runs the loop, its keep-alive watchdog, parameter image and estimators."""

    loop: int = HOST_LOOP
    keepalive_ms: int = 0
    image: int = 0
    kinds: tuple = ()

    def check(self):
        _check(self.loop in (HOST_LOOP, DEVICE_LOOP), "INFO.loop", self.loop, "0 (host loop) or 1 (device loop)")
        _check_uint("INFO.keepalive_ms", self.keepalive_ms, 16)
        _check_uint("INFO.image", self.image, 32)
        _check(len(self.kinds) <= MAX_ESTIMATORS, "INFO.estimator_count", len(self.kinds), f"0..{MAX_ESTIMATORS}")
        for i, k in enumerate(self.kinds):
            _check_uint(f"INFO.estimator[{i}]", k, 8)
        if self.loop == DEVICE_LOOP:
            _check(self.keepalive_ms >= 1, "INFO.keepalive_ms", self.keepalive_ms, "1..65535 for a device loop")

    def pack(self):
        self.check()
        return LOOP_HEAD.pack(self.loop, self.keepalive_ms, self.image, len(self.kinds)) + bytes(self.kinds)

    @classmethod
    def parse(cls, tail):
        if len(tail) < LOOP_HEAD.size:
            raise ProtocolError(f"INFO loop section of {len(tail)} bytes: version 2 has at least {LOOP_HEAD.size}")
        loop, keepalive, image, n = LOOP_HEAD.unpack_from(tail)
        _check(len(tail) == LOOP_HEAD.size + n, "INFO loop section length", len(tail),
               f"{LOOP_HEAD.size + n} bytes for {n} estimators")
        message = cls(loop, keepalive, image, tuple(tail[LOOP_HEAD.size:]))
        message.check()
        return message


def loop_info(info):
    """The loop section of a parsed INFO (a version 1 INFO: the host runs the loop)."""
    if info.protocol_version < LOOP_VERSION:
        return LoopInfo()
    return LoopInfo.parse(info.loop_tail)


@dataclass(frozen=True)
class Control:
    """The loop's settings from device sample ``sample`` on; ``reset`` sets the string to rest there first."""

    TYPE: ClassVar[int] = CONTROL
    id: int
    sample: int
    source: int
    bowing: int
    reset: int
    gain: float
    force_scale: float

    def check(self):
        _check(isinstance(self.id, int) and 1 <= self.id < 1 << 16, "CONTROL.id", self.id, "1..65535")
        _check_uint("CONTROL.sample", self.sample, 32)
        _check(isinstance(self.source, int) and (self.source >= 0 or self.source == SOURCE_VELOCITY_SENSOR)
               and self.source < MAX_ESTIMATORS, "CONTROL.source", self.source,
               f"0..{MAX_ESTIMATORS - 1} (an estimator of INFO) or {SOURCE_VELOCITY_SENSOR} (the velocity sensor)")
        _check(self.bowing in (0, 1), "CONTROL.bowing", self.bowing, "0 or 1")
        _check(self.reset in (0, 1), "CONTROL.reset", self.reset, "0 or 1")
        _check_finite("CONTROL.gain", self.gain)
        _check(self.gain >= 0.0, "CONTROL.gain", self.gain, "0 or more (N)")
        _check_finite("CONTROL.force_scale", self.force_scale)
        _check(0.0 <= self.force_scale <= 1.0, "CONTROL.force_scale", self.force_scale, "0..1")

    def pack(self, seq=0):
        self.check()
        return HEADER.pack(CONTROL, seq) + CONTROL_BODY.pack(self.id, self.sample, self.source, self.bowing,
                                                            self.reset, self.gain, self.force_scale)

    @classmethod
    def parse(cls, payload):
        message = cls(*CONTROL_BODY.unpack(_body(cls, payload, CONTROL_BODY.size)))
        message.check()
        return message


@dataclass(frozen=True)
class Alive(msg._Fixed):
    """The host's keep-alive: it has read the device's samples before ``seen``."""

    TYPE: ClassVar[int] = ALIVE
    LAYOUT: ClassVar[str] = "<I"
    BITS: ClassVar[tuple] = (32,)
    seen: int = 0


def telemetry_row_format(channels):
    return msg.sensors_row_format(channels) + TELEMETRY_TAIL


def max_telemetry_packet(channels):
    """The most samples a TELEMETRY frame of these channels carries within the payload limit."""
    return min(255, (msg.PAYLOAD_MAX - 2 - TELEMETRY_HEADER.size) // struct.calcsize("<" + telemetry_row_format(channels)))


@dataclass(frozen=True)
class Telemetry:
    """Consecutive samples from ``sample``: each row the channels' raw values, then the loop's four values."""

    TYPE: ClassVar[int] = TELEMETRY
    sample: int
    flags: int
    rows: tuple

    def pack(self, seq=0, channels=msg.SI_CHANNELS):
        _check_uint("TELEMETRY.sample", self.sample, 32)
        _check_uint("TELEMETRY.flags", self.flags, 8)
        n = len(self.rows)
        largest = max_telemetry_packet(channels)
        _check(1 <= n <= largest, "TELEMETRY.count", n, f"1..{largest}")
        flat = [v for r in self.rows for v in r]
        width = len(channels) + 4
        _check(len(flat) == n * width, "TELEMETRY values", len(flat), f"{width} per sample")
        try:
            body = struct.pack("<IBB" + telemetry_row_format(channels) * n, self.sample, n, self.flags, *flat)
        except struct.error as exc:
            raise ProtocolError(f"TELEMETRY values: {exc}") from None
        return HEADER.pack(TELEMETRY, seq) + body

    @classmethod
    def parse(cls, payload, channels=msg.SI_CHANNELS):
        body = _body(cls, payload)
        _short(cls, "flags", body, 0, TELEMETRY_HEADER.size)
        sample, n, flags = TELEMETRY_HEADER.unpack_from(body)
        row = "<" + telemetry_row_format(channels)
        size = struct.calcsize(row)
        _check(n >= 1, "TELEMETRY.count", n, "1 or more")
        _check(len(body) == TELEMETRY_HEADER.size + n * size, "TELEMETRY body length", len(body),
               f"6 + {size} x count = {TELEMETRY_HEADER.size + n * size} bytes")
        return cls(sample, flags, tuple(struct.iter_unpack(row, body[TELEMETRY_HEADER.size:])))


def parse(payload, channels=None):
    """``(seq, message)`` of a checked payload of either version; TELEMETRY and SENSORS need INFO's channels."""
    if len(payload) >= 2 and payload[0] in (CONTROL, ALIVE, TELEMETRY):
        if payload[0] == TELEMETRY:
            if channels is None:
                raise ProtocolError("TELEMETRY before INFO: the channel layout is unknown")
            return payload[1], Telemetry.parse(payload, channels)
        return payload[1], (Control if payload[0] == CONTROL else Alive).parse(payload)
    return msg.parse(payload, channels)
