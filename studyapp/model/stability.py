"""Stability monitor: does the loop still behave like a bowed string?

(first pass: criterion being calibrated)
"""

import numpy as np


class StabilityMonitor:
    def __init__(self, rate, f0, beta):
        self.rate = float(rate)
        self.f0 = float(f0)
        self.beta = float(beta)
        self.broken = False
        self.score = 0.0

    def update(self, block, fmax, velocity_scale):
        v = block["velocity_true"]
        if v.size:
            self.score = float(np.sqrt(np.mean(np.square(v - v.mean()))))
