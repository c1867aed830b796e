"""The host's driver for a device that runs the loop itself (protocol version 2): a telemetry source with a shadow.

Protocol: docs/device-protocol.md, "Version 2: the loop on the device". The
paper ran its loop on the device's own board (Sec. 8.4), so the force for
sample k came from the sensors of sample k: F[k] = clamp(-G u(v_src[k]) g),
G = F_max / max|rho(v) v| (eqs. 1, 2 and 20), with no link in between. Such a
device streams TELEMETRY rows (its sensors, the loop's force, the force it
applied, the bridge velocity, the id of the CONTROL in effect); the host:

- checks at the first block that INFO's parameter image CRC is its own
  loop's (loop_image.py: its estimators, Table 1's numbers at the rate,
  the string, the motor limits); a device whose loop computes with other numbers is
  refused with one line (a device fault before any force);
- sends CONTROL (the loop's settings: source, bowing, gain = F_max / peak,
  force scale, a string reset) whenever the loop's settings changed since the
  last block, tagged ``lead`` samples past the newest sample seen (the knob
  reaches the device within lead / rate plus one block), and ALIVE (the
  keep-alive, with the samples read) whenever it waits for telemetry, and
  every ms while it catches up on rows that waited (after a stall);
- runs the **shadow** (shadow.py, one compiled call per setting): the loop's
  own controller (model/control.py ``sample``, with the loop's arrays) on
  each streamed sensor row, every estimator stepped on it, each
  CONTROL applied at the row whose control id first names it, exactly as the
  device did. The shadow's force must equal the row's loop_force, and the
  bridge velocity the shadow's string reads the row's bridge (``tolerance``,
  0 by default: the same C and numba arithmetic, docs/device-protocol.md); a
  difference is a device fault naming the sample. So the audio the loop plays
  (the body filter of the bridge velocity) is the device's string, and the
  scope's other estimators (stepped on the same rows) are the device's;
- records the force the device **applied** (after its arming, ramp and
  clamps) in the loop's force row: what the session logs is what acted.

Link loss or a host stall: the device keeps its loop (its own watchdog on the
keep-alive disarms it if the host stays away); the host finds the rows
waiting and runs them late (a gap in the scope, never a stale force: it sends
none). Device samples that never arrive are counted (``missing``, ``gaps``):
the shadow cannot follow the device across them, so from then on it is no
longer compared (``unchecked`` counts the rows); nor after a reopen of a
failed link. The shadow starts as built, as the device's loop does at this
host's START (the protocol's sl_reset); a device that kept its loop's state
from an earlier host's stream would differ at once: a device fault.

``health`` (cumulative): version 1's counts, plus ``gaps`` (telemetry gaps),
``force_gaps`` (rows armed, past the ramp, with a loop force but none applied),
``unchecked``, ``controls`` (CONTROL frames sent); ``control_delays`` keeps,
per CONTROL, (device samples from the newest seen when it was sent to the row
that first named it, host seconds from sending to reading that row).
"""

import math
import time
from collections import deque

import numpy as np

from studyapp.device import handshake
from studyapp.device import loop_messages as lm
from studyapp.device import shadow
from studyapp.device.link_device import LinkDevice
from studyapp.device.loop_image import image_crc
from studyapp.device.sample_counter import MASK
from studyapp.device.sensor_check import check as check_sensors
from studyapp.errors import ParameterError
from studyapp.model.control import C_BOWING, C_FORCE_SCALE, C_GAIN, C_SOURCE

DEFAULT_PACKET = 10  # rows per TELEMETRY frame (2 ms at 5 kHz)
LEAD_MS = 4.0  # a CONTROL acts this far past the newest sample seen (the knob reaches the device within 10 ms)
ALIVE_EVERY = 0.001  # s: ALIVE after a read at most this often (it is also sent whenever the host waits)
DELAYS_KEPT = 100_000
EXTRA_HEALTH = ("gaps", "force_gaps", "unchecked", "controls")
A_CTL = 0  # the control vector's place in the loop's arrays (control.Control.arrays)
IDLE = (lm.SOURCE_VELOCITY_SENSOR, 0, 0, 0.0, 1.0)  # before the first CONTROL: the bow lifted, gain 0


def default_lead(rate, packet):
    return max(int(packet), round(LEAD_MS * rate / 1000.0))


def settings_of(ctl):
    """The CONTROL fields (source, bowing, gain, force scale) of the loop's control vector."""
    return int(ctl[C_SOURCE]), int(ctl[C_BOWING] != 0.0), float(ctl[C_GAIN]), float(ctl[C_FORCE_SCALE])


class LoopLink(LinkDevice):
    """A version 2 device on ``spec`` that runs the loop; the host shadows it (see the module's text).

    ``packet``: rows per TELEMETRY frame; ``lead``: samples past the newest seen at which a CONTROL acts
    (default ``LEAD_MS``; in the emulator's lock-step, the device never runs further than this past the
    host's ALIVE); ``tolerance``: the largest |shadow - device| (N, string units) that is no fault.
    The rest as ``LinkDevice``; ``silence`` is at least the device's keep-alive watchdog.
    """

    STREAM = lm.Telemetry
    runs_loop = True  # the loop (model/loop.py) defers a string reset to the device's sample
    steps_every_estimator = True  # the shadow steps every estimator per row: the loop does not again

    def __init__(self, spec, rate, *, packet=DEFAULT_PACKET, lead=None, tolerance=0.0, **options):
        packet = handshake.check_packet(packet)
        self.lead = handshake.check_latency(default_lead(rate, packet) if lead is None else lead)
        if not (np.isfinite(tolerance) and tolerance >= 0.0):
            raise ParameterError(f"device tolerance = {tolerance!r}: allowed is a finite number >= 0")
        self.tolerance = float(tolerance)
        self.loop_info = None
        self.control_delays = deque(maxlen=DELAYS_KEPT)
        self._arrays = None
        self._reset_pending = None  # the loop's string reset, waiting for its CONTROL
        super().__init__(spec, rate, latency=self.lead, packet=packet, **options)

    # the link -----------------------------------------------------------------
    def _open(self):
        self._rows = deque()  # (sample, x, a, v, loop force, applied, bridge, control id)
        self._sent = {}  # id -> (setting, reset callback, tag, newest seen when sent, perf_counter when sent)
        self._last_id = 0
        self._last_setting = None
        self._effect = IDLE
        self._effect_id = 0
        self._alive_seen = 0
        self._steady = False
        self._serviced = 0.0
        self._shadow_values = np.zeros(2)  # the shadow's force and bridge velocity at a row that differed
        self._alive_at = 0.0
        # a reopen (a re-arm after the link failed): the device's loop ran on through rows the host never read,
        # so the shadow can no longer follow it
        # the first device sample the shadow can no longer follow: none yet (inf) on a first open; on a reopen
        # (a re-arm after the link failed) every one, the device's loop having run on through rows never read
        self._unsynced_from = math.inf if self._arrays is None else -1
        self._image_checked = False
        super()._open()
        self.health.update({key: self.health.get(key, 0) for key in EXTRA_HEALTH})
        self.silence = max(self.silence, self.loop_info.keepalive_ms / 1000.0)
        self._alive_period = self.loop_info.keepalive_ms / 4000.0  # s: the protocol's longest gap between ALIVEs

    def _check_loop(self, loop):
        if loop.loop != lm.DEVICE_LOOP:
            raise ParameterError(f"device at {self.spec}: it does not run the loop (INFO.loop = {loop.loop}); "
                                 "the host's loop drives it (studyapp/device/link_device.py); refused")
        self.loop_info = loop

    @property
    def info(self):
        info = super().info
        info.update({"loop": "device", "keepalive_ms": self.loop_info.keepalive_ms, "lead_samples": self.lead,
                     "latency_samples": 0, "latency_ms": 0.0, "image": f"{self.loop_info.image:08x}"})
        return info

    def _parse(self, payload):
        return lm.parse(payload, self._channels)

    def _sensors(self, frame):
        """A TELEMETRY frame: its rows to ``_rows`` (samples unwrapped; a gap counted; a counter or a sensor an
        honest device cannot send is a fault, as in ``LinkDevice``)."""
        if self.fault is not None:
            return
        h = self.health
        h["frames"] += 1
        flags = frame.flags
        if flags & lm.FLAG_CLAMPED:
            h["clamped"] += 1
        count = len(frame.rows)
        newest = self._newest
        first = self._follow(frame, count, "TELEMETRY")
        if first is None:
            return
        if newest >= 0 and first > newest + 1:
            h["gaps"] += 1
            self._unsynced_from = min(self._unsynced_from, newest + 1)  # rows before the gap still compare
        width = len(self._channels)
        x, a, v = self.scales.convert([r[:width] for r in frame.rows])
        bad = check_sensors(frame.sample, x, a, v)
        if bad is not None:
            self._host_fault(bad)
            return
        # a packet's flags are the device's state at its end: a force gap is counted only inside a run of
        # steady packets (an ARM or a DISARM within a packet is no gap)
        now_steady = bool(flags & lm.FLAG_ARMED) and not flags & (lm.FLAG_RAMPING | lm.FLAG_FAULT)
        steady, self._steady = now_steady and self._steady, now_steady
        for i, r in enumerate(frame.rows):
            loop_force, applied, bridge, cid = r[width:]
            if steady and applied == 0.0 and loop_force != 0.0:
                h["force_gaps"] += 1
            self._rows.append((first + i, x[i], a[i], v[i], loop_force, applied, bridge, cid))

    def _service(self):
        """While catching up on waiting rows (after a stall), still read the link and send ALIVE every ms: the
        device's keep-alive is fed and its telemetry does not pile up in the link until it drops some."""
        now = time.perf_counter()
        if now - self._serviced >= ALIVE_EVERY:
            self._serviced = now
            self._read_waiting()
            self._alive()

    def _alive(self, force=False):
        """ALIVE(seen) when the host has read further since the last one (at most every ms unless ``force``),
        and at least every keepalive_ms / 4 even when it has not (a device that paused and then runs its
        samples fast, as an emulator catching up, must still hear from the host within its watchdog). None before
        the first TELEMETRY since START: until then the host has no sample of this run to name, and a seen from
        before it (0 on a new host, the last run's on a restart) would hold a lock-step device behind its own
        START for good (START fed its watchdog and set its seen)."""
        if self._counter.fresh:
            return
        seen = self._newest + 1
        now = time.perf_counter()
        due = now - self._alive_at >= self._alive_period
        if due or (seen > self._alive_seen and (force or now - self._alive_at >= ALIVE_EVERY)):
            self._guarded(lm.Alive(seen=seen & 0xFFFFFFFF))
            self._alive_seen, self._alive_at = seen, now

    def _next_row(self):
        """The next telemetry row, waiting up to ``silence`` per frame; None on a device fault."""
        return self._rows.popleft() if self._wait_rows() else None

    def _wait_rows(self):
        """True once a row is waiting (reading the link, ALIVE while waiting); False on a device fault."""
        if self._rows:
            return True
        end = time.monotonic() + self.silence
        while self.fault is None:
            self._alive(force=True)
            try:
                data = self.link.read()
            except (OSError, EOFError) as exc:
                self._link_failed(exc)
                return False
            if data:
                if self._take(data):
                    self.last_data = time.monotonic()
                if self._rows:  # only rows end the wait (as LinkDevice._next_sample)
                    self._alive()
                    return True
                if self.fault is not None:
                    return False
            left = end - time.monotonic()
            if left <= 0:
                self.health["silences"] += 1
                self.fault_timing = True
                self._host_fault(f"no sample from the device for more than {1e3 * self.silence:g} ms "
                                 f"(the link silent, or only corrupt or other frames)")
                return False
            self.link.wait(min(left, self._alive_period))
        return False

    # settings -----------------------------------------------------------------
    def defer_reset(self, rest):
        """The loop's string reset (``rest()`` puts it at rest): sent as a CONTROL, run at the device's sample."""
        self._reset_pending = rest

    def _send_control(self, setting):
        self._read_waiting()  # tag from the newest sample there is, not from where the host last stopped reading
        rest, self._reset_pending = self._reset_pending, None
        self._last_id = self._last_id % 0xFFFF + 1
        seen = self._newest + 1
        tag = seen + self.lead
        source, bowing, gain, scale = setting
        message = lm.Control(id=self._last_id, sample=tag & 0xFFFFFFFF, source=source, bowing=bowing,
                             reset=int(rest is not None), gain=gain, force_scale=scale)
        self._sent[self._last_id] = ((source, bowing, int(rest is not None), gain, scale), rest, tag, self._newest,
                                     time.perf_counter())
        self._last_setting = setting
        self.health["controls"] += 1
        self._guarded(message)

    def _apply(self, cid, sample, ctl):
        """The CONTROL ``cid`` takes effect at ``sample`` in the shadow, as it did on the device.

        The device applies at sample j, in the order sent, every CONTROL tagged j or earlier; its row names
        the last. So every CONTROL sent before ``cid`` and not yet named took effect here too (its reset
        included), superseded at once.
        """
        if cid not in self._sent:
            self._host_fault(f"the device's sample {sample & MASK} runs CONTROL {cid}, which this host never sent")
            return False
        now = time.perf_counter()
        for i in list(self._sent):
            setting, rest, tag, newest, at = self._sent.pop(i)
            if sample > tag:
                self.health["late"] += 1
            self.control_delays.append((sample - newest, now - at))
            if rest is not None:
                rest()
            if i == cid:
                break
        self._effect, self._effect_id = setting, cid
        self._write(ctl, setting)
        return True

    @staticmethod
    def _write(ctl, setting):
        source, bowing, _, gain, scale = setting
        ctl[C_SOURCE], ctl[C_BOWING], ctl[C_GAIN], ctl[C_FORCE_SCALE] = source, bowing, gain, scale

    def _check_image(self, arrays):
        self._image_checked = True
        crc = image_crc(int(self.rate), arrays)
        if crc != self.loop_info.image:
            self._host_fault(f"its loop's parameters are not the host's (image CRC {self.loop_info.image:08x}, "
                               f"the host's {crc:08x}); refused")

    # the loop's block ---------------------------------------------------------
    def exchange(self, control, n, out, est_out):
        """The next ``n`` telemetry rows through the shadow; the rest of the block zero once faulted."""
        self._begin()
        arrays = control.arrays
        self._arrays = arrays
        ctl = arrays[A_CTL]
        if not self._image_checked and self.fault is None:
            self._check_image(arrays)
        wanted = ctl.copy()
        setting = settings_of(ctl)
        if self.fault is None and (setting != self._last_setting or self._reset_pending is not None) \
                and (self._newest >= 0 or self._wait_rows()):  # tagged from a sample seen, never a guess
            self._send_control(setting)
        self._write(ctl, self._effect)
        try:
            self._run(control, n, out, est_out, ctl)
        finally:
            ctl[:] = wanted

    def _run(self, control, n, out, est_out, ctl):
        if self.fault is not None:
            self._drain()
            return
        rows = []
        while len(rows) < n and self.fault is None:
            row = self._next_row()
            if row is None:
                break
            rows.append(row)
            if len(rows) % self.packet == 0:
                self._service()
        if not rows:
            return
        table = np.array(rows, dtype=np.float64)
        controls = table[:, shadow.R_CONTROL]
        h = self.health
        start = 0
        while start < len(rows):
            cid = int(controls[start])
            if cid != self._effect_id and not self._apply(cid, int(table[start, shadow.R_SAMPLE]), ctl):
                return
            changes = np.flatnonzero(controls[start:] != cid)
            end = start + int(changes[0]) if changes.size else len(rows)
            first = table[start, shadow.R_SAMPLE]
            synced = bool(first < self._unsynced_from)
            if synced and table[end - 1, shadow.R_SAMPLE] >= self._unsynced_from:
                end = start + int(self._unsynced_from - first)  # a segment never straddles a gap
            bad = shadow.run_rows(control.arrays, start, table[start:end], self.tolerance,
                                  shadow.CHECK if synced else shadow.TRUST, out,
                                  est_out, self._shadow_values)
            done = end - start if bad < 0 else bad + 1
            h["samples"] += done
            if not synced:
                h["unchecked"] += done
            if bad >= 0:
                row = [float(v) for v in table[start + bad]]
                force, bridge = (float(v) for v in self._shadow_values)
                self._host_fault(
                    f"the device's loop differs from the host's shadow at its sample "
                    f"{int(row[shadow.R_SAMPLE]) & MASK}: "
                    f"force {row[shadow.R_LOOP_FORCE]!r} N (shadow {force!r}), bridge {row[shadow.R_BRIDGE]!r} "
                    f"(shadow {bridge!r})")
                return
            start = end

    def _restarted(self):
        """The stream STARTs again after a fault's STOP: the device's loop starts as built (sl_reset) with its
        CONTROL queue empty, so the shadow, which kept its state, is no longer compared (as after a reopen)."""
        self._rows.clear()
        self._sent.clear()
        self._last_setting = None
        self._effect, self._effect_id = IDLE, 0
        self._steady = False
        self._unsynced_from = -1

    def resync(self):
        """Rows waiting are kept (the shadow must run every row the device ran); only the link's bytes are read."""
        self._begin()
        self._read_waiting()

