"""A link device's arming, its faults and what the host does on each (docs/device-protocol.md, "What the host
does on a fault"): the ``Arming`` half of ``LinkDevice`` (link_device.py), which holds the link and the stream.

ARM with the driver's ramp; DISARM(0) on the host's request, (1) the emergency stop, (2) a fault. A fault, the
device's (a latching FAULT frame) or the host's own (the link failed or fell silent, a counter or a sensor an
honest device cannot send), is latched once: DISARM(2), then STOP so that the device's stream does not pile up in
the link, and from then on each block takes what the device sends without waiting (``_drain``). ``rearm`` (the
experimenter's act; ``studyapp live``'s after a trip of timing, engine/device_link.py) reopens a failed link (a new
handshake) or STARTs the stream again, drops the backlog and arms.
"""

import time

from studyapp.device import messages as msg
from studyapp.device.frames import FrameReader

DISARM_HOST, DISARM_EMERGENCY, DISARM_FAULT = msg.HOST_REQUEST, msg.EMERGENCY_STOP, msg.HOST_FAULT
DRAIN_READS = 64  # reads at most per block while faulted: what the device sent is taken, never waited for


class Arming:
    """Arming, disarming, faults and the re-arm, over ``LinkDevice``'s link (``_send``, ``_take``, ``_begin``)."""

    def arm(self, ramp_ms=None):
        """Allow force, ramping up from 0 over ``ramp_ms`` (default the driver's)."""
        self._begin()
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
        self._host_fault(f"the link failed ({why(exc)})")

    def _host_fault(self, text):
        """A fault the host detected itself (not the device's FAULT frame)."""
        self._device_fault(f"host-detected: {text}")

    def _device_fault(self, text):
        """Latch ``text``; DISARM(2), then STOP so that the device's stream does not pile up in the link."""
        if self.fault is None:
            self.fault = text
            self.fault_time = time.monotonic()
            self._forces = []
            self._pending.clear()
            self.disarm(DISARM_FAULT)
            if self.link is not None and not self.link_lost:
                self._guarded(msg.Stop(), quiet=True)
                self._stopped = True

    def _drain(self):
        """While faulted: take what the device sent (its FAULT and STATE frames; samples are dropped), without
        waiting, so that a device whose writes block never stalls on the host."""
        for _ in range(DRAIN_READS):
            if self.link is None or self.link_lost or not self.link.wait(0.0):
                return
            try:
                data = self.link.read()
            except (OSError, EOFError):
                self.link_lost = True
                return
            if not data:
                return
            self._take(data)

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
                self._stopped = False
            self.fault = None
            self.fault_code = None
            self.fault_timing = False
            self.resync()
            if self._stopped:  # STOPped at the fault: the stream starts again (``arm`` sends START)
                self._stopped = False
                self._restarted()
                self._start()
            self.arm(ramp_ms)
            # a link found gone only now (a device restarted while a silence fault held it): reopen it at once,
            # or this Resume would fail and only the next one work (issue 41, item 8)
            reopen = self.fault is not None and self.link_lost
            if not reopen:
                break

    def _restarted(self):
        """The stream is about to START again on the open link (after a fault's STOP)."""

    def resync(self):
        """Drop every byte waiting on the link undecoded (the host was busy, not answering: decoding the backlog
        frame by frame would take longer than the time it spans): the next sample is fresh."""
        self._begin()
        for _ in range(DRAIN_READS * 16):
            data = self._read_chunk()
            if data is None:
                break
            self._reader = FrameReader()
            self._skip_partial = not data.endswith(b"\x00")
            self._counter.started()  # samples dropped on purpose: the next frame may be any distance ahead
        self._pending.clear()
        self._forces = []
        self._first = None

    def _read_waiting(self):
        """Take every byte already waiting on the link, without waiting."""
        while (data := self._read_chunk()) is not None:
            self._take(data)

    def _read_chunk(self):
        """One read of the bytes waiting on the link; None when none wait, the link failed or a fault holds."""
        if self.fault is not None or not self.link.wait(0.0):
            return None
        try:
            data = self.link.read()
        except (OSError, EOFError) as exc:
            self._link_failed(exc)
            return None
        return data or None

    def stop_stream(self, timeout=0.2):
        """STOP the stream and wait for the device's STATE (its own counters: late, lost, corrupt); None if none
        came."""
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


def why(exc):
    text = getattr(exc, "strerror", None) or str(exc) or type(exc).__name__
    return text.splitlines()[0]

