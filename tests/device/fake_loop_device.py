"""A scripted version 2 device that runs the loop, on a pty, for the host's shadow tests (loop_link.py).

Not the emulator: no mechanics, no clock. Its loop is a ``ClosedLoop`` of the
host's own model (a reference built from the same configuration), stepped
one sample at a time on a given sensor stream with the CONTROLs it receives,
applied at their tagged samples in the order received (docs/device-protocol.md,
"Version 2"). In lock-step, as the emulator's ``--lockstep``: it runs no
further than ALIVE's ``seen`` + START's latency, so the host's CONTROLs are
never late. ``skew = {sample: ulps}`` moves that sample's loop_force by ``ulps``
units in the last place (a device whose loop differs); ``drop = {frame index}``
loses whole TELEMETRY frames (a gap); ``first_sample`` is where its counter
stands when the host opens it (a device that ran for an earlier host). ALIVE
sets ``seen`` and START sets it to the device's sample, as the C core does.
"""

import os
import select
import threading
import time
import tty

import numpy as np

from studyapp.device import frames, messages
from studyapp.device import loop_messages as lm
from studyapp.device.loop_image import image_crc
from studyapp.device.loop_link import IDLE
from studyapp.model import bowed_string
from studyapp.model.control import C_BOWING, C_FORCE_SCALE, C_GAIN, C_SOURCE, OUTPUTS, observe_others
from studyapp.model.device import DeviceLimits, HapticDevice
from studyapp.model.loop import ClosedLoop

KEEPALIVE_MS = 150
A_SP, A_SS, A_BRIDGE = 7, 8, 9  # the string's parameters, state and bridge-side line in the loop's arrays


class Handle(HapticDevice):
    """The reference loop's device: never read (the fake steps the controller itself)."""

    def __init__(self, rate, info):
        self.rate = rate
        self.limits = DeviceLimits(travel=info.travel_m, impulsive=info.impulsive_n, sustained=info.sustained_n,
                                   sustained_window=info.sustained_window_s)


def info_for(config, base, image=None):
    """INFO v2 for a device loop of ``config`` (estimators in the config's order; image: the host's unless given)."""
    reference = ClosedLoop(config, device=Handle(config.rate, base), judge=False)
    crc = image_crc(int(config.rate), reference.control.arrays) if image is None else image
    tail = lm.LoopInfo(lm.DEVICE_LOOP, KEEPALIVE_MS, crc, tuple(int(k) for k in reference.bank.kinds)).pack()
    return messages.Info(**{**base.__dict__, "protocol_version": 2, "loop_tail": tail})


class FakeLoopDevice:
    def __init__(self, config, base, sensors, skew=None, drop=(), image=None, first_sample=0):
        self.info = info_for(config, base, image)
        self.loop = ClosedLoop(config, device=Handle(config.rate, base), judge=False)
        self.sensors = sensors  # (n, 3): x, a, v per sample
        self.skew = dict(skew or {})
        self.drop = set(drop)
        self.master, slave = os.openpty()
        tty.setraw(slave)
        self.path = os.ttyname(slave)
        os.close(slave)
        self.received = []
        self.rows = []  # every row made: (sample, loop force, applied, bridge, control id)
        self.packet = self.latency = None
        self.seen = self.sample = first_sample  # sensors[j] is the row of device sample j
        self.alives = []  # every ALIVE's seen, in order
        self.frames_made = 0
        self.queue = []  # CONTROLs received, not yet in effect
        self.control_id = 0
        self._seq = 0
        self._stop = False
        self._reader = frames.FrameReader()
        ctl = self.loop.control.arrays[0]
        self._write(ctl, IDLE)
        self._out = np.zeros((len(OUTPUTS), 1))
        self._est = np.zeros((len(self.loop.names), 1))
        self._thread = threading.Thread(target=self._serve, daemon=True)
        self._thread.start()

    @staticmethod
    def _write(ctl, setting):
        source, bowing, _, gain, scale = setting
        ctl[C_SOURCE], ctl[C_BOWING], ctl[C_GAIN], ctl[C_FORCE_SCALE] = source, bowing, gain, scale

    def send(self, message):
        payload = message.pack(self._seq, self.info.channels) if isinstance(message, lm.Telemetry) \
            else message.pack(self._seq)
        self._seq = (self._seq + 1) & 0xFF
        os.write(self.master, frames.encode(payload))

    def _serve(self):
        while not self._stop:
            if select.select([self.master], [], [], 0.005)[0]:
                try:
                    data = os.read(self.master, 4096)
                except OSError:
                    time.sleep(0.001)
                    continue
                for payload in self._reader.feed(data):
                    _, message = lm.parse(payload)
                    self.received.append(message)
                    self._act(message)
            self._run()

    def _act(self, message):
        if isinstance(message, messages.Hello):
            self.send(self.info)
        elif isinstance(message, messages.Ping):
            self.send(messages.Pong(nonce=message.nonce, sample=self.sample))
        elif isinstance(message, messages.Start):
            self.packet, self.latency, self.seen = message.packet, message.latency, self.sample
        elif isinstance(message, lm.Alive):
            self.seen = message.seen
            self.alives.append(message.seen)
        elif isinstance(message, lm.Control):
            self.queue.append(message)

    def _run(self):
        """Lock-step: whole packets while they stay within seen + latency."""
        while self.packet and self.sample + self.packet <= min(self.seen + self.latency, len(self.sensors)):
            rows = [self._step() for _ in range(self.packet)]
            first = self.sample - self.packet
            if self.frames_made not in self.drop:
                self.send(lm.Telemetry(first, lm.FLAG_ARMED, tuple(rows)))
            self.frames_made += 1

    def _step(self):
        j = self.sample
        arrays = self.loop.control.arrays
        due = [c for c in self.queue if c.sample <= j]
        for c in due:
            self.queue.remove(c)
            if c.reset:
                self.loop._rest()
            self._write(arrays[0], (c.source, c.bowing, c.reset, c.gain, c.force_scale))
            self.control_id = c.id
        x, a, v = self.sensors[j]
        bridge = bowed_string.read_line(arrays[A_BRIDGE], int(arrays[A_SS][bowed_string.S_WRITE]),
                                        arrays[A_SP][bowed_string.P_DB])
        force = self.loop.control.sample(0, (x, a, v), None, self._out, self._est)
        # every estimator steps every sample, as on the device: a source switched to is warm
        observe_others(int(arrays[0][C_SOURCE]), arrays[4], arrays[5], arrays[6], self._out, self._est)
        if j in self.skew:
            force = float(np.nextafter(force, np.inf)) if self.skew[j] > 0 else float(np.nextafter(force, -np.inf))
        self.rows.append((j, force, force, bridge, self.control_id))
        self.sample += 1
        return (x, a, v, force, force, bridge, self.control_id)

    def close(self):
        if not self._stop:
            self._stop = True
            self._thread.join(1.0)
            os.close(self.master)
