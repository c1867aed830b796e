"""The figures docs/model.md quotes about the shipped model (5 kHz, seed 0), and the breakdown spectrogram.

    PYTHONPATH=. python scripts/model_figures.py [--png docs/breakdown_strokes.png] [--source LOWPASS]

Prints, for the model as calibration.py sets it:

- breakdown: per source (LVT, LOWPASS, KALPOS, LEVANTLP, TRUE), the hand holding, the force's spectral
  peak at 1.1, 1.5 and 1.85 x its breakdown F_max (what frequency the loop oscillates at); the stability
  monitor's level and cv for a held handle at 10 mN and for two limit cycles;
- hearing it: on strokes at 0.5 and 1.5 x, the audio's 100-400 Hz level, its total level (0-2.5 kHz),
  and the audio's spectral peak; and the band level at 0.5, 0.7, 0.9, 1.1 and 1.5 x, held and on strokes;
- bowing: with LVT and TRUE at 1, 2, 4, 8 and 12 N on strokes, the ripple (um RMS), the stick fraction
  and the Helmholtz formation times (bowing_measures.py); the sources the monitor flags on strokes at 20 N;
  the string's pitch over the strokes' cruise at 5, 20 and 48 kHz;

and with ``--png``, a spectrogram of the audio while ``--source`` steps through 0.5, 0.75, 1, 1.25 and
1.5 x its breakdown on strokes, 3 s each (the steps' band levels printed beside it).
"""

import argparse

import numpy as np
from scipy import signal

from studyapp.model import bowing_measures as bm
from studyapp.model import calibration
from studyapp.model.breakdown import breakdown_fmax, is_broken, sources
from studyapp.model.loop import ClosedLoop, LoopConfig
from studyapp.model.simulate import simulate

RATE = 5000.0
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


def loop(source, fmax, gesture, rate=RATE):
    estimators = {} if source in ("LVT", "TRUE") else {source: {}}
    return ClosedLoop(LoopConfig(rate=rate, estimators=estimators, source=source, fmax=fmax, gesture=gesture))


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
    mesh = ax.pcolormesh(t, f[keep], 10.0 * np.log10(sxx[keep] + 1e-16), shading="auto", cmap="magma",
                         vmin=-120.0, vmax=-40.0)
    fig.colorbar(mesh, ax=ax, label="dB")
    ax.axhspan(100.0, 400.0, color="white", alpha=0.08)
    for i, fraction in enumerate(STEPS):
        ax.axvline(i * STEP_SECONDS, color="white", lw=0.6)
        ax.text(i * STEP_SECONDS + 0.1, 930.0, f"{fraction:g} x", color="white", fontsize=8)
    ax.set_xlabel("time (s)")
    ax.set_ylabel("frequency (Hz)")
    ax.set_title(f"{source} on strokes, F_max stepping through its breakdown ({level:.3g} N)", fontsize=10)
    return fig


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--png", help="write the spectrogram here")
    parser.add_argument("--source", default="LOWPASS")
    args = parser.parse_args(argv)
    print(f"f0 {calibration.F0:g} Hz, beta {calibration.BOW_POSITION:g}, velocity scale "
          f"{calibration.VELOCITY_SCALE:g}, contact microphone {calibration.CONTACT_MIC_GAIN:g}")
    levels = {}
    for source in ("LVT", "LOWPASS", "KALPOS", "LEVANTLP", "TRUE"):
        levels[source] = breakdown_fmax(source, tolerance=0.05)
        peaks = []
        for fraction in (1.1, 1.5, 1.85):
            lp = loop(source, min(fraction * levels[source], 200.0), "hold")
            lp.run(int(RATE))
            peaks.append(peak_hz(lp.run(int(4 * RATE))["force"], fmin=2.0))
        print(f"{source}: breakdown {levels[source]:.3g} N; force peak at 1.1/1.5/1.85 x: "
              + "/".join(f"{p:.0f}" for p in peaks) + " Hz")
    for source, fmax in (("LVT", 0.01), ("LOWPASS", 0.01), ("LOWPASS", 9.8), ("LVT", 13.3)):
        lp = loop(source, fmax, "hold")
        for _ in range(20):
            lp.run(500)
        print(f"monitor, {source} held at {fmax:g} N: level {1e3 * lp.monitor.level:.3f} mm/s, "
              f"cv {lp.monitor.cv:.3f}, broken {lp.monitor.broken}")
    for source in ("LVT", "LOWPASS", "KALPOS", "LEVANTLP"):
        for fraction in (0.5, 1.5):
            rec = simulate(fraction * levels[source], rate=RATE, duration=5.0, source=source, gesture="strokes")
            audio = rec.columns["audio"][int(RATE):]
            print(f"{source} strokes {fraction:g} x: band {level_db(audio):.1f} dB, total "
                  f"{level_db(audio, 0.0, 2500.0):.1f} dB, audio peak {peak_hz(audio):.1f} Hz")
        steps = []
        for gesture in ("hold", "strokes"):
            for fraction in (0.5, 0.7, 0.9, 1.1, 1.5):
                rec = simulate(fraction * levels[source], rate=RATE, duration=5.0, source=source, gesture=gesture)
                steps.append(f"{gesture} {fraction:g}: {level_db(rec.columns['audio'][int(RATE):]):.0f}")
        print(f"{source} band level (dB): " + ", ".join(steps))
    for source in ("TRUE", "LVT"):
        for fmax in (1.0, 2.0, 4.0, 8.0, 12.0):
            lp = loop(source, fmax, "strokes")
            b = lp.run(int(4 * RATE))
            target_v = lp._gesture.block(0, b["t"].size, RATE)[1]
            times = bm.formation_times(b["stick"], target_v, RATE, lp.string.f0, lp.string.beta)[1:]
            print(f"{source} {fmax:g} N strokes: ripple {1e6 * bm.ripple_rms(b['position_true'], target_v, RATE, 0.5):.3f}"
                  f" um, stick {bm.stick_fraction(b['stick'], target_v, RATE, 0.5):.2f}, formation "
                  + ", ".join(f"{t:.3f}" for t in times) + " s")
    print("flagged on strokes at 20 N:", [s for s in sources() if is_broken(s, 20.0, gesture="strokes")])
    for rate in (5000.0, 20000.0, 48000.0):
        lp = loop("LVT", 2.0, "strokes", rate)
        b = lp.run(int(3 * rate))
        cruise = bm.cruise_mask(lp._gesture.block(0, b["t"].size, rate)[1], rate)
        cruise[: int(0.5 * rate)] = False
        edges = np.flatnonzero(np.diff(np.r_[0, cruise.astype(np.int8), 0]))
        pitches = [peak_hz(b["string_velocity"][a:e], rate) for a, e in zip(edges[0::2], edges[1::2])]
        print(f"pitch at {rate:g} Hz, 2 N, per cruise: " + ", ".join(f"{p:.1f}" for p in pitches))
    if args.png:
        level = levels.get(args.source) or breakdown_fmax(args.source, tolerance=0.05)
        parts = stepping(args.source, level)
        print(f"{args.source} stepping on strokes, band level per step: "
              + ", ".join(f"{f:g} x {level_db(p):.1f} dB" for f, p in zip(STEPS, parts)))
        spectrogram_figure(args.source, level, parts).savefig(args.png, dpi=100)


if __name__ == "__main__":
    main()
