"""The perceptual distance (evaluation/perceptual.py) against closed forms and independent references."""

import numpy as np
import pytest

from studyapp.errors import ParameterError
from studyapp.evaluation.perceptual import audio_distance, band_energies, bark_edges

RATE = 5000.0


def tone(rate=RATE, duration=1.0, f0=147.0, harmonics=12):
    """A bowed-string-like tone: a band-limited sawtooth, harmonics falling as 1/k."""
    t = np.arange(int(rate * duration)) / rate
    return sum(np.sin(2 * np.pi * k * f0 * t) / k for k in range(1, harmonics + 1) if k * f0 < rate / 2)


def zwicker_terhardt(f):
    """Critical-band rate (Bark), Zwicker & Terhardt (1980), typed here from the paper."""
    return 13.0 * np.arctan(0.00076 * f) + 3.5 * np.arctan((f / 7500.0) ** 2)


# Zwicker (1961), Table I: the upper edges (Hz) of critical bands 1-24.
ZWICKER_1961 = [100, 200, 300, 400, 510, 630, 770, 920, 1080, 1270, 1480, 1720, 2000, 2320, 2700, 3150, 3700,
                4400, 5300, 6400, 7700, 9500, 12000, 15500]


def test_identical_signals_are_at_zero():
    x = tone() + 0.01 * np.random.default_rng(0).standard_normal(int(RATE))
    assert audio_distance(x, x.copy(), RATE) == 0.0


@pytest.mark.parametrize("gain", [0.1, 0.5, 2.0, 10.0])
def test_a_level_change_follows_the_power_law(gain):
    # E scales by g^2, N = E^0.23 by g^0.46 in every band and frame.
    x = tone()
    expected = abs(gain ** 0.46 - 1.0) / np.sqrt((1.0 + gain ** 0.92) / 2.0)
    assert audio_distance(x, gain * x, RATE) == pytest.approx(expected, rel=1e-9)


def test_silence_against_a_sound_is_the_maximum():
    x = tone()
    assert audio_distance(np.zeros_like(x), x, RATE) == pytest.approx(np.sqrt(2.0), rel=1e-12)
    assert audio_distance(np.zeros_like(x), np.zeros_like(x), RATE) == 0.0


def test_more_noise_is_further_away():
    x = tone()
    noise = np.random.default_rng(1).standard_normal(x.size)
    noise *= np.sqrt(np.mean(x ** 2) / np.mean(noise ** 2))
    distances = [audio_distance(x, x + 10 ** (-snr / 20) * noise, RATE) for snr in (50, 40, 30, 20, 10, 0)]
    assert np.all(np.diff(distances) > 0), distances
    assert 0.0 < distances[0] and distances[-1] < np.sqrt(2.0)


def test_symmetric_and_scale_free():
    rng = np.random.default_rng(2)
    a = tone() + 0.05 * rng.standard_normal(int(RATE))
    b = 0.7 * tone(f0=150.0) + 0.2 * rng.standard_normal(int(RATE))
    assert audio_distance(a, b, RATE) == audio_distance(b, a, RATE)
    assert audio_distance(3.0 * a, 3.0 * b, RATE) == pytest.approx(audio_distance(a, b, RATE), rel=1e-12)


@pytest.mark.parametrize("rate", [5000.0, 44100.0])
def test_band_edges_are_whole_barks(rate):
    edges = bark_edges(rate / 2)
    # Inverted independently: interpolation of the formula on a fine grid.
    grid = np.linspace(0.0, rate / 2, 2_000_001)
    whole = np.arange(1, int(np.ceil(zwicker_terhardt(rate / 2))))
    np.testing.assert_allclose(edges[1:-1], np.interp(whole, zwicker_terhardt(grid), grid), atol=0.01)
    assert edges[0] == 0.0 and edges[-1] == rate / 2
    # The formula's edges lie within 0.25 Bark of Zwicker's tabulated critical bands.
    table = np.array([f for f in ZWICKER_1961 if f < rate / 2])
    assert len(table) == len(edges) - 2
    np.testing.assert_allclose(zwicker_terhardt(table), np.arange(1, len(table) + 1), atol=0.25)


@pytest.mark.parametrize("frequency", [250.0, 1000.0, 2000.0])
def test_a_sine_excites_its_own_band(frequency):
    t = np.arange(int(RATE)) / RATE
    energies = band_energies(np.sin(2 * np.pi * frequency * t), RATE)
    band = int(np.floor(zwicker_terhardt(frequency)))
    assert np.all(np.argmax(energies, axis=1) == band)


@pytest.mark.parametrize("reference, audio, rate, match", [
    (np.zeros(1000), np.zeros(999), RATE, "same length"),
    (np.zeros(1000), np.full(1000, np.nan), RATE, "non-finite"),
    (np.zeros(100), np.zeros(100), RATE, "shorter than one frame"),
    (np.zeros(1000), np.zeros(1000), 0.0, "rate"),
    (np.zeros((2, 1000)), np.zeros((2, 1000)), RATE, "1-D"),
])
def test_bad_input_is_refused(reference, audio, rate, match):
    with pytest.raises(ParameterError, match=match):
        audio_distance(reference, audio, rate)
