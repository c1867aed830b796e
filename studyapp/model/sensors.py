"""The device's sensors with the paper's measured figures (Sec. 4.2).

- LVDT position: the true position plus Gaussian noise of 15 um RMS ("measured
  ... when at rest"), quantised by a 16-bit converter over the 2.2 cm range
  (LSB = 0.022 / 2^16 = 0.34 um) and limited to that range.
- LVT tachometer (Trans-Tek Series 100, 0112-0000): "flat frequency response up
  to 500 Hz", modelled as a 2nd-order Butterworth low-pass at 500 Hz (maximally
  flat, -3 dB at 500 Hz: our reading of "flat up to 500 Hz"), plus 0.115 mm/s RMS
  Gaussian noise added after it (the paper measured the noise after A/D conversion).
- Accelerometer (PCB 352C22, a piezoelectric ICP sensor): "frequency range up
  to 10 kHz" and "a constant RMS noise level of 0.22 m/s^2 ... when at rest".
  One sample is

      a_m = LP(HP(a + n_lf)) + sigma_w w

  * HP, the AC coupling: a piezoelectric element holds no charge at DC, and
    the sensor's built-in amplifier discharges it with one RC time constant,
    so the sensor is a first-order high-pass, H(s) = s / (s + 2 pi f_c). The
    paper gives no low-frequency figure; PCB's data sheet specifies the
    352C22's range as 1 Hz to 10 kHz within +-5% (0.7 Hz within +-10%). A first-order high-pass that is 5% low at 1 Hz has
    f / sqrt(f^2 + f_c^2) = 0.95, f_c = 1 Hz * sqrt(1 / 0.95^2 - 1) = 0.33 Hz
    (the +-10% point then falls at 0.68 Hz, consistent), a discharge time
    constant tau = 1 / (2 pi f_c) = 0.48 s. A constant acceleration therefore
    reads exp(-t / tau) of itself and no DC reaches the output: the former
    constant bias (0.05 m/s^2, assumed) is gone, as an AC-coupled sensor cannot
    hold one. Designed by the bilinear transform (scipy's ``butter(1, f_c,
    "high")``); its frequency warping at 0.33 Hz is negligible at every rate.
  * LP, the band limit: a 2nd-order Butterworth low-pass at 10 kHz when that
    is below 0.45 * rate, else none (the sensor's band covers the sampled one).
  * n_lf, the low-frequency error the paper names without a figure (Sec. 5.6:
    "our accelerometer measurement does not adhere to its bias-free
    assumptions"; Sec. 7.1: R_a "perhaps reflecting problems due to
    low-frequency error"): a random walk through a leaky integrator, i.e. white
    noise through a first-order low-pass at f_lf = 2 Hz,

        n_lf[k] = rho n_lf[k-1] + sqrt(1 - rho^2) s_lf w_lf[k],   rho = exp(-2 pi f_lf / rate),

    whose spectrum is flat below f_lf and falls as 1/f^2 above it (the slow
    baseline wander of a piezoelectric sensor: thermal transients, cable and
    base strain). It enters before the coupling, as the sensor's own error
    does, so the high-pass bounds it: its part of the output is band-limited
    to about 0.33-2 Hz. f_lf = 2 Hz puts the paper's 20 Hz high-pass (H in
    Sec. 5.7, "to remove accelerometer DC error") a decade above the wander,
    where its spectrum is 20 dB down.
  * sigma_w w, white noise added after the sensor (the acquisition's noise,
    measured by the paper after A/D conversion, like the LVT's).

  The split of the 0.22 m/s^2: the sensor's own broadband resolution in PCB's
  data sheet, of the order of 0.002 g = 0.02 m/s^2 RMS, is a tenth of what
  the paper measured, so the measured figure is mostly the acquisition
  chain's broadband noise: the white part keeps most of it. The low-frequency part takes 0.10 m/s^2 RMS at the
  output (a fifth of the variance; our choice, the paper gives no figure),
  which stands some 20 dB above the white floor below 2 Hz at 5 kHz: a
  wander that breaks a Kalman filter's zero-mean assumption, while the total
  stays the "constant" level the paper measured. The white part is then
  sigma_w = sqrt(0.22^2 - 0.10^2) = 0.196 m/s^2, so the total at rest is the
  paper's 0.22 m/s^2 at any rate. s_lf is the low-pass's stationary RMS scaled
  so that its high-passed part has 0.10 m/s^2 RMS: the variance after HP of a
  unit-variance AR(1) is computed exactly (``lf_gain``); for the analog
  filters it would be f_lf / (f_lf + f_c) = 0.86. The 10 kHz low-pass does not
  count in it (it removes about 1e-4 of the wander's variance).

  n_lf starts at 0 and reaches its stationary level within 1 / (2 pi f_lf) =
  80 ms.

Cut-offs above 0.45 * rate are lowered to 0.45 * rate (the estimators' own
rule, ``studyapp.estimators.spec.NYQUIST_FRACTION``), so every rate from 1 kHz works.

The noises are drawn per block by the loop, each from its own seeded generator
(the accelerometer's white and low-frequency parts from two); the compiled
functions here only shape and add them.
"""

from dataclasses import dataclass

import numpy as np
from numba import njit

from studyapp.estimators.biquad import butter_section, section_from_sos
from studyapp.estimators.butterworth import sos_row
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
    acc_low_limit: float = 1.0  # Hz, PCB's lower frequency limit ...
    acc_low_tolerance: float = 0.05  # ... within +-5%: it sets the AC coupling's corner
    acc_noise: float = 0.22  # m/s^2 RMS at rest, in total
    acc_lf_noise: float = 0.10  # m/s^2 RMS at rest, of it the low-frequency part (assumed)
    acc_lf_corner: float = 2.0  # Hz, the low-frequency noise's leaky integrator (assumed)

    @property
    def lvdt_lsb(self):
        return self.lvdt_range / 2.0 ** self.lvdt_bits

    @property
    def acc_corner(self):
        """The AC coupling's -3 dB corner (Hz): a first-order high-pass, ``acc_low_tolerance`` low at the limit."""
        return self.acc_low_limit * float(np.sqrt(1.0 / (1.0 - self.acc_low_tolerance) ** 2 - 1.0))

    @property
    def acc_white_noise(self):
        """The white part's RMS: what the low-frequency part leaves of the total variance."""
        return float(np.sqrt(self.acc_noise ** 2 - self.acc_lf_noise ** 2))

    def lvt_section(self, rate):
        """The LVT's low-pass as one 5-number section (b0 b1 b2 a1 a2)."""
        return butter_section(min(self.lvt_band, NYQUIST_FRACTION * rate), rate)

    def acc_section(self, rate):
        """The accelerometer's low-pass, or a pass-through section when its band exceeds 0.45 * rate."""
        if self.acc_band >= NYQUIST_FRACTION * rate:
            return np.array([1.0, 0.0, 0.0, 0.0, 0.0])
        return butter_section(self.acc_band, rate)

    def acc_coupling_section(self, rate):
        """The AC coupling: a first-order high-pass at ``acc_corner`` as a 5-number section (b2 = a2 = 0)."""
        return section_from_sos(sos_row(1, self.acc_corner, rate, "high"))

    def acc_lf_pole(self, rate):
        """rho of the low-frequency noise's leaky integrator."""
        return float(np.exp(-2.0 * np.pi * self.acc_lf_corner / rate))

    def acc_lf_drive(self, rate):
        """The gain on the unit normal draw that gives the low-frequency part ``acc_lf_noise`` RMS at the output."""
        rho = self.acc_lf_pole(rate)
        stationary = self.acc_lf_noise / np.sqrt(lf_gain(rho, self.acc_coupling_section(rate)))
        return float(np.sqrt(1.0 - rho * rho) * stationary)

    def params(self, rate):
        """Packed for the compiled loop: see the ``SP_*`` indices."""
        p = np.zeros(N_PARAMS)
        p[SP_LVDT_NOISE] = self.lvdt_noise
        p[SP_LVDT_LSB] = self.lvdt_lsb
        p[SP_LVDT_HALF] = self.lvdt_range / 2.0
        p[SP_LVT_NOISE] = self.lvt_noise
        p[SP_ACC_NOISE] = self.acc_white_noise
        p[SP_ACC_LF_POLE] = self.acc_lf_pole(rate)
        p[SP_ACC_LF_DRIVE] = self.acc_lf_drive(rate)
        p[SP_LVT:SP_LVT + 5] = self.lvt_section(rate)
        p[SP_ACC:SP_ACC + 5] = self.acc_section(rate)
        p[SP_ACC_HP:SP_ACC_HP + 5] = self.acc_coupling_section(rate)
        return p


def lf_gain(rho, hp):
    """Stationary variance of ``hp`` (a first-order section) driven by a unit-variance AR(1) with pole ``rho``.

    With n[k] = rho n[k-1] + e[k] (Var e = 1 - rho^2) and y[k] = b0 n[k] + b1 n[k-1] + p y[k-1]
    (p = -a1), the state (n[k], y[k]) obeys s[k] = A s[k-1] + B e[k] with
    A = [[rho, 0], [b0 rho + b1, p]] and B = [1, b0]; the stationary covariance
    P = A P A^T + (1 - rho^2) B B^T solved element by element gives
    P_nn = 1, P_ny = (r b0 + rho (b0 rho + b1)) / (1 - rho p) and Var y = P_yy below
    (r = 1 - rho^2).
    """
    b0, b1, p = hp[0], hp[1], -hp[3]
    r = 1.0 - rho * rho
    c = b0 * rho + b1
    p_ny = (r * b0 + rho * c) / (1.0 - rho * p)
    return (c * c + 2.0 * c * p * p_ny + r * b0 * b0) / (1.0 - p * p)


(SP_LVDT_NOISE, SP_LVDT_LSB, SP_LVDT_HALF, SP_LVT_NOISE, SP_ACC_NOISE, SP_ACC_LF_POLE,
 SP_ACC_LF_DRIVE) = range(7)
SP_LVT = 7
SP_ACC = 12
SP_ACC_HP = 17
N_PARAMS = 22
# state: LVT section (2), accelerometer low-pass (2), AC coupling (2), low-frequency noise (1)
SS_LVT = 0
SS_ACC = 2
SS_ACC_HP = 4
SS_ACC_LF = 6
N_STATE = 7


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
def accelerometer(p, s, a_true, noise, noise_lf):
    """One accelerometer sample: ``noise`` (white part) and ``noise_lf`` (low-frequency part) are normal draws."""
    lf = p[SP_ACC_LF_POLE] * s[SS_ACC_LF] + p[SP_ACC_LF_DRIVE] * noise_lf
    s[SS_ACC_LF] = lf
    coupled = section_at(p, SP_ACC_HP, s, SS_ACC_HP, a_true + lf)
    return section_at(p, SP_ACC, s, SS_ACC, coupled) + p[SP_ACC_NOISE] * noise
