"""A device driver for tests, behind the model's device interface (model/device.py): a free mass
whose sensors report NaN at one chosen sample, as a failing ADC or a broken cable might."""

import math

from studyapp.model.device import DeviceLimits, HapticDevice

NAN_AT = 2000  # sample number of the bad reading


class NanDevice(HapticDevice):
    def __init__(self, rate, nan_at=NAN_AT, mass=0.1):
        self.rate = float(rate)
        self.limits = DeviceLimits()
        self.nan_at = nan_at
        self.mass = mass
        self.k = 0
        self.x = 0.0
        self.v = 0.01  # moving, so the bow rubs the string and a force develops
        self.forces = []

    def read_sensors(self):
        self.k += 1
        if self.k == self.nan_at:
            return math.nan, 0.0, math.nan
        return self.x, 0.0, self.v

    def write_force(self, force):
        self.forces.append(force)
        t = 1.0 / self.rate
        # a hand holds the handle at 1 cm/s against the string's friction
        self.v += t * (force + 20.0 * (0.01 - self.v)) / self.mass
        self.x = max(-0.011, min(0.011, self.x + t * self.v))


def make(rate):
    return NanDevice(rate)
