"""The worker's block clock, and what it counts: deadline misses, overruns, stalls, late wake-ups, loads.

Block k of B samples at rate R (period T = B / R) starts when the pacing
clock says so: the audio device's FIFO dropping below its lead (the device
callback is the clock, for a ``paced`` sink), or else the monotonic timer
reaching t0 + k T; or, for a device that owns the sample clock (a link
device, studyapp/device/link_device.py), the device itself: the worker does
not wait before a block, the device's ``exchange`` waits for its sensor
frames, so blocks arrive at the device's rate (a paced audio sink is then fed,
not followed: its FIFO and the resampler take up the drift between the two
clocks). A device that faults hands the pacing to the timer until it is
re-armed. A paced sink that stops calling back (three silent waits of 50 ms)
hands the pacing to the timer for the rest of the run. A timer more
than ``RESYNC`` behind restarts its schedule from now instead of running
blocks back to back to catch up.

A block is a *deadline miss* when it finishes after its deadline: t0 + (k+1) T
on the timer; on the audio clock, when the device had to play silence while
the block was being made; on the device clock, when the device's driver
counted a force frame late during the block (its ``health["late"]``). The load
of a block is its compute time (wall clock) over T. A miss is an *overrun*
when the block's own compute took longer than T on the CPU (the thread's CPU
time), a *stall* when it took longer than T by the wall clock only (the worker
was taken off the CPU mid-block); the other misses come from starting late
(the OS woke the worker late, or an earlier block overran): ``wake_late_max``
says how late. Stalls and late starts are the machine's share of the misses,
overruns the engine's.
"""

import time

import numpy as np

RESYNC = 0.1  # s behind the timer after which the schedule restarts from now
SILENT_WAITS = 3  # waits of 50 ms without a device callback before the timer takes over
IDLE = {"seconds": 0.0, "achieved_rate": 0.0, "load_mean": 0.0, "load_p99": 0.0, "load_max": 0.0,
        "wake_late_max": 0.0, "overruns": 0, "stalls": 0}  # the figures of a worker that never ran


class Pacing:
    """The clock of a run that starts at block ``k`` (now), for ``sink`` and blocks of ``period`` s."""

    def __init__(self, sink, period, k, device=None):
        self.sink = sink
        self.period = period
        self.device = device if device is not None and getattr(device, "clock", False) else None
        self.device_clock = self.device is not None
        self.device_late = self.device.health["late"] if self.device_clock else 0
        self.audio_clock = sink.paced and not self.device_clock
        self.start = self.t0 = time.monotonic()
        self.k_start = self.k0 = k
        self.end = None
        self.silent_waits = 0
        self.shortfalls = sink.shortfalls
        self.loads = []  # every timed block's load, for the summary's percentiles
        self.wake_late_max = 0.0  # the timer's worst wake-up delay: the OS's share of a miss
        self.overruns = 0  # misses whose block alone took longer than its period on the CPU
        self.stalls = 0  # misses whose block took longer than its period by the wall clock only
        self._window = (self.start, 0, 0)  # the status's window: its start, samples and blocks so far

    def wait(self, k):
        """Wait until block ``k`` may start; True when the audio or device clock has just been given up for the timer."""
        if self.device is not None and self.device.fault is None and not self.device_clock:
            self.device_clock = True  # re-armed: the device paces again
            self.device_late = self.device.health["late"]
        if self.device_clock:
            if self.device.fault is None:
                return False
            self.device_clock = False
            self.t0, self.k0 = time.monotonic(), k
            return True
        if self.audio_clock:
            self.silent_waits = 0 if self.sink.wait(0.05) else self.silent_waits + 1
            if self.silent_waits >= SILENT_WAITS:
                self.audio_clock = False
                self.t0, self.k0 = time.monotonic(), k
                return True
            return False
        start_at = self.t0 + (k - self.k0) * self.period
        now = time.monotonic()
        if start_at > now:
            time.sleep(start_at - now)
            self.wake_late_max = max(self.wake_late_max, time.monotonic() - start_at)
        elif now - start_at > RESYNC:
            self.t0, self.k0 = now, k
        return False

    def deadline(self, k):
        """When block ``k`` must be finished, on the timer."""
        return self.t0 + (k - self.k0 + 1) * self.period

    def missed(self, deadline, finished, compute, cpu):
        """Count a block just run (wall-clock ``compute``, thread ``cpu`` seconds); True if it missed its deadline."""
        self.loads.append(compute / self.period)
        if self.device_clock:
            late = self.device.health["late"] > self.device_late
            self.device_late = self.device.health["late"]
        elif self.audio_clock:
            late = self.sink.shortfalls > self.shortfalls
        else:
            late = finished > deadline
        self.shortfalls = self.sink.shortfalls
        if late:
            if cpu > self.period:
                self.overruns += 1
            elif compute > self.period:
                self.stalls += 1
        return late

    def window(self, finished, samples):
        """Once a second, the achieved rate and the mean and highest load since the last time ({} in between),
        counting a block of ``samples`` samples that finished at ``finished``."""
        start, total, blocks = self._window
        total, blocks = total + samples, blocks + 1
        if finished - start < 1.0:
            self._window = (start, total, blocks)
            return {}
        self._window = (finished, 0, 0)
        loads = self.loads[-blocks:]
        return {"achieved_rate": total / (finished - start), "load_mean": float(np.mean(loads)),
                "load_max": float(np.max(loads))}

    def summary(self, blocks, block, end):
        """The run's figures, over ``blocks`` blocks run (of ``block`` samples) from its start to ``end``."""
        seconds = end - self.start
        loads = self.loads
        return {
            "seconds": seconds, "achieved_rate": (blocks - self.k_start) * block / seconds if seconds > 0 else 0.0,
            "load_mean": float(np.mean(loads)) if loads else 0.0,
            "load_p99": float(np.percentile(loads, 99)) if loads else 0.0,
            "load_max": float(np.max(loads)) if loads else 0.0,
            "wake_late_max": self.wake_late_max, "overruns": self.overruns, "stalls": self.stalls,
        }

    @property
    def clock(self):
        """What paces the blocks now: "device", "audio" or "timer"."""
        return "device" if self.device_clock else "audio" if self.audio_clock else "timer"
