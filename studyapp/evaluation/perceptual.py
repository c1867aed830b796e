"""A perceptual distance between two sounds: specific loudness in critical bands (paper Sec. 10).

The paper closes (Sec. 10) with "an objective function based on models of
human perception could be relevant for future work": its rating task found
that the delay-corrected error E did not predict perceived noisiness well
(Spearman rho = 0.61, Sec. 9.2). ``audio_distance`` compares two sounds the
way a loudness model hears them, after Zwicker's model of loudness.

1. **Frames.** Both signals are cut into Hann-windowed frames of
   ``FRAME_S`` = 32 ms (``round(0.032 rate)`` samples, about a critical
   band's temporal integration), hop half a frame, zero-padded to the next
   power of two; the power spectrum of frame t is |X_t(f)|^2.
2. **Critical bands.** Zwicker and Terhardt's critical-band rate (1980),

       z(f) = 13 arctan(0.00076 f) + 3.5 arctan((f / 7500)^2)   (Bark, f in Hz),

   cuts 0 .. rate/2 into bands one Bark wide: band b holds the frequencies
   with b <= z(f) < b + 1 (its edges are z^-1(b), found numerically; the last
   band ends at the Nyquist frequency). Bins below ``LOWEST_HZ`` = 20 Hz,
   below hearing, are left out. The band's energy in frame t is
   E[t, b] = sum of |X_t(f)|^2 over its bins: the excitation of one
   critical band, without the spreading across bands of a full model.
3. **Specific loudness.** Zwicker's power law above threshold,

       N[t, b] = E[t, b] ^ 0.23

   (Zwicker and Fastl, *Psychoacoustics*, ch. 8: specific loudness grows as
   the 0.23rd power of intensity, well above threshold). The simulated audio
   is in arbitrary units, with no sound pressure level, so there is no
   threshold in quiet and no outer/middle-ear weighting: the compression
   alone makes a weak band count for less than a loud one, but not as little
   as its energy (a band 60 dB down still has 4% of the loudness).
4. **Distance.** The RMS over frames and bands of the difference in specific
   loudness, relative to the RMS loudness of the two sounds together:

       d(a, b) = sqrt(mean (N_a - N_b)^2) / sqrt(mean (N_a^2 + N_b^2) / 2).

   It is 0 for identical sounds, symmetric in a and b, unchanged when both
   are scaled by one gain (arbitrary units), and at most sqrt(2), reached
   when one of the two is silent (or when they share no band and frame),
   since (N_a - N_b)^2 <= N_a^2 + N_b^2 for N >= 0. Two silent sounds are at
   distance 0. A pure level change by a gain g (b = g a) multiplies N by
   g^0.46, so d = |g^0.46 - 1| / sqrt((1 + g^0.92) / 2): 0.31 for +6 dB.

Related measures: the log-spectral distance (the same in dB, without
loudness weighting) and ITU-R BS.1387 (PEAQ), whose loudness comparison of
excitation patterns this is a much reduced form of.

References: E. Zwicker and E. Terhardt, "Analytical expressions for
critical-band rate and critical bandwidth as a function of frequency",
J. Acoust. Soc. Am. 68(5), 1523-1525, 1980. E. Zwicker, "Subdivision of the
audible frequency range into critical bands", J. Acoust. Soc. Am. 33(2), 248,
1961. E. Zwicker and H. Fastl, *Psychoacoustics: Facts and Models*, Springer.
"""

import math

import numpy as np
from scipy.optimize import brentq
from scipy.signal import spectrogram

from studyapp.errors import ParameterError

FRAME_S = 0.032
LOWEST_HZ = 20.0
LOUDNESS_EXPONENT = 0.23


def bark(f):
    """Critical-band rate z (Bark) of frequency ``f`` (Hz), Zwicker and Terhardt (1980)."""
    f = np.asarray(f, dtype=np.float64)
    return 13.0 * np.arctan(0.00076 * f) + 3.5 * np.arctan((f / 7500.0) ** 2)


def bark_edges(nyquist):
    """Band edges (Hz): z^-1(0), z^-1(1), ... below ``nyquist``, then ``nyquist`` itself."""
    top = float(bark(nyquist))
    inner = [brentq(lambda f, z=z: float(bark(f)) - z, 0.0, nyquist, xtol=1e-9)
             for z in range(1, math.ceil(top))]
    return np.array([0.0, *inner, nyquist])


def frame_length(rate):
    return max(2, int(round(FRAME_S * rate)))


def check_rate(rate):
    try:
        value = float(rate)
    except (TypeError, ValueError):
        value = float("nan")
    if not (math.isfinite(value) and value > 2.0 * LOWEST_HZ):
        raise ParameterError(f"rate = {rate!r}: allowed is a sample rate in Hz above {2 * LOWEST_HZ:g}")
    return value


def band_energies(audio, rate):
    """E[t, b]: the energy of each critical band (columns) in each frame (rows)."""
    n = frame_length(rate)
    nfft = 1 << (n - 1).bit_length()
    freqs, _, power = spectrogram(audio, fs=rate, window="hann", nperseg=n, noverlap=n // 2, nfft=nfft,
                                  detrend=False, scaling="spectrum", mode="psd")
    edges = bark_edges(rate / 2.0)
    band = np.searchsorted(edges, freqs, side="right") - 1
    band = np.minimum(band, len(edges) - 2)  # the Nyquist bin belongs to the last band
    audible = freqs >= LOWEST_HZ
    energies = np.zeros((power.shape[1], len(edges) - 1))
    np.add.at(energies.T, band[audible], power[audible])
    return energies


def specific_loudness(energies):
    """N = E^0.23 (Zwicker's power law, arbitrary units)."""
    return np.asarray(energies, dtype=np.float64) ** LOUDNESS_EXPONENT


def _signal(values, what):
    x = np.asarray(values, dtype=np.float64)
    if x.ndim != 1:
        raise ParameterError(f"{what}: expected a 1-D signal, got shape {x.shape}")
    if not np.all(np.isfinite(x)):
        raise ParameterError(f"{what}: holds {int(np.sum(~np.isfinite(x)))} non-finite samples")
    return x


def audio_distance(reference_audio, audio, rate):
    """The loudness distance d (module docstring) between two sounds at ``rate`` Hz: 0 .. sqrt(2)."""
    rate = check_rate(rate)
    a = _signal(reference_audio, "reference_audio")
    b = _signal(audio, "audio")
    if a.shape != b.shape:
        raise ParameterError(f"audio: {b.shape[0]} samples, the reference has {a.shape[0]}: allowed is the same length")
    if a.shape[0] < frame_length(rate):
        raise ParameterError(f"audio: {a.shape[0]} samples is shorter than one frame "
                             f"({frame_length(rate)} samples = {FRAME_S * 1000:g} ms at {rate:g} Hz)")
    na = specific_loudness(band_energies(a, rate))
    nb = specific_loudness(band_energies(b, rate))
    power = np.mean(na ** 2 + nb ** 2) / 2.0
    if power == 0.0:
        return 0.0
    return float(np.sqrt(np.mean((na - nb) ** 2) / power))
