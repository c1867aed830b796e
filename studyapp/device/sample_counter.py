"""The device's u32 sample counter as the host follows it: serial-number arithmetic, and what cannot happen.

The device counts its samples in a u32 that wraps (docs/device-protocol.md:
2^32 samples are 9.9 days at 5 kHz), so two counters are compared by their
signed 32-bit difference (serial-number arithmetic, as RFC 1982 has it):

    ahead(a, b) = ((a - b + 2^31) mod 2^32) - 2^31

which is a - b whenever the two are less than 2^31 samples apart, across the
wrap too. The host keeps its own count *unwrapped* (a Python int that goes
on past 2^32): each frame's u32 ``sample`` becomes ``expected + ahead(sample,
expected mod 2^32)``, so everything downstream (the tags it sends, mod 2^32;
late, missing; the shadow's CONTROL schedule) compares plain integers.

What an honest device cannot send, each a named fault (``CounterFault``):

- a frame whose count is not START's packet;
- a frame that goes back (its first sample at or before one already read:
  the protocol never repeats a sample);
- a jump forward of more than ``MAX_JUMP_S`` of samples from one frame to the
  next within a stream. Frames the link dropped (a pty that filled while the
  host was busy) leave a gap of real time: counted as missing, no fault. A
  counter that jumps at random goes back half the time and otherwise lands
  on average 2^30 samples (2.5 days at 5 kHz) ahead: caught within a frame
  or two. (A bound from the host's own clock would not do: a device that
  fell behind its schedule and catches up, as the emulator does, streams
  faster than real time for a while; and a host stopped for longer than
  ``MAX_JUMP_S`` finds its device's watchdog tripped anyway.)

The first frame after a START is taken as it comes (the device's counter ran
on while it was not streaming), but never behind the newest already read.
"""

MASK = 0xFFFFFFFF
HALF = 0x80000000
MAX_JUMP_S = 60.0  # s of samples a frame may skip ahead of the one before it (frames lost on the way)


class CounterFault(Exception):
    """A sample counter an honest device cannot send (one line)."""


def ahead(a, b):
    """a - b as the signed 32-bit difference of two wrapping u32 counters."""
    return ((a - b + HALF) & MASK) - HALF


class SampleCounter:
    """The device's samples seen since START, unwrapped; ``packet`` the count every frame must carry."""

    def __init__(self, rate, packet):
        self.rate = float(rate)
        self.packet = int(packet)
        self.max_jump = int(MAX_JUMP_S * self.rate)
        self.newest = -1  # the newest device sample read, unwrapped; -1 before the first frame ever
        self._fresh = True  # no frame read since START yet

    @property
    def fresh(self):
        """No frame read since START: the device's counter is not known yet."""
        return self._fresh

    def started(self):
        """START was sent: the next frame may be any distance ahead."""
        self._fresh = True

    def take(self, sample, count, name="SENSORS"):
        """(first sample unwrapped, samples missing before it) of a frame of ``count`` samples from the u32
        ``sample``; ``CounterFault`` for what an honest device cannot send."""
        if count != self.packet:
            raise CounterFault(f"a {name} frame of {count} samples at the device's sample {sample}: START's packet "
                               f"is {self.packet}")
        if self.newest < 0:
            first = sample
        else:
            expected = self.newest + 1
            first = expected + ahead(sample, expected & MASK)
            if first < expected:
                raise CounterFault(f"the device's sample counter went back: a {name} frame from its sample {sample} "
                                   f"after its sample {self.newest & MASK} (expected {expected & MASK})")
            if first - expected > self.max_jump and not self._fresh:
                raise CounterFault(f"the device's sample counter jumped: a {name} frame from its sample {sample} "
                                   f"after its sample {self.newest & MASK}, {first - expected} samples ahead (more "
                                   f"than {MAX_JUMP_S:g} s at {self.rate:g} Hz)")
        missing = 0 if self._fresh else first - (self.newest + 1)
        self._fresh = False
        self.newest = first + count - 1
        return first, missing
