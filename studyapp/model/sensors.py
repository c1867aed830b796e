"""The device's sensors, each modelled as the instrument it is from its data sheet and the paper (Sec. 4.2).

docs/model.md's sensor table gives every parameter with its source.

- LVDT position. An LVDT's secondaries carry the excitation (the carrier,
  20 Hz - 20 kHz on the AD598) modulated by the core's position; the
  conditioner demodulates it and low-passes the result, and the device's
  16-bit converter samples that. One sample is

      x_m = Q(LP(x + sigma_c w_c) + sigma_a w_a)

  * LP, the conditioner's output low-pass: the AD598 sets its bandwidth with
    three equal capacitors, C2 = C3 = C4 = 1e-4 F Hz / f_subsystem (its
    design step 8; the example 250 Hz, 0.4 uF), so three poles: a 3rd-order
    Butterworth at ``lvdt_band`` (the Butterworth alignment is our
    assumption; the data sheet's Figs. 13-15 plot the response), designed by
    the bilinear transform as a first-order section times a second-order one
    of Q = 1 (the 3rd-order Butterworth's factors). The signal and the
    conditioner's noise pass it together: the position is delayed (2 /
    (2 pi f_b) at DC, 1.3 ms at 250 Hz) and its noise band-limited.
    ``lvdt_band = inf``: no band limit (the former white model).
  * sigma_c w_c, the conditioner's noise, white before LP, so coloured by it
    at the output.
  * sigma_a w_a, the converter's own white noise (``lvdt_adc_noise``, 1 LSB
    RMS: our choice, the transition noise of a 16-bit converter; the
    paper's board does not name its converter).
  * Q, 16-bit quantisation over the 2.2 cm range (LSB = 0.022 / 2^16 =
    0.34 um) and the range's limits.
  * The carrier's ripple (at twice the carrier) is not modelled: with the
    carrier at least ten times the bandwidth (the rule the data sheets'
    examples follow), three poles pass at most (1 / 20)^3 = 1.25e-4 of a
    full-wave demodulator's ripple (2/3 of its output), 0.9 um at the 11 mm
    full scale: below 3 LSB and 6 % of the noise (it would alias to a fixed
    tone where the carrier is above half the rate).

  The paper gives the total: 15 um RMS "in the sampled analog signal when at
  rest". sigma_c is set so that the total is that at any rate and any band:
  sigma_c^2 G + sigma_a^2 + LSB^2 / 12 = lvdt_noise^2, G = sum h[k]^2 the
  low-pass's power gain (``lvdt_power_gain``, summed over its impulse
  response). The analog noise's variance does not depend on the rate that
  samples it, so neither does the model's.
- LVT tachometer (Trans-Tek Series 100, 0112-0000): "flat frequency response up
  to 500 Hz", modelled as a 2nd-order Butterworth low-pass at 500 Hz (maximally
  flat, -3 dB at 500 Hz: our reading of "flat up to 500 Hz"), plus 0.115 mm/s RMS
  Gaussian noise added after it (the paper measured the noise after A/D conversion).
  Trans-Tek's note on LVT frequency response puts the band in the coils' L / R
  with the load, a first-order pole whose corner the paper does not give; the
  2nd order at 500 Hz is the stricter reading (more delay), kept.
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
    is below 0.49 * rate, else none (the sensor's band covers the sampled one).
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

Cut-offs above 0.49 * rate are lowered to 0.49 * rate (the estimators' own
rule, ``studyapp.estimators.spec.NYQUIST_FRACTION``), so every rate from 1 kHz works.

The noises are drawn per block by the loop, each from its own seeded generator
(the LVDT's conditioner and converter parts from two, the accelerometer's white
and low-frequency parts from two); the compiled functions here only shape and add them.

``from_environment`` reads the LVDT's band and noise from ``STUDYAPP_LVDT_BAND``
(Hz, or ``inf``: no band limit) and ``STUDYAPP_LVDT_NOISE`` (m RMS at rest), as
``STUDYAPP_NUDGE`` is read (nudge.py): so that a sweep (scripts/lvdt_sensitivity.py)
can vary them under whole sessions (``studyapp run``); provenance records them.
"""

import dataclasses
import functools
import os
from dataclasses import dataclass

import numpy as np
from numba import njit

from studyapp.estimators.biquad import butter_section, section_from_sos
from studyapp.estimators.butterworth import sos_row
from studyapp.errors import ParameterError
from studyapp.estimators.spec import NYQUIST_FRACTION


@dataclass(frozen=True)
class SensorSpec:
    """The paper's sensor figures (SI units); see the module docstring for sources."""

    lvdt_noise: float = 15e-6  # m RMS at rest, in total
    lvdt_band: float = 250.0  # Hz, the conditioner's -3 dB bandwidth (math.inf: none)
    lvdt_adc_noise: float = 0.022 / 2 ** 16  # m RMS, the converter's own white noise (1 LSB, assumed)
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
    def lvdt_conditioner_variance(self):
        """What the converter (noise and quantisation) leaves of the total variance at rest (m^2)."""
        return self.lvdt_noise ** 2 - self.lvdt_adc_noise ** 2 - self.lvdt_lsb ** 2 / 12.0

    def lvdt_sections(self, rate):
        """The conditioner's low-pass as two 5-number sections (first order, then Q = 1), or two pass-throughs."""
        if not np.isfinite(self.lvdt_band):
            return PASS.copy(), PASS.copy()
        f = min(self.lvdt_band, NYQUIST_FRACTION * rate)
        return section_from_sos(sos_row(1, f, rate, "low")), lowpass_section(f, 1.0, rate)

    def lvdt_drive(self, rate):
        """sigma_c: the conditioner's noise before the low-pass that gives ``lvdt_noise`` in total at rest."""
        first, second = self.lvdt_sections(rate)
        return float(np.sqrt(self.lvdt_conditioner_variance / lvdt_power_gain(tuple(first), tuple(second))))

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
        """The accelerometer's low-pass, or a pass-through section when its band exceeds 0.49 * rate."""
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
        p[SP_LVDT_DRIVE] = self.lvdt_drive(rate)
        p[SP_LVDT_ADC] = self.lvdt_adc_noise
        p[SP_LVDT_LSB] = self.lvdt_lsb
        p[SP_LVDT_HALF] = self.lvdt_range / 2.0
        p[SP_LVT_NOISE] = self.lvt_noise
        p[SP_ACC_NOISE] = self.acc_white_noise
        p[SP_ACC_LF_POLE] = self.acc_lf_pole(rate)
        p[SP_ACC_LF_DRIVE] = self.acc_lf_drive(rate)
        p[SP_LVT:SP_LVT + 5] = self.lvt_section(rate)
        p[SP_ACC:SP_ACC + 5] = self.acc_section(rate)
        p[SP_ACC_HP:SP_ACC_HP + 5] = self.acc_coupling_section(rate)
        p[SP_LVDT_LP1:SP_LVDT_LP1 + 5], p[SP_LVDT_LP2:SP_LVDT_LP2 + 5] = self.lvdt_sections(rate)
        return p


PASS = np.array([1.0, 0.0, 0.0, 0.0, 0.0])


def lowpass_section(f, q, rate):
    """A second-order low-pass of quality ``q`` at ``f`` Hz by the bilinear transform, prewarped at ``f``.

    H(s) = w^2 / (s^2 + w s / q + w^2) with s = (w / K) (z - 1) / (z + 1), K = tan(pi f / rate):
    b0 = b2 = K^2 / d, b1 = 2 b0, a1 = 2 (K^2 - 1) / d, a2 = (1 - K / q + K^2) / d,
    d = 1 + K / q + K^2. With q = 1 and a first-order section at the same f it is
    the 3rd-order Butterworth (its poles at -w and w exp(+-j 2 pi / 3)).
    """
    k = np.tan(np.pi * f / rate)
    d = 1.0 + k / q + k * k
    b0 = k * k / d
    return np.array([b0, 2.0 * b0, b0, 2.0 * (k * k - 1.0) / d, (1.0 - k / q + k * k) / d])


@functools.lru_cache(maxsize=256)
def lvdt_power_gain(first, second, tail=1e-13):
    """sum h[k]^2 of the two sections in series: their impulse response summed until its state is below ``tail``.

    Plain float operations in a fixed order (no BLAS: the same bits on every machine, issue 39)."""
    s = [0.0, 0.0, 0.0, 0.0]
    total, x = 0.0, 1.0
    for _ in range(10_000_000):
        y = first[0] * x + s[0]
        s[0] = first[1] * x - first[3] * y + s[1]
        s[1] = first[2] * x - first[4] * y
        z = second[0] * y + s[2]
        s[2] = second[1] * y - second[3] * z + s[3]
        s[3] = second[2] * y - second[4] * z
        total += z * z
        x = 0.0
        if max(abs(s[0]), abs(s[1]), abs(s[2]), abs(s[3])) < tail:
            return total
    raise ValueError("the LVDT's low-pass does not settle")


def _environment_number(name, default, low):
    text = os.environ.get(name, "").strip()
    if not text:
        return default
    try:
        value = float(text)
    except ValueError:
        value = float("nan")
    if not (value > low) or np.isnan(value):
        raise ParameterError(f"environment variable {name}={text!r}: allowed is a number above {low:g}"
                             + (" or inf" if name == BAND_VARIABLE else ""))
    return value


BAND_VARIABLE = "STUDYAPP_LVDT_BAND"
NOISE_VARIABLE = "STUDYAPP_LVDT_NOISE"


def from_environment():
    """The sensors with the LVDT's band and noise from ``STUDYAPP_LVDT_BAND`` / ``STUDYAPP_LVDT_NOISE`` if set."""
    spec = SensorSpec()
    band = _environment_number(BAND_VARIABLE, spec.lvdt_band, 0.0)
    noise = _environment_number(NOISE_VARIABLE, spec.lvdt_noise, 0.0)
    if not np.isfinite(noise) or noise ** 2 <= spec.lvdt_adc_noise ** 2 + spec.lvdt_lsb ** 2 / 12.0:
        raise ParameterError(f"environment variable {NOISE_VARIABLE}={noise!r}: allowed is a finite number of "
                             f"metres above the converter's {np.sqrt(spec.lvdt_adc_noise ** 2 + spec.lvdt_lsb ** 2 / 12):.3g}")
    return dataclasses.replace(spec, lvdt_band=band, lvdt_noise=noise)


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


(SP_LVDT_DRIVE, SP_LVDT_LSB, SP_LVDT_HALF, SP_LVT_NOISE, SP_ACC_NOISE, SP_ACC_LF_POLE,
 SP_ACC_LF_DRIVE) = range(7)
SP_LVT = 7
SP_ACC = 12
SP_ACC_HP = 17
SP_LVDT_ADC = 22
SP_LVDT_LP1 = 23
SP_LVDT_LP2 = 28
N_PARAMS = 33
# state: LVT section (2), accelerometer low-pass (2), AC coupling (2), low-frequency noise (1), the LVDT's
# low-pass (2 + 2)
SS_LVT = 0
SS_ACC = 2
SS_ACC_HP = 4
SS_ACC_LF = 6
SS_LVDT_LP1 = 7
SS_LVDT_LP2 = 9
N_STATE = 11


@njit(cache=True, inline="always")
def lvdt(p, s, x_true, noise, noise_adc):
    """One LVDT sample: ``noise`` (the conditioner's) and ``noise_adc`` (the converter's) are standard normal draws."""
    lsb = p[SP_LVDT_LSB]
    half = p[SP_LVDT_HALF]
    demodulated = section_at(p, SP_LVDT_LP1, s, SS_LVDT_LP1, x_true + p[SP_LVDT_DRIVE] * noise)
    demodulated = section_at(p, SP_LVDT_LP2, s, SS_LVDT_LP2, demodulated)
    x = np.floor((demodulated + p[SP_LVDT_ADC] * noise_adc) / lsb + 0.5) * lsb
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
