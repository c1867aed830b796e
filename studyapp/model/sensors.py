"""The device's sensors with the paper's measured figures (Sec. 4.2).

- LVDT position: the true position plus Gaussian noise of 15 um RMS ("measured
  ... when at rest"), quantised by a 16-bit converter over the 2.2 cm range
  (LSB = 0.022 / 2^16 = 0.34 um) and limited to that range.
- LVT tachometer (Trans-Tek Series 100, 0112-0000): "flat frequency response up
  to 500 Hz", modelled as a 2nd-order Butterworth low-pass at 500 Hz (maximally
  flat, -3 dB at 500 Hz: our reading of "flat up to 500 Hz"), plus 0.115 mm/s RMS
  Gaussian noise added after it (the paper measured the noise after A/D conversion).
- Accelerometer (PCB 352C22): "frequency range up to 10 kHz", modelled as a
  2nd-order Butterworth low-pass at 10 kHz when that is below 0.45 * rate (else
  the sensor's band covers the whole sampled band and no filter is applied),
  plus 0.22 m/s^2 RMS Gaussian noise and a constant bias. The bias is our
  assumption (0.05 m/s^2): the paper reports DC error in this sensor without a
  figure (Sec. 5.6: "our accelerometer measurement does not adhere to its
  bias-free assumptions"; it high-passes it at 20 Hz).

Cut-offs above 0.45 * rate are lowered to 0.45 * rate (the estimators' own
rule, ``studyapp.estimators.spec.NYQUIST_FRACTION``), so every rate from 1 kHz works.

The noises are white and drawn per block by the loop from its seeded generator;
the compiled functions here only add them.
"""

from dataclasses import dataclass

import numpy as np
from numba import njit

from studyapp.estimators.biquad import butter_section
from studyapp.estimators.spec import NYQUIST_FRACTION


@dataclass(frozen=True)
class SensorSpec:
    """The paper's sensor figures (SI units); see the module docstring for sources."""

    lvdt_noise: float = 15e-6  # m RMS
    lvdt_bits: int = 16
    lvdt_range: float = 0.022  # m, full scale
    lvt_band: float = 500.0  # Hz
    lvt_noise: float = 0.115e-3  # m/s RMS
    acc_band: float = 10_000.0  # Hz
    acc_noise: float = 0.22  # m/s^2 RMS
    acc_bias: float = 0.05  # m/s^2, assumed

    @property
    def lvdt_lsb(self):
        return self.lvdt_range / 2.0 ** self.lvdt_bits

    def lvt_section(self, rate):
        """The LVT's low-pass as one 5-number section (b0 b1 b2 a1 a2)."""
        return butter_section(min(self.lvt_band, NYQUIST_FRACTION * rate), rate)

    def acc_section(self, rate):
        """The accelerometer's low-pass, or a pass-through section when its band exceeds 0.45 * rate."""
        if self.acc_band >= NYQUIST_FRACTION * rate:
            return np.array([1.0, 0.0, 0.0, 0.0, 0.0])
        return butter_section(self.acc_band, rate)

    def params(self, rate):
        """Packed for the compiled loop: see the ``SP_*`` indices."""
        p = np.zeros(N_PARAMS)
        p[SP_LVDT_NOISE] = self.lvdt_noise
        p[SP_LVDT_LSB] = self.lvdt_lsb
        p[SP_LVDT_HALF] = self.lvdt_range / 2.0
        p[SP_LVT_NOISE] = self.lvt_noise
        p[SP_ACC_NOISE] = self.acc_noise
        p[SP_ACC_BIAS] = self.acc_bias
        p[SP_LVT:SP_LVT + 5] = self.lvt_section(rate)
        p[SP_ACC:SP_ACC + 5] = self.acc_section(rate)
        return p


SP_LVDT_NOISE, SP_LVDT_LSB, SP_LVDT_HALF, SP_LVT_NOISE, SP_ACC_NOISE, SP_ACC_BIAS = range(6)
SP_LVT = 6
SP_ACC = 11
N_PARAMS = 16
# state: LVT section (2), accelerometer section (2)
SS_LVT = 0
SS_ACC = 2
N_STATE = 4


@njit(cache=True, inline="always")
def lvdt(p, x_true, noise):
    """One LVDT sample: ``noise`` is a standard normal draw."""
    lsb = p[SP_LVDT_LSB]
    half = p[SP_LVDT_HALF]
    x = np.floor((x_true + p[SP_LVDT_NOISE] * noise) / lsb + 0.5) * lsb
    if x > half - lsb:
        return half - lsb
    if x < -half:
        return -half
    return x


@njit(cache=True, inline="always")
def section_at(p, i, s, j, x):
    """A section with coefficients p[i:i+5] and state s[j:j+2] (transposed direct form II).

    Indexing instead of slicing keeps the per-sample path free of array views.
    """
    y = p[i] * x + s[j]
    s[j] = p[i + 1] * x - p[i + 3] * y + s[j + 1]
    s[j + 1] = p[i + 2] * x - p[i + 4] * y
    return y


@njit(cache=True, inline="always")
def lvt(p, s, v_true, noise):
    """One tachometer sample."""
    return section_at(p, SP_LVT, s, SS_LVT, v_true) + p[SP_LVT_NOISE] * noise


@njit(cache=True, inline="always")
def accelerometer(p, s, a_true, noise):
    """One accelerometer sample."""
    return section_at(p, SP_ACC, s, SS_ACC, a_true) + p[SP_ACC_BIAS] + p[SP_ACC_NOISE] * noise
