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
    missing   device samples never received (frames lost on the way): the loop skips them
    late      forces sent for a sample the host already knew had passed (the device drops them)
    faults    FAULT frames from the device (WATCHDOG, LINK_CORRUPT, INTERNAL latch; CLAMP, SUSTAINED, LATE count)
    trips     the device's WATCHDOG faults (its force cut because the host's forces came too late)
    silences  the host's silence faults (no valid frame for ``silence`` s)

The device's u32 sample counter is followed by serial-number arithmetic
(sample_counter.py): the host counts unwrapped, so a run across the wrap is
like any other. A device fault is latched when the device reports one (a
latching FAULT), or when the host detects one: the link closes or errors, no
valid frame for ``SILENCE`` while the host waits for one (corrupt frames are
no sign of life), a counter that goes back, jumps further than the device's
clock can run, or a frame of another count than START's packet
(sample_counter.py), or a sensor value that is not finite or physically
impossible (sensor_check.py). Either way ``fault`` is set (its text says
which: "the device reported ..." or "host-detected: ..."; the loop latches it
at the end of the block: force 0 from then on), DISARM(2) then STOP are sent
if the link still takes them, and from then on each block reads what the
device sends (its FAULT and STATE frames; samples dropped) without waiting,
its forces zero. It stays latched until ``rearm()``, which reopens the link if
it has to (a new handshake) or else STARTs the stream again, and arms. A
disarmed device is sent 0 N, never the loop's force.

``info`` is a plain dict (the console, session.json and recordings read it;
names documented in docs/engine.md): name, serial, protocol, firmware, rate,
channels, calibration, limits, latency_samples, packet, round_trip_ms
{median, p99}, link.
"""

import time

from studyapp.device import handshake
from studyapp.device import loop_messages as lm
from studyapp.device import messages as msg
from studyapp.device.errors import ProtocolError
from studyapp.device.frames import FrameReader, encode
from studyapp.device.link_arming import DISARM_EMERGENCY, DISARM_FAULT, DISARM_HOST, Arming  # noqa: F401 (re-exported)
from studyapp.device.link_arming import why as _why
from studyapp.device.link_open import open_link
from studyapp.device.sample_counter import MASK, CounterFault, SampleCounter
from studyapp.device.sensor_check import check as check_sensors
from studyapp.errors import ParameterError
from studyapp.model.device import DeviceLimits, HapticDevice

SILENCE = 0.020  # s without a device frame, while waiting for one, that makes a device fault
LATCHING = (msg.WATCHDOG, msg.LINK_CORRUPT, msg.INTERNAL)
DEFAULT_LATENCY = 5  # samples the host answers ahead (1 ms at 5 kHz)
DEFAULT_PACKET = 1  # samples per sensor frame
DEFAULT_RAMP_MS = 200  # the force ramps up from 0 over this after each ARM
HEALTH = ("frames", "samples", "corrupt", "lost", "missing", "late", "faults", "clamped", "trips", "silences")


class LinkDevice(Arming, HapticDevice):
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
        self.fault_code = None  # the device's FAULT code of a latched device-reported fault; None if host-detected
        self.fault_timing = False  # the latched fault is one of timing (the device's WATCHDOG, the host's silence)
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
            self._pending = []  # decoded SENSORS samples not yet run: (sample unwrapped, x, a, v)
            self._counter = SampleCounter(self.rate, self.packet)
            self._newest = -1  # the newest device sample seen, unwrapped (sample_counter.py)
            self._stopped = False  # STOP sent after a fault: a re-arm STARTs again
            self._skip_partial = False  # bytes were dropped undecoded: the next frame starts after a 0x00
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
            self._counter = SampleCounter(self.rate, self.packet)
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
        """START waits for the host's first use (``_begin``): the device streams from the moment the host reads,
        so nothing piles up in the link while the engine is still being built (a backlog read later costs more
        time than it spans, and the pty drops what does not fit: issue 41's trips at the start)."""
        self._start_pending = True

    def _begin(self):
        if self._start_pending and self.link is not None:
            self._start_pending = False
            self._guarded(msg.Start(packet=self.packet, latency=self.latency))
            self._counter.started()

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
        """Decode the bytes read: SENSORS samples go to ``_pending``, other messages to ``_queue`` or act.
        Returns how many valid frames there were (corrupt ones are no sign of a live device)."""
        if self._skip_partial:
            end = data.find(b"\x00")
            if end < 0:
                return 0
            data, self._skip_partial = data[end + 1:], False
        corrupt = self._reader.corrupt
        valid = 0
        for payload in self._reader.feed(data):
            try:
                seq, message = self._parse(payload)
            except ProtocolError as exc:
                self._reader.corrupt += 1
                if payload[0] == msg.INFO and not self._streaming:  # the handshake refuses it by its field
                    self._queue.append(handshake.BadFrame(str(exc), True))
                continue
            valid += 1
            if self._seq_in is not None:
                gap = (seq - self._seq_in - 1) & 0xFF
                self.health["lost"] += gap
            self._seq_in = seq
            if isinstance(message, self.STREAM):
                self._sensors(message)
            elif isinstance(message, msg.Fault):
                self.health["faults"] += 1
                self.device_faults.append((message.code, message.sample, message.detail))
                if message.code == msg.WATCHDOG and self.fault is None:
                    self.health["trips"] += 1
                if message.code in LATCHING and self.fault is None:
                    self.fault_code = message.code
                    self.fault_timing = message.code == msg.WATCHDOG
                    self._device_fault(f"the device reported {msg.FAULT_NAMES.get(message.code, message.code)} "
                                       f"at its sample {message.sample}")
            elif isinstance(message, msg.State):
                self.device_state = message
            elif not self._streaming:
                self._queue.append(message)
        self.health["corrupt"] += self._reader.corrupt - corrupt
        return valid

    def _follow(self, frame, count, name):
        """The frame's first sample, unwrapped, after the counter's checks (sample_counter.py); None on a fault."""
        try:
            first, missing = self._counter.take(frame.sample, count, name)
        except CounterFault as exc:
            self._host_fault(str(exc))
            return None
        self.health["missing"] += missing
        self._newest = self._counter.newest
        return first

    def _sensors(self, frame):
        if self.fault is not None:
            return  # a faulted stream's samples are read (the device's queue must not back up), never run
        h = self.health
        h["frames"] += 1
        if frame.flags & msg.FLAG_CLAMPED:
            h["clamped"] += 1
        count = len(frame.values)
        first = self._follow(frame, count, "SENSORS")
        if first is None:
            return
        x, a, v = self.scales.convert(frame.values)
        bad = check_sensors(frame.sample, x, a, v)
        if bad is not None:
            self._host_fault(bad)
            return
        for i in range(count):
            self._pending.append((first + i, x[i], a[i], v[i]))

    # streaming ----------------------------------------------------------------
    def _next_sample(self):
        """The next device sample (sample, x, a, v), waiting up to ``silence`` for one; None on a device fault."""
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
                if self._take(data):
                    self.last_data = time.monotonic()
                if self._pending:  # only samples end the wait: corrupt frames, or a stream of other frames, are
                    # no sign of a live stream (a device sending STATE or PONG forever must not wedge the host)
                    return self._pending.pop(0)
                if self.fault is not None:
                    return None
            left = end - time.monotonic()
            if left <= 0:
                self.health["silences"] += 1
                self.fault_timing = True
                self._host_fault(f"no sample from the device for more than {1e3 * self.silence:g} ms "
                                 f"(the link silent, or only corrupt or other frames)")
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
        forces = self._forces if self.armed else [0.0] * len(self._forces)  # a disarmed device is sent 0 N
        try:
            for start in range(0, len(forces), msg.MAX_FORCES):
                chunk = forces[start:start + msg.MAX_FORCES]
                self._send(msg.Force(sample=(tag + start) & MASK, forces=tuple(chunk)))  # u32, wraps
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
        self._begin()
        h = self.health
        if self.fault is not None:
            self._drain()
            return  # zero sensors and force, at once: the loop has latched ``fault``
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
