"""The device emulator: the simulated device behind the protocol, on a pty, in its own process.

``Emulator(config).run()`` opens a pty link (pty_link.py), prints
``ready: PATH`` on stdout once the link exists, and runs a device there:
the simulated device's mechanics, sensors and virtual hand
(model/simulated_device.py, read sample by sample through ``read_sensors`` /
``write_force``, the hand following ``make_gesture(gesture)`` as
model/loop.py has it), and a firmware core (firmware.py, or the C core of
firmware/studyapp_device.c through c_core.py) that speaks the protocol and
enforces the device-side safety (device_side.py). Per sample k: the host's
bytes that have arrived go in, the sensors are read and given to the core,
the core's force acts over [k, k+1], its frames go out.

Clock: by default the emulator owns the sample clock, sample k due at
t0 + k / rate on ``time.perf_counter`` (wait: sleep, or ``select`` on the
link so a host's frame wakes it, then spin the last ``SPIN`` s while armed or
streaming; a sample that is already due runs at once, so a descheduled
emulator catches up and never skips one). With ``lockstep`` it has no clock:
it advances only while streaming and, before moving over [j, j+1], waits for
the force tagged j (from START's sample + latency on; the samples before get
0 N), so a host's loop over the pty equals the simulated loop with that fixed
latency sample for sample.

The loop (``loop``): ``host`` (the default) is protocol version 1's, the
host's FORCE frames applied at their tags. ``device`` is version 2's loop on
the device (docs/device-protocol.md, "Version 2"): INFO says loop = 1 with
the keep-alive watchdog (``keepalive_ms``), the parameter image's CRC
(loop_image.py) and the estimators of loop_bank.py (the study's
position-only ones, and the accelerometer's), and per sample the C core runs
the C loop on the simulated sensors (c_loop_core.py: CONTROL settings at
their tags, the loop, the unchanged safety core on its force, TELEMETRY).
Its lock-step has the device run sample j only once j < ALIVE's seen +
START's latency, so a host that tags its CONTROL at seen + latency is never
late and the loop equals the model's at no latency, sample for sample.

The link's faults (link_faults.py, seeded): ``latency`` and ``jitter`` delay
what the device receives; ``loss`` and ``corrupt`` drop frames or flip a bit
of them, both ways; ``disconnect_after`` closes the link after that many
seconds (of the device's clock; of wall time in lock-step). ``first_sample``
starts the device's u32 sample counter there (the wrap past 2^32 in a test's seconds).

SIGTERM, SIGINT and SIGHUP end it: the link is removed on every exit. At the
end one line on stdout: ``stats: {json}`` (samples, the core's counters, the
link's lost and flipped frames each way, frames dropped because the host did not read).
"""

import json
import select
import signal
import sys
import time
from dataclasses import dataclass

from studyapp.device import loop_messages, messages
from studyapp.device.firmware import Firmware
from studyapp.device.link_faults import LinkFaults
from studyapp.device.pty_link import PtyLink
from studyapp.errors import UserError

SPIN = 0.0003  # s of busy wait before a sample is due, while armed or streaming
IDLE_TICK = 0.001  # s: the longest sleep while idle (a host's frame wakes it sooner)
GESTURES = ("strokes", "hold")
FORMATS = ("f64", "counts")
CORES = ("auto", "c", "python")
LOOPS = ("host", "device")
KEEPALIVE_MS = 200
MAX_PACKET = 32
FIRMWARE_VERSION = (1, 0)
# --format counts: what a firmware with ADCs would send; SI = gain * raw
COUNT_CHANNELS = (messages.Channel(messages.POSITION, messages.I32, 1e-9, 0.0),
                  messages.Channel(messages.ACCELERATION, messages.I32, 1e-6, 0.0),
                  messages.Channel(messages.VELOCITY, messages.I32, 1e-8, 0.0))
I32 = (-(1 << 31), (1 << 31) - 1)


@dataclass(frozen=True)
class EmulatorConfig:
    link: str
    rate: int = 5000
    seed: int = 0
    gesture: str = "strokes"
    latency: float = 0.0
    jitter: float = 0.0
    loss: float = 0.0
    corrupt: float = 0.0
    disconnect_after: float | None = None
    lockstep: bool = False
    format: str = "f64"
    core: str = "auto"
    watchdog_ms: int = 1
    loop: str = "host"
    keepalive_ms: int = KEEPALIVE_MS
    first_sample: int = 0  # where the device's u32 sample counter starts (near 2^32: it wraps while streaming)


def device_info(config, loop=None):
    """The emulator's INFO: the simulated device's limits (model/limits.py), its rate, watchdog and channels;
    with ``loop`` (loop_bank.device_loop's) version 2's loop section for a device loop."""
    from studyapp.model.device import DeviceLimits
    limits = DeviceLimits()
    channels = COUNT_CHANNELS if config.format == "counts" else messages.SI_CHANNELS
    version, largest, tail = messages.PROTOCOL_VERSION, MAX_PACKET, b""
    if loop is not None:
        from studyapp.device.loop_image import image_crc
        version, largest = loop_messages.LOOP_VERSION, min(MAX_PACKET, loop_messages.max_telemetry_packet(channels))
        tail = loop_messages.LoopInfo(loop_messages.DEVICE_LOOP, int(config.keepalive_ms),
                                      image_crc(int(config.rate), loop.control.arrays),
                                      tuple(int(k) for k in loop.bank.kinds)).pack()
    return messages.Info(version, *FIRMWARE_VERSION, int(config.rate), largest,
                         "studyapp emulator", f"EMU-{config.seed:04d}", limits.travel, limits.impulsive,
                         limits.sustained, limits.sustained_window, int(config.watchdog_ms), 0, channels, tail)


def make_core(kind, info):
    """(core, name): the C core if asked for, or if ``auto`` and it builds; else the Python one."""
    if kind in ("auto", "c"):
        from studyapp.device import c_core
        try:
            return c_core.CCore(info), "c"
        except c_core.BuildError as exc:
            if kind == "c":
                raise UserError(f"--core c: {exc}") from None
            print(f"studyapp device-emulator: no C core ({exc}); the Python core runs", file=sys.stderr)
    return Firmware(info), "python"


def make_loop_core(info, loop):
    """The C core with the C loop on ``loop``'s arrays attached: a device loop has no Python core."""
    from studyapp.device import c_core, c_loop, c_loop_core
    try:
        return c_loop_core.CLoopCore(info, c_loop.CLoop(loop.control.arrays)), "c"
    except c_core.BuildError as exc:
        raise UserError(f"--loop device: {exc}") from None


def raw_row(channels, x, a, v):
    values = (x, a, v)
    if channels[0].format == messages.F64:
        return values
    return tuple(min(max(round(s / c.gain), I32[0]), I32[1]) for c, s in zip(channels, values))


class Emulator:
    def __init__(self, config):
        from studyapp.model.loop import make_gesture
        from studyapp.model.simulated_device import SimulatedDevice
        self.config = config
        self.device_loop = config.loop == "device"
        if self.device_loop:
            from studyapp.device.loop_bank import device_loop
            self.loop = device_loop(config.rate, accelerometer=True)  # the emulator has an accelerometer channel
            self.info = device_info(config, self.loop)
            self.core, self.core_name = make_loop_core(self.info, self.loop)
        else:
            self.info = device_info(config)
            self.core, self.core_name = make_core(config.core, self.info)
        self.core.set_counter(config.first_sample)
        warm = SimulatedDevice(config.rate)  # loads the compiled per-sample path before the link is ready
        warm.read_sensors()
        warm.write_force(0.0)
        self.device = SimulatedDevice(config.rate, seed=config.seed)
        self.device.follow(make_gesture(config.gesture, config.rate))
        self.faults = LinkFaults(config.seed, config.latency, config.jitter, config.loss, config.corrupt)
        self.link = None
        self.samples = 0
        self._stop = False

    def _on_signal(self, signum, frame):
        self._stop = True

    def run(self, out=sys.stdout):
        handled = (signal.SIGTERM, signal.SIGINT, signal.SIGHUP)
        previous = {s: signal.signal(s, self._on_signal) for s in handled}
        self.link = PtyLink(self.config.link)
        try:
            self.link.open()
            print(f"ready: {self.link.path}", file=out, flush=True)
            print(f"studyapp device-emulator: {self.link.path} -> {self.link.name}, {self.config.rate} Hz, "
                  f"{self.core_name} core, loop on the {self.config.loop}"
                  f"{', lock-step' if self.config.lockstep else ''}", file=sys.stderr)
            if self.config.lockstep:
                self._lockstep()
            else:
                self._clocked()
        finally:
            self.link.close()
            for s, h in previous.items():
                signal.signal(s, h)
        print("stats: " + json.dumps(self.stats()), file=out, flush=True)
        return 0

    def stats(self):
        return {"samples": self.samples, "core": self.core_name, "loop": self.config.loop, **self.core.counters(),
                "link_lost_in": self.faults.lost["in"], "link_lost_out": self.faults.lost["out"],
                "link_flipped_in": self.faults.flipped["in"], "link_flipped_out": self.faults.flipped["out"],
                "tx_dropped": self.link.dropped}

    def _sense_and_actuate(self):
        x, a, v = self.device.read_sensors()
        self.core.sample(raw_row(self.info.channels, x, a, v))
        self.link.write(self.faults.outgoing(self.core.tx()))
        self._actuate()

    def _actuate(self):
        self.device.write_force(self.core.actuate())
        self.link.write(self.faults.outgoing(self.core.tx()))
        self.samples += 1

    def _receive(self):
        self.faults.incoming(self.link.read(), time.perf_counter())
        data = self.faults.due(time.perf_counter())
        if data:
            self.core.rx(data)

    def _wait(self, target):
        busy = self.core.busy()
        while not self._stop:
            remaining = target - time.perf_counter()
            if remaining <= 0.0:
                return
            if busy and remaining <= SPIN:
                while time.perf_counter() < target:
                    pass
                return
            timeout = remaining - SPIN if busy else max(remaining, IDLE_TICK)
            writers = [self.link.master] if self.link.pending else []
            readable, writable, _ = select.select([self.link.master], writers, [], timeout)
            if writable:
                self.link.write(b"")
            if readable:
                self.faults.incoming(self.link.read(), time.perf_counter())
                busy = True

    def _clocked(self):
        period = 1.0 / self.config.rate
        end = self.config.disconnect_after
        t0 = time.perf_counter()
        k = 0
        while not self._stop:
            if end is not None and k * period >= end:
                return
            self._wait(t0 + k * period)
            if self._stop:
                return
            self._receive()
            self._sense_and_actuate()
            k += 1

    def _block(self, timeout=0.05):
        writers = [self.link.master] if self.link.pending else []
        readable, writable, _ = select.select([self.link.master], writers, [], timeout)
        if writable:
            self.link.write(b"")
        if readable:
            data = self.link.read()
            if data:
                self.core.rx(data)
                self.link.write(self.core.tx())

    def _lockstep(self):
        end = self.config.disconnect_after
        t0 = time.perf_counter()
        while not self._stop:
            if end is not None and time.perf_counter() - t0 >= end:
                return
            if not self.core.streaming():
                self._block()
                continue
            if self.device_loop:
                self._lockstep_device_loop()
                continue
            x, a, v = self.device.read_sensors()
            self.core.sample(raw_row(self.info.channels, x, a, v))
            self.link.write(self.core.tx())
            while self.core.needs_force() and not self._stop:
                self._block()
            if self._stop:  # the host's last frames may still be unread: a device asked to stop does not move
                return
            self._actuate()

    def _lockstep_device_loop(self):
        """One sample of a device loop once the host's ALIVE lets it run (sample j < seen + latency)."""
        while self.core.needs_alive() and not self._stop:
            self._block()
        if self.core.streaming() and not self._stop:
            self._sense_and_actuate()
