"""The device-side safety core: what a firmware does with the host's commands, sample by sample.

A pure state machine over the device's own sample counter ``now`` (u32,
wrapping; comparisons are by the signed difference mod 2^32). Host messages
arrive between samples (``arm``, ``force``, ...); ``actuate()`` gives the
force over [now, now + 1] and advances ``now``. firmware/studyapp_device.c
is the same core in C; the tests hold the two equal.

Force over [j, j + 1], in this order:

1. Not armed, or not streaming: 0. Armed and streaming: the force tagged j
   (a FORCE frame with ``sample + i = j``); before the first tagged force
   since START or ARM, 0 N; a sample with no tagged force (lost, late)
   holds the last one (``missing`` += 1).
2. The ramp on ARM: the k-th sample after ARM (k = 0, 1, ...) is scaled by
   k / R while k < R, R = max(ramp_ms, ramp_ms_min) * rate / 1000 samples.
3. The watchdog: armed, and no feeding host frame by the deadline -> the
   force falls linearly from its last value to 0 over D = ceil(rate / 1000)
   samples (0 at the (D-1)-th sample after the deadline, within 1 ms), then
   the device disarms and reports FAULT WATCHDOG (sample: where the force
   reached 0, detail: the sample at which the last feeding frame arrived);
   latched until ARM. Streaming, only FORCE frames feed it: deadline =
   t_last + W, t_last the latest sample tagged so far, W = watchdog_ms *
   rate / 1000 samples (START feeds it to now + latency + W); not streaming,
   any valid host frame feeds it to now + W; ARM sets it to now + W (+ latency
   while streaming). So from the host's last frame
   (tagged now + latency) the force is 0 within latency + W + D - 1 samples.
4. The motor limits, as the host's loop applies them (model/device.py
   clamp_force): |F| <= impulsive, and <= sustained while the exponential
   mean of F^2 (ms += alpha (F^2 - ms), alpha = 1 - exp(-1 / (rate *
   window))) exceeds sustained^2. Reported as FAULT CLAMP / SUSTAINED at most
   once per second (detail: |command| in mN); neither disarms.

FORCE frames: each force tagged t is stored if now <= t < now + RING, dropped
and counted ``late`` if t < now (FAULT LATE at most once per second, detail:
the late count), dropped and counted ``corrupt`` if t is RING or more ahead.
``LINK_RUN`` corrupt frames in a row while armed disarm the device (FAULT
LINK_CORRUPT). DISARM sets the force to 0 at once.
"""

import math
from dataclasses import dataclass

from studyapp.device import messages

RING = 1024  # tagged forces held ahead, samples
LINK_RUN = 16  # corrupt frames in a row that disarm
MASK = 0xFFFFFFFF


def ahead(a, b):
    """a - b as a signed 32-bit difference of wrapping counters."""
    return ((a - b + 0x80000000) & MASK) - 0x80000000


def ms_samples(ms, rate_hz):
    """``ms`` milliseconds in whole samples (rounded down)."""
    return ms * rate_hz // 1000


@dataclass(frozen=True)
class SafetyConfig:
    """The core's constants, from what the device announces in INFO."""

    rate_hz: int
    impulsive: float
    sustained: float
    rms_alpha: float
    watchdog_ms: int
    ramp_ms_min: int

    @classmethod
    def from_info(cls, info):
        alpha = 1.0 - math.exp(-1.0 / (info.rate_hz * info.sustained_window_s))
        return cls(info.rate_hz, info.impulsive_n, info.sustained_n, alpha, info.watchdog_ms, info.ramp_ms_min)

    @property
    def watchdog_samples(self):
        return max(1, ms_samples(self.watchdog_ms, self.rate_hz))

    @property
    def down_samples(self):
        return max(1, -(-self.rate_hz // 1000))


class DeviceSide:
    """The safety core's state; ``reports`` collects (code, sample, detail) for FAULT frames, oldest first."""

    def __init__(self, config):
        self.c = config
        self.now = 0
        self.armed = False
        self.streaming = False
        self.fault = 0
        self.arm_sample = 0
        self.ramp = 0
        self.start_sample = 0
        self.latency = 0
        self.got = False
        self.hold = 0.0
        self.tags = [0] * RING
        self.values = [0.0] * RING
        self.valid = [False] * RING
        self.deadline = 0
        self.last_feed = 0
        self.down = 0
        self.down_from = 0.0
        self.last_out = 0.0
        self.ms = 0.0
        self.late = 0
        self.corrupt = 0
        self.missing = 0
        self.corrupt_run = 0
        self.clamped = False
        self.ramping = False
        self.sustained_on = False
        self.last_report = {}
        self.reports = []

    def set_counter(self, sample):
        """The counter from ``sample`` on (before START): a device's counter may start anywhere (C: sd_set_counter)."""
        sample &= MASK
        self.now = self.arm_sample = self.start_sample = self.deadline = self.last_feed = sample

    # host messages, arriving before the actuation of sample ``now``

    def _feed(self, until):
        if self.down:  # the watchdog has fired: nothing feeds it until ARM
            return
        if ahead(until, self.deadline) > 0 or not self.armed:
            self.deadline = until & MASK
        self.last_feed = self.now

    def valid_frame(self, message):
        """Any valid host frame: ends a run of corrupt ones; feeds the watchdog when not streaming."""
        self.corrupt_run = 0
        if not self.streaming:
            self._feed(self.now + self.c.watchdog_samples)

    def corrupt_frame(self):
        self.corrupt += 1
        self.corrupt_run += 1
        if self.corrupt_run >= LINK_RUN and self.armed:
            self._disarm(messages.LINK_CORRUPT)
            self.reports.append((messages.LINK_CORRUPT, self.now, self.corrupt_run))

    def arm(self, ramp_ms):
        self.armed = True
        self.fault = 0
        self.down = 0
        self.arm_sample = self.now
        self.ramp = ms_samples(max(ramp_ms, self.c.ramp_ms_min), self.c.rate_hz)
        self.got = False
        self.hold = 0.0
        # streaming, the first forces answer sensor frames sent from now on: latency + W, as at START
        self.deadline = (self.now + self.c.watchdog_samples + (self.latency if self.streaming else 0)) & MASK
        self.last_feed = self.now

    def _disarm(self, fault=0):
        self.armed = False
        self.down = 0
        if fault:
            self.fault = fault

    def disarm(self, reason):
        self._disarm()

    def start(self, packet, latency):
        self.streaming = True
        self.start_sample = self.now
        self.latency = latency
        self.got = False
        self.hold = 0.0
        self.valid = [False] * RING
        self._feed(self.now + latency + self.c.watchdog_samples)

    def stop(self):
        self.streaming = False
        self.got = False
        self.hold = 0.0
        self.valid = [False] * RING

    def force(self, sample, forces):
        if not self.streaming:
            return
        last = None
        for i, f in enumerate(forces):
            t = (sample + i) & MASK
            d = ahead(t, self.now)
            if d < 0:
                self.late += 1
                self._report(messages.LATE, self.late)
            elif d >= RING:
                self.corrupt += 1
            else:
                slot = t % RING
                self.tags[slot] = t
                self.values[slot] = f
                self.valid[slot] = True
                last = t
        if last is not None:
            self._feed(last + self.c.watchdog_samples)

    def _report(self, code, detail):
        """A FAULT that is not latched, at most once per second per code."""
        previous = self.last_report.get(code)
        if previous is None or ahead(self.now, previous) >= self.c.rate_hz:
            self.last_report[code] = self.now
            self.reports.append((code, self.now, detail & MASK))

    def needs_force(self):
        """Streaming and the force for ``now`` is due but not here (lock-step waits on this)."""
        if not self.streaming or ahead(self.now, self.start_sample + self.latency) < 0:
            return False
        slot = self.now % RING
        return not (self.valid[slot] and self.tags[slot] == self.now)

    # one sample

    def actuate(self):
        """The force over [now, now + 1] (N); advances ``now``."""
        j = self.now
        f = 0.0
        if self.armed and self.down == 0 and ahead(j, self.deadline) >= 0:
            self.fault = messages.WATCHDOG
            self.down = self.c.down_samples
            self.down_from = self.last_out
        if self.down > 0:
            self.down -= 1
            f = self.down_from * (self.down / self.c.down_samples)
            if self.down == 0:
                self.armed = False
                self.reports.append((messages.WATCHDOG, j, self.last_feed))
        elif self.armed and self.streaming:
            slot = j % RING
            if self.valid[slot] and self.tags[slot] == j:
                self.valid[slot] = False
                f = self.values[slot]
                self.hold = f
                self.got = True
            elif self.got:
                f = self.hold
                self.missing += 1
            k = ahead(j, self.arm_sample)
            if k < self.ramp:
                f = f * (k / self.ramp)
                self.ramping = True
        f = self._clamp(f)
        self.last_out = f
        self.now = (j + 1) & MASK
        return f

    def _clamp(self, f):
        limit = self.c.impulsive
        sustained = self.ms > self.c.sustained * self.c.sustained
        if sustained:
            limit = self.c.sustained
            if not self.sustained_on:
                self._report(messages.SUSTAINED, _milli(f))
        self.sustained_on = sustained
        if f > limit or f < -limit:
            self._report(messages.CLAMP, _milli(f))
            f = limit if f > limit else -limit
            self.clamped = True
        self.ms += self.c.rms_alpha * (f * f - self.ms)
        return f

    def take_flags(self):
        """SENSORS flags over the samples since the last call (clamped, ramping), and the state now."""
        flags = (messages.FLAG_ARMED if self.armed else 0) | (messages.FLAG_FAULT if self.fault else 0)
        flags |= (messages.FLAG_CLAMPED if self.clamped else 0) | (messages.FLAG_RAMPING if self.ramping else 0)
        self.clamped = False
        self.ramping = False
        return flags


def _milli(f):
    """|f| in mN, as a u32 (saturating)."""
    return int(min(abs(f), 4294967.0) * 1000.0)
