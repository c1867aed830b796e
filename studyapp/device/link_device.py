"""The host's driver for a device that owns the clock: a ``HapticDevice`` over a byte link.

Protocol: docs/device-protocol.md (v1). At open (``handshake.py``): HELLO ->
INFO checked against the loop (version, rate, limits), the calibration
(INFO's, or the lab's TOML file, calibration_file.py), a PING loopback probe
(round trip median and p99), then START(packet, latency). From then on the
device streams SENSORS frames every ``packet`` samples on its own clock, and
``exchange(control, n, out, est_out)`` (the loop's one call per block,
model/device.py) takes the next ``n`` device samples as they arrive: for each
sample k of the device it converts the raw channels to SI (SI = gain * raw +
offset), asks the loop for the force (``control.sample``) and, once the frame's
samples are done (or the block ends), sends FORCE(k + latency, forces). The
device applies at its sample j the force tagged j, so the loop's one-step
delay (loop.py) becomes ``latency`` samples: the model's fixed link latency
(model/link.py). The worker is paced by these frames (engine/pacing.py).

What can go wrong, and what is done (``health`` counts it, cumulative):

    corrupt   a frame that does not check (frames.FrameReader): never applied
    lost      device frames missing by their sequence numbers (mod 256)
    missing   device samples never received (the sample counter jumped): the loop skips them
    late      forces sent for a sample the host already knew had passed (the device drops them)
    faults    FAULT frames from the device (WATCHDOG, LINK_CORRUPT, INTERNAL latch; CLAMP, SUSTAINED, LATE count)

A link that closes or errors, or is silent longer than ``SILENCE`` while the
host waits for a frame, or a latching FAULT from the device, is a device
fault: ``fault`` is set (the loop latches it at the end of the block: force 0
from then on), DISARM(2) is sent if the link still takes it, and the rest of
the block is filled with zero sensors and zero force without waiting. It
stays latched until ``rearm()`` (the experimenter's act), which reopens the
link if it has to, shakes hands again and arms.

``info`` is a plain dict (the console, session.json and recordings read it;
names documented in docs/engine.md): name, serial, protocol, firmware, rate,
channels, calibration, limits, latency_samples, packet, round_trip_ms
{median, p99}, link.
"""

import time

import numpy as np

from studyapp.device import handshake
from studyapp.device import loop_messages as lm
from studyapp.device import messages as msg
from studyapp.device.errors import ProtocolError
from studyapp.device.frames import FrameReader, encode
from studyapp.device.link_open import open_link
from studyapp.errors import ParameterError
from studyapp.model.device import DeviceLimits, HapticDevice

SILENCE = 0.020  # s without a device frame, while waiting for one, that makes a device fault
LATCHING = (msg.WATCHDOG, msg.LINK_CORRUPT, msg.INTERNAL)
DISARM_HOST, DISARM_EMERGENCY, DISARM_FAULT = msg.HOST_REQUEST, msg.EMERGENCY_STOP, msg.HOST_FAULT
DEFAULT_LATENCY = 5  # samples the host answers ahead (1 ms at 5 kHz)
DEFAULT_PACKET = 1  # samples per sensor frame
DEFAULT_RAMP_MS = 200  # the force ramps up from 0 over this after each ARM
HEALTH = ("frames", "samples", "corrupt", "lost", "missing", "late", "faults", "clamped")


class LinkDevice(HapticDevice):
    """The device on the link ``spec`` (path or URL), streaming at ``rate`` Hz once opened.

    ``latency``: samples ahead the host answers (FORCE tagged sensor sample + latency);
    ``packet``: samples per sensor frame; ``calibration``: a TOML file keyed by serial
    number (None: the device's own); ``ramp_ms``: the force's ramp after each ARM;
    ``timing``: keep every host turnaround (sensor frame read -> force frame written), for benchmarks;
    ``silence``: the longest wait for a frame before the device counts as lost (a device in lock-step,
    which has no clock of its own, may take longer on a loaded machine: its tests raise it).
    """

    clock = True  # the device's frames pace the worker (engine/pacing.py)
    STREAM = msg.Sensors  # the streamed frame ``_sensors`` takes

    def __init__(self, spec, rate, *, latency=DEFAULT_LATENCY, packet=DEFAULT_PACKET, calibration=None,
                 ramp_ms=DEFAULT_RAMP_MS, limits=DeviceLimits(), pings=handshake.PINGS, timing=False,
                 silence=SILENCE):
        self.spec = str(spec)
        self.rate = float(rate)
        self.packet = handshake.check_packet(packet)
        self.latency = handshake.check_latency(latency, self.packet)
        self.calibration_path = calibration
        self.ramp_ms = handshake.check_ramp(ramp_ms)
        self.motor_limits = limits
        self.pings = int(pings)
        self.timing = bool(timing)
        self.silence = handshake.check_silence(silence)
        self.turnarounds = []  # s, per force frame, when ``timing``
        self.health = dict.fromkeys(HEALTH, 0)
        self.fault = None
        self.fault_time = None  # time.monotonic() when ``fault`` was set
        self.last_data = None  # time.monotonic() when bytes last came from the device while streaming
        self.device_faults = []  # (code, sample, detail) of every FAULT frame, oldest first
        self.link_lost = False  # the link itself failed (closed, errored): a re-arm reopens it
        self.armed = False
        self.link = None
        self._open()

    # the link -----------------------------------------------------------------
    def _open(self):
        self.link = open_link(self.spec)
        health = dict(self.health)  # what the handshake's own traffic counts is not the stream's health
        try:
            self._reader = FrameReader()
            self._seq_out = 0
            self._seq_in = None
            self._pending = []  # decoded SENSORS samples not yet run: (sample, x, a, v)
            self._newest = -1  # the newest device sample seen
            self._forces = []  # forces of the current run of samples, not yet sent
            self._first = None  # the device sample of _forces[0]
            self._read_at = 0.0
            self._queue = []  # other messages, while shaking hands
            self._streaming = False
            self.device_state = None  # the device's last STATE (its own counters)
            self.device_info = None
            self._channels = None  # INFO's channel layout, which SENSORS frames need to be read
            self.device_info, self.scales = handshake.greet(self._send, self._receive_one, self.spec, self.rate,
                                                            self.motor_limits, self.packet, self.calibration_path)
            self._channels = self.device_info.channels
            self._check_loop(handshake.loop_of(self.device_info, self.spec))
            self.round_trip = handshake.probe(self._send, self._receive_one, self.spec, self.pings)
            self._pending.clear()
            self._newest = -1
            self.health = health
            self._start()
            self._streaming = True
        except (OSError, EOFError) as exc:
            self.link.close()
            self.link = None
            raise ParameterError(f"device at {self.spec}: the link failed during the handshake ({_why(exc)})") from None
        except BaseException:
            self.link.close()
            self.link = None
            raise
        self.limits = DeviceLimits(travel=self.device_info.travel_m,
                                   impulsive=min(self.device_info.impulsive_n, self.motor_limits.impulsive),
                                   sustained=min(self.device_info.sustained_n, self.motor_limits.sustained),
                                   sustained_window=self.motor_limits.sustained_window)

    def _check_loop(self, loop):
        """Refuse a version 2 device that runs the loop itself: FORCE frames would be corrupt to it."""
        if loop.loop == lm.DEVICE_LOOP:
            raise ParameterError(f"device at {self.spec}: it runs the loop itself (protocol 2), so the host's loop "
                                 "cannot drive it (studyapp/device/loop_link.py does); refused")

    def _start(self):
        self._send(msg.Start(packet=self.packet, latency=self.latency))

    def _parse(self, payload):
        return msg.parse(payload, self._channels)

    @property
    def info(self):
        d = self.device_info
        return {
            "name": d.name, "serial": d.serial, "protocol": d.protocol_version,
            "firmware": f"{d.firmware_major}.{d.firmware_minor}", "rate": float(d.rate_hz),
            "channels": [c for c in handshake.CHANNEL_NAMES if c in self.scales],
            "calibration": self.calibration_source,
            "limits": {"travel_m": d.travel_m, "impulsive_n": d.impulsive_n, "sustained_n": d.sustained_n,
                       "sustained_window_s": d.sustained_window_s, "watchdog_ms": d.watchdog_ms,
                       "ramp_ms_min": d.ramp_ms_min},
            "latency_samples": self.latency, "latency_ms": 1e3 * self.latency / self.rate, "packet": self.packet,
            "round_trip_ms": dict(self.round_trip), "link": self.spec,
        }

    @property
    def calibration_source(self):
        return self.scales.source

    def _send(self, message):
        """Frame and write one message; a link that will not take it is a device fault (``OSError`` caught)."""
        payload = message.pack(self._seq_out)
        self._seq_out = (self._seq_out + 1) & 0xFF
        self.link.write(encode(payload))

    def _receive_one(self, timeout):
        """The next decoded device message within ``timeout`` s, or None (handshake use: no streaming yet)."""
        end = time.monotonic() + timeout
        while True:
            if self._queue:
                return self._queue.pop(0)
            left = end - time.monotonic()
            if left <= 0 or not self.link.wait(left):
                return None
            self._take(self.link.read())

    def _take(self, data):
        """Decode the bytes read: SENSORS samples go to ``_pending``, other messages to ``_queue`` or act."""
        corrupt = self._reader.corrupt
        for payload in self._reader.feed(data):
            try:
                seq, message = self._parse(payload)
            except ProtocolError as exc:
                self._reader.corrupt += 1
                if payload[0] == msg.INFO and not self._streaming:  # the handshake refuses it by its field
                    self._queue.append(handshake.BadFrame(str(exc), True))
                continue
            if self._seq_in is not None:
                gap = (seq - self._seq_in - 1) & 0xFF
                self.health["lost"] += gap
            self._seq_in = seq
            if isinstance(message, self.STREAM):
                self._sensors(message)
            elif isinstance(message, msg.Fault):
                self.health["faults"] += 1
                self.device_faults.append((message.code, message.sample, message.detail))
                if message.code in LATCHING:
                    self._device_fault(f"the device reported {msg.FAULT_NAMES.get(message.code, message.code)} "
                                       f"at its sample {message.sample}")
            elif isinstance(message, msg.State):
                self.device_state = message
            elif not self._streaming:
                self._queue.append(message)
        self.health["corrupt"] += self._reader.corrupt - corrupt

    def _sensors(self, frame):
        h = self.health
        h["frames"] += 1
        if frame.flags & msg.FLAG_CLAMPED:
            h["clamped"] += 1
        expected = self._newest + 1
        if self._newest >= 0 and frame.sample > expected:
            h["missing"] += frame.sample - expected
        if frame.sample < expected:
            return  # a repeat of samples already run: never applied twice
        count = len(frame.values)
        self._newest = frame.sample + count - 1
        x, a, v = self.scales.convert(frame.values)
        for i in range(count):
            self._pending.append((frame.sample + i, x[i], a[i], v[i]))

    # streaming ----------------------------------------------------------------
    def _next_sample(self):
        """The next device sample (sample, x, a, v), waiting up to ``SILENCE`` per frame; None on a device fault."""
        if self._pending:
            return self._pending.pop(0)
        self._flush()
        end = time.monotonic() + self.silence
        while self.fault is None:
            try:
                data = self.link.read()
            except (OSError, EOFError) as exc:
                self._link_failed(exc)
                return None
            if data:
                self._read_at = time.perf_counter()
                self.last_data = time.monotonic()
                self._take(data)
                if self._pending:
                    return self._pending.pop(0)
                end = time.monotonic() + self.silence  # bytes came: the link is alive
                continue
            left = end - time.monotonic()
            if left <= 0:
                self._device_fault(f"the link was silent for more than {1e3 * self.silence:g} ms")
                return None
            self.link.wait(left)
        return None

    def _flush(self):
        """Send the forces computed so far as one FORCE frame tagged with their first sample + latency."""
        if not self._forces:
            return
        tag = self._first + self.latency
        if tag <= self._newest_known():
            self.health["late"] += 1
        try:
            for start in range(0, len(self._forces), msg.MAX_FORCES):
                chunk = self._forces[start:start + msg.MAX_FORCES]
                self._send(msg.Force(sample=(tag + start) & 0xFFFFFFFF, forces=tuple(chunk)))  # u32, wraps
        except OSError as exc:
            self._link_failed(exc)
        if self.timing:
            self.turnarounds.append(time.perf_counter() - self._read_at)
        self._forces = []
        self._first = None

    def _newest_known(self):
        return self._newest

    def exchange(self, control, n, out, est_out):
        """The next ``n`` device samples through the loop's controller; zeros without waiting once faulted."""
        h = self.health
        for k in range(n):
            got = self._next_sample() if self.fault is None else None
            if got is None:
                self._forces = []
                return  # the rest of the block stays zero (force 0); the loop latches ``fault``
            sample, x, a, v = got
            if self._first is not None and sample != self._first + len(self._forces):
                self._flush()
            if self._first is None:
                self._first = sample
            self._forces.append(control.sample(k, (x, a, v), None, out, est_out))
            h["samples"] += 1
            if not self._pending or len(self._forces) >= self.packet:
                self._flush()
        self._flush()

    # arming and faults --------------------------------------------------------
    def arm(self, ramp_ms=None):
        """Allow force, ramping up from 0 over ``ramp_ms`` (default the driver's)."""
        if self.fault is None:
            ramp = self.ramp_ms if ramp_ms is None else int(ramp_ms)
            self._guarded(msg.Arm(ramp_ms=max(ramp, self.device_info.ramp_ms_min)))
            self.armed = self.fault is None

    def disarm(self, reason=DISARM_HOST):
        """Force 0 at once on the device, latched there until ``arm``."""
        self.armed = False
        if self.link is not None:
            self._guarded(msg.Disarm(reason=int(reason)), quiet=True)

    def _guarded(self, message, quiet=False):
        try:
            self._send(message)
        except OSError as exc:
            if not quiet:
                self._link_failed(exc)

    def _link_failed(self, exc):
        self.link_lost = True
        self._device_fault(f"the link failed ({_why(exc)})")

    def _device_fault(self, text):
        if self.fault is None:
            self.fault = text
            self.fault_time = time.monotonic()
            self.disarm(DISARM_FAULT)

    def rearm(self, ramp_ms=None):
        """The experimenter's reset after a device fault: reopen the link if it failed (and shake hands again),
        drop the frames that piled up, arm.

        ``ParameterError`` (one line) when the device is still not there; the fault stays latched then.
        """
        reopen = self.fault is not None and self.link_lost
        for _ in range(2):
            if reopen:
                self.close()
                self._open()
                self.link_lost = False
            self.fault = None
            self.resync()
            self.arm(ramp_ms)
            # a link found gone only now (a device restarted while a silence fault held it): reopen it at once,
            # or this Resume would fail and only the next one work (issue 41, item 8)
            reopen = self.fault is not None and self.link_lost
            if not reopen:
                break

    def resync(self):
        """Drop every frame waiting on the link (the host was busy, not answering): the next sample is fresh."""
        self._read_waiting()
        self._pending.clear()
        self._forces = []
        self._first = None

    def _read_waiting(self):
        """Take every byte already waiting on the link, without waiting."""
        while self.fault is None and self.link.wait(0.0):
            try:
                data = self.link.read()
            except (OSError, EOFError) as exc:
                self._link_failed(exc)
                break
            if not data:
                break
            self._take(data)

    def stop_stream(self, timeout=0.2):
        """STOP the stream and wait for the device's STATE (its own counters: late, lost, corrupt); None if none came."""
        self.device_state = None
        self._guarded(msg.Stop(), quiet=True)
        end = time.monotonic() + timeout
        while self.device_state is None and self.fault is None and (left := end - time.monotonic()) > 0:
            if self.link.wait(left):
                try:
                    self._take(self.link.read())
                except (OSError, EOFError) as exc:
                    self._link_failed(exc)
        self._streaming = False
        return self.device_state

    def close(self):
        """STOP the stream (force 0) and close the link."""
        if self.link is None:
            return
        try:
            self._send(msg.Disarm(reason=DISARM_HOST))
            self._send(msg.Stop())
        except OSError:
            pass
        self.link.close()
        self.link = None
        self.armed = False


def _why(exc):
    text = getattr(exc, "strerror", None) or str(exc) or type(exc).__name__
    return text.splitlines()[0]

