"""Opening a conversation with a device: HELLO -> INFO checked, the calibration, the round-trip probe.

The host speaks versions 1 and 2 (docs/device-protocol.md): it refuses
(``ParameterError``, one line naming what differs) a device that speaks
another protocol version, a version 2 device whose loop section does not
parse or whose loop this host cannot run beside it (``check_loop``), runs at a rate other than the loop's,
declares force limits above the motor's (model/limits.py: 200 N impulsive,
60 N sustained), has no position channel, or sends fewer samples per frame
than asked. An INFO that does not parse (a name that is not UTF-8, no
channel, a gain that is not finite, ...: messages.py's checks) is refused
naming its field and value, not taken for silence. A device that sends no INFO
within ``HELLO_WAIT`` is refused too (naming the last frame that did not check,
if one came): the host sends HELLO every ``HELLO_EVERY`` until then, so that
a board that resets when its port opens (an Arduino's bootloader, 1-2 s) is
answered once it runs; the whole handshake is bounded, never a hang.

The latency the host answers at (``check_latency``) is at least ``packet``
samples: a frame leaves the device after its last sample's actuation, so
under the loop order (docs/device-protocol.md: receive, sample, actuate,
send) the force for the frame's first sample k, tagged k + latency, can be
on time only from latency = packet on (with packet - 1 it is always late);
and at most ``MAX_LATENCY`` = 1024: the device drops a force tagged 1024 or
more samples ahead of its clock, and the answer to a frame of samples
k..k+p-1 reaches it at sample k + p at the earliest, its newest force tagged
k + latency + p - 1, so 1023 ahead at most (tests/device/test_latency_range.py
measures both ends on the emulator).

Calibration: SI = gain * raw + offset per channel, INFO's own or the lab's
TOML file's (calibration_file.py); a float64 channel with gain 1 and offset 0
passes its value through untouched (bit for bit: the emulator's lock-step
test relies on it).

The probe: ``PINGS`` PING(nonce) -> PONG(nonce) round trips, timed on the host
(``time.perf_counter``); their median and 99th percentile (ms) are recorded in
the driver's ``info``. A PONG that does not come within ``PING_TIMEOUT`` is a
refusal: a link that loses a handshake frame will not stream.
"""

import math
import statistics
import time
from collections import namedtuple

from studyapp.device import calibration_file, device_side
from studyapp.device import loop_messages as lm
from studyapp.device import messages as msg
from studyapp.device.errors import ProtocolError
from studyapp.errors import ParameterError

HELLO_WAIT = 3.0  # s the host waits for INFO: an Arduino-style board boots for 1-2 s after its port opens
HELLO_EVERY = 0.25  # s between HELLOs while waiting (a HELLO sent while the board boots is lost)
PINGS = 20
PING_TIMEOUT = 0.2  # s
CHANNEL_NAMES = calibration_file.CHANNELS  # INFO's channel kinds 0, 1, 2
MAX_LATENCY = device_side.RING  # samples: a force then reaches the device at most RING - 1 ahead, which it keeps
VERSIONS = (msg.PROTOCOL_VERSION, lm.LOOP_VERSION)  # 1: the loop on the host; 2: either side runs it


def check_latency(latency, packet=1):
    """The latency in samples (``packet``..``MAX_LATENCY``), or ``ParameterError`` saying why the ends are there."""
    try:
        value = int(latency)
    except (TypeError, ValueError):
        value = 0
    if value != latency or not packet <= value <= MAX_LATENCY:
        raise ParameterError(f"device latency = {latency!r}: allowed is a whole number of samples from the packet "
                             f"({packet}: a force for a frame's first sample is late below it) to {MAX_LATENCY} "
                             f"(above it the device drops forces tagged {device_side.RING} or more samples ahead)")
    return value


def check_packet(packet):
    """The samples per sensor frame (1..255), or ``ParameterError``."""
    try:
        value = int(packet)
    except (TypeError, ValueError):
        value = 0
    if value != packet or not 1 <= value <= 255:
        raise ParameterError(f"device packet = {packet!r}: allowed is a whole number of samples from 1 to 255")
    return value


def check_ramp(ramp_ms):
    """The ramp after ARM in ms (0..65535), or ``ParameterError``."""
    try:
        value = int(ramp_ms)
    except (TypeError, ValueError):
        value = -1
    if value != ramp_ms or not 0 <= value <= 0xFFFF:
        raise ParameterError(f"device ramp = {ramp_ms!r}: allowed is a whole number of ms from 0 to 65535")
    return value


def check_silence(seconds):
    """The silence bound in seconds (above 0, at most 10), or ``ParameterError``."""
    try:
        value = float(seconds)
    except (TypeError, ValueError):
        value = math.nan
    if not 0.0 < value <= 10.0:
        raise ParameterError(f"device silence = {seconds!r}: allowed is a number of seconds above 0 and up to 10")
    return value


class Scales:
    """Raw channel values to SI (x m, a m/s^2, v m/s), with where the calibration came from (``source``)."""

    def __init__(self, kinds, pairs, source):
        self.kinds = tuple(kinds)  # channel names in the frame's order
        self.pairs = pairs  # name -> (gain, offset)
        self.source = source

    def __contains__(self, name):
        return name in self.pairs

    def convert(self, rows):
        """``(x, a, v)`` lists from a SENSORS frame's raw ``rows`` (one tuple per sample, channels in INFO's order)."""
        out = {}
        for i, name in enumerate(self.kinds):
            gain, offset = self.pairs[name]
            out[name] = [r[i] for r in rows] if gain == 1.0 and offset == 0.0 else [gain * r[i] + offset for r in rows]
        zeros = [0.0] * len(rows)
        return out["position"], out.get("acceleration", zeros), out.get("velocity", zeros)


BadFrame = namedtuple("BadFrame", "what info")  # a frame that did not check while shaking hands; info: an INFO's


def _refuse(link, what):
    raise ParameterError(f"device at {link}: {what}; refused")


def check_info(info, link, rate, motor_limits, packet):
    """Refuse a device that does not fit this host and loop (one line naming what differs)."""
    if info.protocol_version not in VERSIONS:
        _refuse(link, f"protocol version {info.protocol_version}, this host speaks "
                      f"{' and '.join(str(v) for v in VERSIONS)}")
    if float(info.rate_hz) != float(rate):
        _refuse(link, f"rate {info.rate_hz:g} Hz, the loop runs at {rate:g} Hz")
    if not info.impulsive_n <= motor_limits.impulsive:
        _refuse(link, f"impulsive limit {info.impulsive_n:g} N, above the motor's {motor_limits.impulsive:g} N")
    if not info.sustained_n <= motor_limits.sustained:
        _refuse(link, f"sustained limit {info.sustained_n:g} N, above the motor's {motor_limits.sustained:g} N")
    kinds = [c.kind for c in info.channels]
    if 0 not in kinds:
        _refuse(link, "no position channel (kind 0)")
    if len(set(kinds)) != len(kinds) or not set(kinds) <= {0, 1, 2}:
        _refuse(link, f"channel kinds {kinds}; allowed is each of 0 (position), 1, 2 at most once")
    if packet > info.max_packet:
        _refuse(link, f"at most {info.max_packet} samples per frame, {packet} asked")
    check_loop(info, link, packet)


def loop_of(info, link):
    """INFO's loop section (``loop_messages.LoopInfo``; a version 1 INFO: the host runs the loop), or a refusal."""
    try:
        return lm.loop_info(info)
    except ProtocolError as exc:
        _refuse(link, f"its INFO's loop section does not parse ({exc})")


def check_loop(info, link, packet):
    """Refuse a device loop this host cannot run beside: TELEMETRY frames of ``packet`` rows must fit a frame."""
    loop = loop_of(info, link)
    if loop.loop == lm.DEVICE_LOOP:
        largest = lm.max_telemetry_packet(info.channels)
        if packet > largest:
            _refuse(link, f"runs the loop itself, and a TELEMETRY frame of its channels holds at most {largest} "
                          f"samples, {packet} asked")


def scales(info, serial, calibration_path):
    kinds = [CHANNEL_NAMES[c.kind] for c in info.channels]
    device = {CHANNEL_NAMES[c.kind]: (float(c.gain), float(c.offset)) for c in info.channels}
    pairs, source = calibration_file.apply(device, serial, calibration_path)
    return Scales(kinds, pairs, source)


def greet(send, receive, link, rate, motor_limits, packet, calibration_path):
    """HELLO every ``HELLO_EVERY`` until INFO comes, for at most ``HELLO_WAIT``; the checked INFO and its ``Scales``.

    ``receive(timeout)`` gives the next message, a ``BadFrame`` or None; an INFO that does not parse is refused at
    once, naming its field; other frames that do not check (a board's boot noise) are waited through."""
    end = time.monotonic() + HELLO_WAIT
    noise = None
    while time.monotonic() < end:
        send(msg.Hello(protocol_version=msg.PROTOCOL_VERSION))  # HELLO(1), as the protocol has it for both
        until = min(end, time.monotonic() + HELLO_EVERY)
        while (left := until - time.monotonic()) > 0:
            reply = receive(left)
            if isinstance(reply, BadFrame):
                if reply.info:
                    _refuse(link, f"its INFO: {reply.what}")
                noise = reply.what
            elif isinstance(reply, msg.Info):
                check_info(reply, link, rate, motor_limits, packet)
                return reply, scales(reply, reply.serial, calibration_path)
    heard = "" if noise is None else f" (the last frame that came did not check: {noise})"
    raise ParameterError(f"device at {link}: no answer to HELLO within {HELLO_WAIT:g} s{heard}; "
                         "allowed is a device speaking docs/device-protocol.md")


def probe(send, receive, link, pings):
    """``pings`` PING -> PONG round trips: ``{"median": ms, "p99": ms}``."""
    times = []
    for nonce in range(1, pings + 1):
        started = time.perf_counter()
        send(msg.Ping(nonce=nonce))
        end = time.monotonic() + PING_TIMEOUT
        while True:
            left = end - time.monotonic()
            reply = receive(left) if left > 0 else None
            if reply is None:
                raise ParameterError(f"device at {link}: no PONG to PING {nonce} within {1e3 * PING_TIMEOUT:g} ms")
            if isinstance(reply, msg.Pong) and reply.nonce == nonce:
                times.append(time.perf_counter() - started)
                break
    if not times:
        return {"median": math.nan, "p99": math.nan}
    ms = sorted(1e3 * t for t in times)
    return {"median": statistics.median(ms), "p99": percentile(ms, 99)}


def percentile(ordered, q):
    """The ``q``-th percentile of the sorted list ``ordered``, interpolated linearly (numpy's default);
    here so that the handshake loads no numpy (the probe must answer within seconds on a loaded machine)."""
    position = (len(ordered) - 1) * q / 100.0
    low = math.floor(position)
    high = min(low + 1, len(ordered) - 1)
    return ordered[low] + (ordered[high] - ordered[low]) * (position - low)
