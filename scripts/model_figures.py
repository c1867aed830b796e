"""The figures docs/model.md quotes about the shipped model (5 kHz, Table 1), and the breakdown spectrograms.

    PYTHONPATH=. python scripts/model_figures.py [--png docs/breakdown_strokes.png] [--source LVT] [--seeds 3]
    PYTHONPATH=. python scripts/model_figures.py --only-png --png docs/breakdown_strokes_lowpass.png --source LOWPASS
    PYTHONPATH=. python scripts/model_figures.py --only-signals

Prints, for the model as calibration.py sets it, with sinclair2014's Table 1 parameters:

- breakdown while bowing (strokes) for LVT, LOWPASS, KALPOS, LEVANT, FOAW and TRUE, seed 0, and the
  frequency the loop buzzes at (the handle's velocity's spectral peak at 1.25 x, above 50 Hz: below it
  lie the strokes themselves);
- the handle's velocity per band (mm/s RMS) with TRUE at 4 N and at 1.25 x LVT's breakdown, and with
  LVT, LOWPASS and KALPOS at 1.25 x theirs: what the bowing verdict's band holds;
- hearing it, seeds 0..N-1 (each with its own breakdown): the audio's 100-400 Hz level at 1.25 x minus
  its level at 0.8 x (dB), and three other measures of the same two sounds: the contact microphone's
  own band (the audio's 50-400 Hz), the audio's level outside the string's harmonics (the spectrum with
  +-3 % around each multiple of f0 removed, 50-2500 Hz) and the loudness distance from TRUE's sound at
  the same F_max and seed (evaluation.perceptual.audio_distance; the rise as 20 log10 of the ratio);
- the paper's signals on the data set's settings (LVT in the loop, strokes, data_set.TRAINING's seeds):
  max |dv/dt| of ``velocity_lvt`` at 12.1 N, ``velocity_lvt`` high-passed at 100 Hz (RMS) at 7.7 N and
  FOAW (Table 1) at its maximum window at 7.7 N;
- the string's pitch on the strokes with LVT at 2 N at 5, 20 and 48 kHz;

``--only-signals`` prints only the last two (a few seconds); tests/test_quoted_model_figures.py
recomputes them through ``paper_signals`` and ``loop_pitch`` and compares them with docs/model.md.

With ``--png``, a spectrogram of the audio while ``--source`` steps through 0.5, 0.75, 1, 1.25 and
1.5 x its bowing breakdown on strokes, 3 s each (the steps' band levels printed beside it).
"""

import argparse

import numpy as np
from scipy import signal

import tomllib
from pathlib import Path

from studyapp.estimators.foaw import window_sizes
from studyapp.model import calibration
from studyapp.model.bowing_reference import pitch
from studyapp.model.breakdown import breakdown_fmax
from studyapp.model.data_set import TRAINING
from studyapp.model.loop import ClosedLoop, LoopConfig
from studyapp.model.simulate import simulate

RATE = 5000.0
TABLE1 = tomllib.loads((Path(__file__).resolve().parents[1] / "protocols" / "sinclair2014.toml").read_text())["estimators"]
STEPS = (0.5, 0.75, 1.0, 1.25, 1.5)
STEP_SECONDS = 3.0


def level_db(audio, low=100.0, high=400.0, rate=RATE):
    f, p = signal.welch(audio, fs=rate, nperseg=4096)
    band = (f >= low) & (f <= high)
    return 10.0 * np.log10(np.sum(p[band]) * (f[1] - f[0]))


def peak_hz(x, rate=RATE, fmin=30.0):
    x = np.asarray(x) - np.mean(x)
    n = 1 << int(np.ceil(np.log2(x.size * 4)))
    spec = np.abs(np.fft.rfft(x * np.hanning(x.size), n))
    f = np.fft.rfftfreq(n, 1.0 / rate)
    spec[f < fmin] = 0.0
    return float(f[int(np.argmax(spec))])


def estimators(source):
    return {} if source in ("LVT", "TRUE") else {source: TABLE1.get(source, {})}


def loop(source, fmax, gesture, rate=RATE, seed=0):
    return ClosedLoop(LoopConfig(rate=rate, estimators=estimators(source), source=source, fmax=fmax,
                                 gesture=gesture, seed=seed))


def stepping(source, level):
    """Audio while ``source`` steps through STEPS x ``level`` on strokes (one loop, F_max set per step)."""
    lp = loop(source, STEPS[0] * level, "strokes")
    parts = []
    for fraction in STEPS:
        lp.set_fmax(fraction * level)
        parts.append(lp.run(int(STEP_SECONDS * RATE))["audio"])
    return parts


def spectrogram_figure(source, level, parts):
    from matplotlib.figure import Figure

    audio = np.concatenate(parts)
    fig = Figure(figsize=(8.0, 4.2), layout="constrained")
    ax = fig.add_subplot()
    f, t, sxx = signal.spectrogram(audio, fs=RATE, nperseg=512, noverlap=384)
    keep = f <= 1000.0
    db = 10.0 * np.log10(sxx[keep] + 1e-16)
    top = float(np.ceil(np.percentile(db, 99.9) / 10.0) * 10.0)  # the scale follows the audio's level
    mesh = ax.pcolormesh(t, f[keep], db, shading="auto", cmap="magma", vmin=top - 70.0, vmax=top)
    fig.colorbar(mesh, ax=ax, label="dB")
    ax.axhspan(100.0, 400.0, color="white", alpha=0.08)
    for i, fraction in enumerate(STEPS):
        ax.axvline(i * STEP_SECONDS, color="white", lw=0.6)
        ax.text(i * STEP_SECONDS + 0.1, 930.0, f"{fraction:g} x", color="white", fontsize=8,
                bbox=dict(facecolor="black", alpha=0.6, pad=1.5, lw=0))
    ax.set_xlabel("time (s)")
    ax.set_ylabel("frequency (Hz)")
    ax.set_title(f"{source} bowing strokes, F_max stepping through its breakdown ({level:.3g} N)", fontsize=10)
    return fig


def inharmonic_db(audio, f0, rate=RATE):
    """Level (dB) of the audio at 50-2500 Hz outside +-3 % of every multiple of f0."""
    f, p = signal.welch(audio, fs=rate, nperseg=4096)
    n = np.round(f / f0)
    keep = (f >= 50.0) & (f <= 2500.0) & ((n < 1) | (np.abs(f - n * f0) > 0.03 * n * f0))
    return 10.0 * np.log10(np.sum(p[keep]) * (f[1] - f[0]))


def hearing(source, seed):
    """(band rise, 50-400 Hz rise, inharmonic rise, distance-from-TRUE rise) in dB, 0.8 -> 1.25 x breakdown."""
    from studyapp.evaluation.perceptual import audio_distance

    level = breakdown_fmax(source, tolerance=0.05, seed=seed, estimators=estimators(source))
    rows = []
    for fraction in (0.8, 1.25):
        fmax = fraction * level
        audio = simulate(fmax, rate=RATE, duration=5.0, source=source, seed=seed,
                         estimators=estimators(source)).columns["audio"][int(0.25 * RATE):]
        true = simulate(fmax, rate=RATE, duration=5.0, source="TRUE", seed=seed).columns["audio"][int(0.25 * RATE):]
        rows.append((level_db(audio), level_db(audio, 50.0, 400.0), inharmonic_db(audio, calibration.F0),
                     20.0 * np.log10(max(audio_distance(true, audio, RATE), 1e-9))))
    return level, [hi - lo for lo, hi in zip(*rows)]


BANDS = ((0, 20), (20, 50), (50, 100), (100, 400), (400, 2500))  # Hz
PAPER_SIGNALS = ((12.1, 14), (7.7, 12))  # (F_max N, the training set's recording index)
PITCH_RATES = (5000.0, 20000.0, 48000.0)


def buzz_hz(source, fmax):
    """The handle's velocity's spectral peak above 50 Hz (after 1 s) over 5 s of strokes at ``fmax``."""
    b = loop(source, min(fmax, 200.0), "strokes").run(int(5 * RATE))
    return peak_hz(b["velocity_true"][int(RATE):], fmin=50.0)


def band_rms(source, fmax):
    """The handle's velocity per BANDS (mm/s RMS, after 0.25 s) over 5 s of strokes at ``fmax``, seed 0."""
    v = loop(source, fmax, "strokes").run(int(5 * RATE))["velocity_true"][int(0.25 * RATE):]
    f, p = signal.welch(v, fs=RATE, nperseg=2048)
    return [1e3 * np.sqrt(np.sum(p[(f >= lo) & (f < hi)]) * (f[1] - f[0])) for lo, hi in BANDS]


def paper_signals(fmax, index, seed=None):
    """(max |dv/dt| m/s^2, mm/s RMS above 100 Hz, % of samples at FOAW's maximum window) of ``velocity_lvt``
    on the training set's recording ``index`` (LVT in the loop at ``fmax`` N, 7 s; ``seed``: another seed)."""
    seed = TRAINING["seed"] * 1000 + index if seed is None else seed
    rec = simulate(fmax, rate=RATE, duration=7.0, source="LVT", seed=seed)
    v = rec.columns["velocity_lvt"]
    hp = signal.sosfilt(signal.butter(2, 100.0, "high", fs=RATE, output="sos"), v)
    window = window_sizes(rec.columns["position"], TABLE1["FOAW"]["window"], TABLE1["FOAW"]["margin"])
    return (float(np.max(np.abs(np.diff(v))) * RATE), float(1e3 * np.sqrt(np.mean(hp ** 2))),
            float(100 * np.mean(window == TABLE1["FOAW"]["window"])))


def loop_pitch(rate, seed=0):
    """The string's pitch (Hz, after 0.25 s) with LVT at 2 N on 5 s of strokes at ``rate``."""
    b = loop("LVT", 2.0, "strokes", rate, seed).run(int(5 * rate))
    return pitch(b["string_velocity"][int(0.25 * rate):], rate)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--png", help="write the spectrogram here")
    parser.add_argument("--source", default="LVT")
    parser.add_argument("--seeds", type=int, default=3)
    parser.add_argument("--only-png", action="store_true", help="only the spectrogram")
    parser.add_argument("--only-signals", action="store_true", help="only the paper's signals and the pitches")
    args = parser.parse_args(argv)
    if args.only_png:
        return png(args.source, args.png, {})
    if args.only_signals:
        return signals()
    print(f"f0 {calibration.F0:g} Hz, beta {calibration.BOW_POSITION:g}, velocity scale "
          f"{calibration.VELOCITY_SCALE:g}, end-effector {calibration.DEVICE_MASS:g} kg on a grip of "
          f"{calibration.GRIP_STIFFNESS:g} N/m, {calibration.GRIP_DAMPING:g} N s/m")
    levels = {}
    for source in ("LVT", "LOWPASS", "KALPOS", "LEVANT", "FOAW", "TRUE"):
        levels[source] = breakdown_fmax(source, tolerance=0.05, estimators=estimators(source))
        print(f"{source}: bowing breakdown {levels[source]:.3g} N (seed 0); handle's buzz at 1.25 x: "
              f"{buzz_hz(source, 1.25 * levels[source]):.0f} Hz")
    for source, fmax in (("TRUE", 4.0), ("TRUE", 1.25 * levels["LVT"]), ("LVT", 1.25 * levels["LVT"]),
                         ("LOWPASS", 1.25 * levels["LOWPASS"]), ("KALPOS", 1.25 * levels["KALPOS"])):
        print(f"{source} at {fmax:.3g} N, handle's velocity per band (mm/s RMS): " + ", ".join(
            f"{lo}-{hi} Hz {rms:.1f}" for (lo, hi), rms in zip(BANDS, band_rms(source, fmax))))
    for source in ("LVT", "LOWPASS", "KALPOS", "LEVANT", "FOAW", "LEVANTLP", "KALLEV", "KALFOAW", "LEASTSQ"):
        rises = [hearing(source, seed)[1] for seed in range(args.seeds)]
        lo = np.min(rises, axis=0)
        hi = np.max(rises, axis=0)
        names = ("100-400 Hz", "50-400 Hz", "inharmonic", "distance from TRUE")
        print(f"{source} rise 0.8 -> 1.25 x, seeds 0-{args.seeds - 1} (dB): "
              + ", ".join(f"{n} {a:.1f}..{b:.1f}" for n, a, b in zip(names, lo, hi)))
    signals()
    if args.png:
        png(args.source, args.png, levels)


def signals():
    for fmax, index in PAPER_SIGNALS:
        dvdt, high, at_max = paper_signals(fmax, index)
        print(f"data set at {fmax:g} N: max |dv/dt| {dvdt:.0f} m/s^2, above 100 Hz "
              f"{high:.2f} mm/s RMS, FOAW at its maximum window {at_max:.1f} % of samples")
    for rate in PITCH_RATES:
        print(f"pitch at {rate:g} Hz, LVT at 2 N on strokes: {loop_pitch(rate):.1f} Hz")


def png(source, path, levels):
    level = levels.get(source) or breakdown_fmax(source, tolerance=0.05, estimators=estimators(source))
    parts = stepping(source, level)
    print(f"{source} stepping on strokes, band level per step: "
          + ", ".join(f"{f:g} x {level_db(p):.1f} dB" for f, p in zip(STEPS, parts)))
    spectrogram_figure(source, level, parts).savefig(path, dpi=100)


if __name__ == "__main__":
    main()
