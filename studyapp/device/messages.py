"""The protocol's messages: one frozen dataclass per type, ``pack`` to a payload, ``parse`` from one.

A payload (frames.py carries it) is ``type:u8, seq:u8, body``; every integer
little-endian, every float IEEE-754 binary64 little-endian. Host -> device
types are >= 0x80, device -> host < 0x80. The byte layouts are tabled in
docs/device-protocol.md; the ``LAYOUT`` of each fixed-size message below is
its body as a ``struct`` format, fields in the dataclass's order.

``parse`` raises ``ProtocolError`` naming the field for a body of the wrong
length, an unknown type, a value out of its range (a force that is not
finite, a count of 0, a name that is not UTF-8): such a frame is counted and
never applied. ``pack`` checks the same ranges, so that nothing a peer
would refuse is sent.

SENSORS depends on the channel layout announced in INFO, so its ``pack``
and ``parse`` take the ``channels``; ``parse(payload, channels)`` at module
level dispatches on the type byte and returns ``(seq, message)``.
"""

import math
import struct
from dataclasses import dataclass, fields
from typing import ClassVar

from studyapp.device.errors import ProtocolError

PROTOCOL_VERSION = 1

HELLO, FORCE, ARM, DISARM, START, STOP, PING, KEEPALIVE = range(0x81, 0x89)
INFO, SENSORS, PONG, FAULT, STATE = range(0x01, 0x06)

# FAULT codes
WATCHDOG, CLAMP, SUSTAINED, LINK_CORRUPT, INTERNAL, LATE = range(1, 7)
FAULT_NAMES = {WATCHDOG: "WATCHDOG", CLAMP: "CLAMP", SUSTAINED: "SUSTAINED", LINK_CORRUPT: "LINK_CORRUPT",
               INTERNAL: "INTERNAL", LATE: "LATE"}
# DISARM reasons
HOST_REQUEST, EMERGENCY_STOP, HOST_FAULT = range(3)
# channel kinds (SI unit) and formats
POSITION, ACCELERATION, VELOCITY = range(3)
KIND_NAMES = {POSITION: "position m", ACCELERATION: "acceleration m/s^2", VELOCITY: "velocity m/s"}
F64, I32, I16 = range(3)
FORMAT_CODES = {F64: "d", I32: "i", I16: "h"}
# SENSORS flags
FLAG_ARMED, FLAG_FAULT, FLAG_CLAMPED, FLAG_RAMPING = 1, 2, 4, 8

MAX_FORCES = 64
TEXT_MAX = 32
MAX_CHANNELS = 8
PAYLOAD_MAX = 1024
GAIN_MAX = 1e3  # SI units per count (m, m/s^2, m/s): a sensor's count is nm to mm, never a kilometre
OFFSET_MAX = 1e3  # SI units
HEADER = struct.Struct("<BB")
SENSORS_HEADER = struct.Struct("<IBB")


def scale_problem(field, value):
    """None if ``value`` is a usable calibration ``field`` ("gain" or "offset"), else ``"field = value: allowed ..."``.

    SI = gain x raw + offset: a gain of 0 makes every sample 0, and bounds keep a count channel's SI values finite
    and physical (a gain of -1e300 with an offset of 1e300 overflows or cancels to nonsense)."""
    bound = GAIN_MAX if field == "gain" else OFFSET_MAX
    number = isinstance(value, (int, float)) and not isinstance(value, bool)
    if number and math.isfinite(value) and abs(value) <= bound and (value != 0 or field == "offset"):
        return None
    what = f"a number from -{bound:g} to {bound:g}" + (", not 0" if field == "gain" else "")
    return f"{field} = {value!r}: allowed is {what} (SI units{' per count' if field == 'gain' else ''})"


def _check(ok, name, value, allowed):
    if not ok:
        raise ProtocolError(f"{name} = {value!r}: allowed is {allowed}")


def _check_uint(name, value, bits):
    _check(isinstance(value, int) and 0 <= value < 1 << bits, name, value, f"an integer 0..{(1 << bits) - 1}")


def _check_finite(name, value, positive=False):
    number = isinstance(value, (int, float)) and not isinstance(value, bool)
    ok = number and math.isfinite(value) and (value > 0.0 or not positive)
    _check(ok, name, value, "a finite number above 0" if positive else "a finite number")


def _body(cls, payload, size=None):
    if len(payload) < 2:
        raise ProtocolError(f"payload of {len(payload)} bytes: shorter than type and seq")
    if payload[0] != cls.TYPE:
        raise ProtocolError(f"type 0x{payload[0]:02x}: {cls.__name__.upper()} is 0x{cls.TYPE:02x}")
    body = bytes(payload[2:])
    if size is not None and len(body) != size:
        raise ProtocolError(f"{cls.__name__.upper()} body of {len(body)} bytes: it has {size}")
    return body


def _short(cls, field, body, offset, size):
    if offset + size > len(body):
        raise ProtocolError(f"{cls.__name__.upper()} ends inside {field} (body of {len(body)} bytes)")


class _Fixed:
    """A message whose body is ``LAYOUT``, the dataclass's fields in order; ``check`` names a bad field."""

    TYPE: ClassVar[int]
    LAYOUT: ClassVar[str] = "<"
    BITS: ClassVar[tuple] = ()

    def check(self):
        for f, bits in zip(fields(self), self.BITS):
            _check_uint(f"{type(self).__name__.upper()}.{f.name}", getattr(self, f.name), bits)

    def pack(self, seq=0):
        self.check()
        return HEADER.pack(self.TYPE, seq) + struct.pack(self.LAYOUT, *(getattr(self, f.name) for f in fields(self)))

    @classmethod
    def parse(cls, payload):
        body = _body(cls, payload, struct.calcsize(cls.LAYOUT))
        message = cls(*struct.unpack(cls.LAYOUT, body))
        message.check()
        return message


@dataclass(frozen=True)
class Hello(_Fixed):
    TYPE: ClassVar[int] = HELLO
    LAYOUT: ClassVar[str] = "<H"
    BITS: ClassVar[tuple] = (16,)
    protocol_version: int = PROTOCOL_VERSION


@dataclass(frozen=True)
class Arm(_Fixed):
    TYPE: ClassVar[int] = ARM
    LAYOUT: ClassVar[str] = "<H"
    BITS: ClassVar[tuple] = (16,)
    ramp_ms: int = 0


@dataclass(frozen=True)
class Disarm(_Fixed):
    TYPE: ClassVar[int] = DISARM
    LAYOUT: ClassVar[str] = "<B"
    BITS: ClassVar[tuple] = (8,)
    reason: int = HOST_REQUEST

    def check(self):
        super().check()
        _check(self.reason in (HOST_REQUEST, EMERGENCY_STOP, HOST_FAULT), "DISARM.reason", self.reason, "0, 1 or 2")


@dataclass(frozen=True)
class Start(_Fixed):
    TYPE: ClassVar[int] = START
    LAYOUT: ClassVar[str] = "<BH"
    BITS: ClassVar[tuple] = (8, 16)
    packet: int = 1
    latency: int = 1

    def check(self):
        super().check()
        _check(self.packet >= 1, "START.packet", self.packet, "1..255 samples")
        # the force for sample j answers the frame holding sample j - latency, sent once its last sample is in
        _check(self.latency >= self.packet - 1, "START.latency", self.latency,
               f"at least packet - 1 = {self.packet - 1}")


@dataclass(frozen=True)
class Stop(_Fixed):
    TYPE: ClassVar[int] = STOP


@dataclass(frozen=True)
class Ping(_Fixed):
    TYPE: ClassVar[int] = PING
    LAYOUT: ClassVar[str] = "<I"
    BITS: ClassVar[tuple] = (32,)
    nonce: int = 0


@dataclass(frozen=True)
class Keepalive(_Fixed):
    TYPE: ClassVar[int] = KEEPALIVE


@dataclass(frozen=True)
class Pong(_Fixed):
    TYPE: ClassVar[int] = PONG
    LAYOUT: ClassVar[str] = "<II"
    BITS: ClassVar[tuple] = (32, 32)
    nonce: int = 0
    sample: int = 0


@dataclass(frozen=True)
class Fault(_Fixed):
    TYPE: ClassVar[int] = FAULT
    LAYOUT: ClassVar[str] = "<BII"
    BITS: ClassVar[tuple] = (8, 32, 32)
    code: int = INTERNAL
    sample: int = 0
    detail: int = 0

    def check(self):
        super().check()
        _check(self.code in FAULT_NAMES, "FAULT.code", self.code, "1..6")


@dataclass(frozen=True)
class State(_Fixed):
    TYPE: ClassVar[int] = STATE
    LAYOUT: ClassVar[str] = "<BBBIII"
    BITS: ClassVar[tuple] = (1, 1, 8, 32, 32, 32)
    armed: int = 0
    streaming: int = 0
    faults: int = 0
    late: int = 0
    lost: int = 0
    corrupt: int = 0


@dataclass(frozen=True)
class Force:
    """Forces (N) for the consecutive device samples ``sample``, ``sample + 1``, ... (1..64 of them)."""

    TYPE: ClassVar[int] = FORCE
    sample: int
    forces: tuple

    def check(self):
        _check_uint("FORCE.sample", self.sample, 32)
        _check(1 <= len(self.forces) <= MAX_FORCES, "FORCE.count", len(self.forces), f"1..{MAX_FORCES}")
        for i, f in enumerate(self.forces):
            _check_finite(f"FORCE.force[{i}]", f)

    def pack(self, seq=0):
        self.check()
        n = len(self.forces)
        return HEADER.pack(FORCE, seq) + struct.pack(f"<IB{n}d", self.sample, n, *self.forces)

    @classmethod
    def parse(cls, payload):
        body = _body(cls, payload)
        _short(cls, "count", body, 0, 5)
        sample, n = struct.unpack_from("<IB", body)
        _check(1 <= n <= MAX_FORCES, "FORCE.count", n, f"1..{MAX_FORCES}")
        _check(len(body) == 5 + 8 * n, "FORCE body length", len(body), f"5 + 8 x count = {5 + 8 * n} bytes")
        message = cls(sample, struct.unpack_from(f"<{n}d", body, 5))
        message.check()
        return message


@dataclass(frozen=True)
class Channel:
    """One sensor channel: what it measures, how it is sent; SI = gain * raw + offset."""

    kind: int
    format: int = F64
    gain: float = 1.0
    offset: float = 0.0

    def check(self, i=0):
        _check(self.kind in KIND_NAMES, f"INFO.channel[{i}].kind", self.kind, "0 position, 1 acceleration, 2 velocity")
        _check(self.format in FORMAT_CODES, f"INFO.channel[{i}].format", self.format, "0 f64, 1 i32, 2 i16")
        problem = scale_problem("gain", self.gain) or scale_problem("offset", self.offset)
        if problem:
            raise ProtocolError(f"INFO.channel[{i}].{problem}")
        if self.format == F64:
            _check(self.gain == 1.0 and self.offset == 0.0, f"INFO.channel[{i}] gain, offset",
                   (self.gain, self.offset), "1 and 0 for an f64 channel (it is sent in SI)")

    def to_si(self, raw):
        return raw if self.format == F64 else self.gain * raw + self.offset


# the emulator's and the simulated device's channels: read_sensors' order (x, a, v), in SI
SI_CHANNELS = (Channel(POSITION), Channel(ACCELERATION), Channel(VELOCITY))
CHANNEL = struct.Struct("<BBdd")
INFO_LIMITS = struct.Struct("<ddddHHB")
INFO_HEAD = struct.Struct("<HBBIB")


def sensors_row_format(channels):
    return "".join(FORMAT_CODES[c.format] for c in channels)


def max_packet(channels):
    """The most samples a SENSORS frame of ``channels`` holds within the largest payload."""
    row = struct.calcsize("<" + sensors_row_format(channels))
    return min(255, (PAYLOAD_MAX - HEADER.size - SENSORS_HEADER.size) // row)


def _text(name, value):
    raw = value.encode("utf-8") if isinstance(value, str) else b"\xff"
    _check(len(raw) <= TEXT_MAX, name, value, f"at most {TEXT_MAX} bytes of UTF-8")
    return bytes((len(raw),)) + raw


def _read_text(name, body, offset):
    _short(Info, name, body, offset, 1)
    n = body[offset]
    _check(n <= TEXT_MAX, f"{name} length", n, f"0..{TEXT_MAX} bytes")
    _short(Info, name, body, offset + 1, n)
    try:
        text = body[offset + 1:offset + 1 + n].decode("utf-8")
    except UnicodeDecodeError:
        raise ProtocolError(f"{name}: not valid UTF-8 ({body[offset + 1:offset + 1 + n]!r})") from None
    return text, offset + 1 + n


@dataclass(frozen=True)
class Info:
    """The device's answer to HELLO: versions, clock, identity, limits, watchdog and channels."""

    TYPE: ClassVar[int] = INFO
    protocol_version: int
    firmware_major: int
    firmware_minor: int
    rate_hz: int
    max_packet: int
    name: str
    serial: str
    travel_m: float
    impulsive_n: float
    sustained_n: float
    sustained_window_s: float
    watchdog_ms: int
    ramp_ms_min: int
    channels: tuple = SI_CHANNELS
    loop_tail: bytes = b""  # version 2: the loop section after the channels (loop_messages.LoopInfo)

    def check(self):
        for name, bits in (("protocol_version", 16), ("firmware_major", 8), ("firmware_minor", 8),
                           ("rate_hz", 32), ("max_packet", 8), ("watchdog_ms", 16), ("ramp_ms_min", 16)):
            _check_uint(f"INFO.{name}", getattr(self, name), bits)
        _check(self.rate_hz > 0, "INFO.rate_hz", self.rate_hz, "above 0")
        for name in ("travel_m", "impulsive_n", "sustained_n", "sustained_window_s"):
            _check_finite(f"INFO.{name}", getattr(self, name), positive=True)
        _check(1 <= len(self.channels) <= MAX_CHANNELS, "INFO.channel_count", len(self.channels), f"1..{MAX_CHANNELS}")
        for i, c in enumerate(self.channels):
            c.check(i)
        largest = max_packet(self.channels)
        _check(1 <= self.max_packet <= largest, "INFO.max_packet", self.max_packet,
               f"1..{largest} (a SENSORS frame of these channels within {PAYLOAD_MAX} bytes)")
        _text("INFO.name", self.name)
        _text("INFO.serial", self.serial)
        _check(self.protocol_version >= 2 or not self.loop_tail, "INFO loop section", len(self.loop_tail),
               "none in version 1")

    def pack(self, seq=0):
        self.check()
        out = bytearray(HEADER.pack(INFO, seq))
        out += INFO_HEAD.pack(self.protocol_version, self.firmware_major, self.firmware_minor, self.rate_hz,
                              self.max_packet)
        out += _text("INFO.name", self.name) + _text("INFO.serial", self.serial)
        out += INFO_LIMITS.pack(self.travel_m, self.impulsive_n, self.sustained_n, self.sustained_window_s,
                                self.watchdog_ms, self.ramp_ms_min, len(self.channels))
        for c in self.channels:
            out += CHANNEL.pack(c.kind, c.format, c.gain, c.offset)
        return bytes(out + self.loop_tail)

    @classmethod
    def parse(cls, payload):
        body = _body(cls, payload)
        _short(cls, "max_packet", body, 0, INFO_HEAD.size)
        head = INFO_HEAD.unpack_from(body)
        name, at = _read_text("INFO.name", body, INFO_HEAD.size)
        serial, at = _read_text("INFO.serial", body, at)
        _short(cls, "channel_count", body, at, INFO_LIMITS.size)
        *limits, n = INFO_LIMITS.unpack_from(body, at)
        at += INFO_LIMITS.size
        _check(1 <= n <= MAX_CHANNELS, "INFO.channel_count", n, f"1..{MAX_CHANNELS}")
        end = at + n * CHANNEL.size
        if head[0] < 2:
            _check(len(body) == end, "INFO body length", len(body), f"{end} bytes for {n} channels")
        _short(cls, "channels", body, at, n * CHANNEL.size)
        channels = tuple(Channel(*CHANNEL.unpack_from(body, at + i * CHANNEL.size)) for i in range(n))
        message = cls(*head, name, serial, *limits, channels, bytes(body[end:]))
        message.check()
        return message


@dataclass(frozen=True)
class Sensors:
    """``len(values)`` consecutive samples from device sample ``sample``: each row the channels' raw values."""

    TYPE: ClassVar[int] = SENSORS
    sample: int
    flags: int
    values: tuple

    def pack(self, seq=0, channels=SI_CHANNELS):
        _check_uint("SENSORS.sample", self.sample, 32)
        _check_uint("SENSORS.flags", self.flags, 8)
        n = len(self.values)
        _check(1 <= n <= max_packet(channels), "SENSORS.count", n, f"1..{max_packet(channels)}")
        row = sensors_row_format(channels)
        flat = [v for r in self.values for v in r]
        _check(len(flat) == n * len(channels), "SENSORS values", len(flat), f"{len(channels)} per sample")
        try:
            body = struct.pack("<IBB" + row * n, self.sample, n, self.flags, *flat)
        except struct.error as exc:
            raise ProtocolError(f"SENSORS values: {exc}") from None
        return HEADER.pack(SENSORS, seq) + body

    @classmethod
    def parse(cls, payload, channels=SI_CHANNELS):
        body = _body(cls, payload)
        _short(cls, "flags", body, 0, SENSORS_HEADER.size)
        sample, n, flags = SENSORS_HEADER.unpack_from(body)
        row = "<" + sensors_row_format(channels)
        size = struct.calcsize(row)
        _check(n >= 1, "SENSORS.count", n, "1 or more")
        _check(len(body) == SENSORS_HEADER.size + n * size, "SENSORS body length", len(body),
               f"6 + {size} x count = {SENSORS_HEADER.size + n * size} bytes")
        values = tuple(struct.iter_unpack(row, body[SENSORS_HEADER.size:]))
        return cls(sample, flags, values)

    def si(self, channels=SI_CHANNELS):
        """The rows in SI units (calibration of each channel applied)."""
        return tuple(tuple(c.to_si(v) for c, v in zip(channels, r)) for r in self.values)


HOST_TYPES = {m.TYPE: m for m in (Hello, Force, Arm, Disarm, Start, Stop, Ping, Keepalive)}
DEVICE_TYPES = {m.TYPE: m for m in (Info, Sensors, Pong, Fault, State)}


def parse(payload, channels=None):
    """``(seq, message)`` of a checked payload (frames.py); SENSORS needs the INFO's ``channels``."""
    if len(payload) < 2:
        raise ProtocolError(f"payload of {len(payload)} bytes: shorter than type and seq")
    kind = payload[0]
    cls = HOST_TYPES.get(kind) or DEVICE_TYPES.get(kind)
    if cls is None:
        raise ProtocolError(f"type 0x{kind:02x}: unknown")
    if cls is Sensors:
        if channels is None:
            raise ProtocolError("SENSORS before INFO: the channel layout is unknown")
        return payload[1], Sensors.parse(payload, channels)
    return payload[1], cls.parse(payload)
