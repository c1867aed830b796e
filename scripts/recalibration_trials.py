"""Issue 11, items 1 and 4 on strokes: the levers tried, one trial each, as the table in docs/model.md.

A record of issue 11's world (a rigid 1 kg handle, until 2026-11-25): since issue 20 the device is a
light end-effector on a grip, which this script makes rigid (RIGID_GRIP) so its trials stay issue 11's.

    PYTHONPATH=. python scripts/recalibration_trials.py [-o table.md] [--workers 2] [--only NAME ...]

Each trial changes a few of the model's constants in its own process (a fresh
fork per trial, so nothing leaks into the next) and measures, at 5 kHz, seed 0 (``--seed``):

- on strokes with LVT in the loop at F_max = 2, 5 and 8 N (3 s each): the
  handle's stick-slip ripple (studyapp.model.bowing_measures.ripple_rms, um RMS
  of the true position high-passed at 50 Hz over the strokes' cruise after
  0.5 s), at 2 N the stick fraction of the cruise and the median Helmholtz
  formation time over the strokes after the first (s; "never" when Helmholtz
  motion formed on none), and the string's pitch at 2 N (the spectral peak of
  the string velocity after 0.5 s, as tests/model/test_model_string.py does);
- breakdown F_max of LVT and LOWPASS with the hand holding
  (studyapp.model.breakdown.breakdown_fmax, tolerance 0.05) and their ratio;
- on strokes, for LVT, LOWPASS, KALPOS and LEVANTLP: the audio's 100-400 Hz
  level at 1.5 x the source's (held) breakdown F_max minus its level at 0.5 x,
  over 4 s after a 1 s settle (Welch, 4096 points), in dB.

Item 1 needs ripple >= 10 um at 2 N while LVT breaks down at >= 5 N: a
product ripple(2 N) x F_max(LVT) of at least 50 um N (its own column).

The constants are replaced for the trial only: the calibration module's
values, the string's beta, the simulated device's mass (device plus the hand
lumped with it: what moves at the loop mode when the grip decouples the rest
of the hand), the contact microphone's gain, and the strokes (the shipped
raised-cosine strokes, or strokes whose onset accelerates at a constant rate,
Guettler's attack, played back as a trajectory).
"""

import argparse
import functools
import math
import multiprocessing
import sys

import numpy as np
from scipy import signal

RATE = 5000.0
SEED = 0
RIGID_GRIP = (1e7, 1e4)  # N/m, N s/m: the grip of issue 20's device made rigid for issue 11's handle
# the model before 2026-11-23: a 147 Hz string bowed at STK's beta, velocity scale 0.6, contact microphone 2e-3;
# every trial is written as its changes to it
BASE = dict(mass=1.0, s=0.6, f0=147.0, beta=0.127236, speed=0.04, accel=None, dwell=0.1, mic=2e-3)
SHIPPED = dict(f0=440.0, beta=0.25, mic=0.02, s=1.2)  # calibration.py since 2026-11-23
# (name, lever, changes against BASE)
TRIALS = [
    ("147 Hz", "none: the model before 2026-11-23", {}),
    ("guettler", "onset at constant acceleration 50 m/s^2, 0.08 m/s", dict(speed=0.08, accel=50.0)),
    ("guettler-fast", "onset 80 m/s^2, 0.12 m/s", dict(speed=0.12, accel=80.0)),
    ("f0-98", "98 Hz string", dict(f0=98.0)),
    ("f0-98-guettler", "98 Hz string, onset 50 m/s^2, 0.08 m/s", dict(f0=98.0, speed=0.08, accel=50.0)),
    ("f0-440", "440 Hz string (violin A): its sound above the 100-400 Hz band", dict(f0=440.0)),
    ("f0-440-mic-x100", "440 Hz string, contact microphone gain 0.2 (x100)", dict(f0=440.0, mic=0.2)),
    ("f0-440-beta-0.2", "440 Hz string, bow at beta 0.2 (2.3 samples to the bridge at 5 kHz)",
     dict(f0=440.0, beta=0.2)),
    ("f0-440-beta-0.25", "440 Hz string, beta 0.25", dict(f0=440.0, beta=0.25)),
    ("f0-440-beta-0.25-mic-x10", "440 Hz string, beta 0.25, mic gain 0.02 (x10)", dict(f0=440.0, beta=0.25,
                                                                                         mic=0.02)),
    ("a440-s1.2", "440 Hz, beta 0.25, mic x10, velocity scale 1.2: shipped since 2026-11-23", SHIPPED),
    ("a440-s1.5", "440 Hz, beta 0.25, mic x10, velocity scale 1.5", dict(f0=440.0, beta=0.25, mic=0.02, s=1.5)),
    ("a440-m0.5", "440 Hz, beta 0.25, mic x10, 0.5 kg", dict(f0=440.0, beta=0.25, mic=0.02, mass=0.5)),
    ("a440-b0.2-s1.2", "440 Hz, beta 0.2, mic x10, velocity scale 1.2", dict(f0=440.0, beta=0.2, mic=0.02, s=1.2)),
    ("beta-0.09", "bow closer to the bridge (beta 0.09)", dict(beta=0.09)),
    ("light-0.5", "0.5 kg at the loop mode, 98 Hz, onset 50 m/s^2", dict(mass=0.5, f0=98.0, speed=0.08,
                                                                          accel=50.0)),
    ("light-0.15", "0.15 kg at the loop mode, onset 50 m/s^2, 0.08 m/s", dict(mass=0.15, speed=0.08, accel=50.0)),
    ("light-0.15-s0.3", "0.15 kg, s 0.3, onset 60 m/s^2, 0.16 m/s", dict(mass=0.15, s=0.3, speed=0.16,
                                                                        accel=60.0)),
    ("light-0.25-s0.15", "0.25 kg, s 0.15, onset 50 m/s^2, 0.1 m/s", dict(mass=0.25, s=0.15, speed=0.1,
                                                                          accel=50.0)),
    ("light-0.25-s0.15-98", "as above, 98 Hz string", dict(mass=0.25, s=0.15, f0=98.0, speed=0.1, accel=50.0)),
    ("mic-x100", "contact microphone gain 0.2 (x100)", dict(mic=0.2)),
    ("mic-x100-dwell-0.3", "mic gain 0.2, 0.3 s dwell at the stroke ends", dict(mic=0.2, dwell=0.3)),
    ("mic-x100-dwell-0.5", "mic gain 0.2, 0.5 s dwell", dict(mic=0.2, dwell=0.5)),
    ("mic-x1000-dwell-0.3", "mic gain 2.0 (x1000), 0.3 s dwell", dict(mic=2.0, dwell=0.3)),
]
COLUMNS = ("trial", "lever", "ripple 2/5/8 N (um)", "stick", "formation (s)", "pitch (Hz)", "LVT (N)",
           "LOWPASS (N)", "ratio", "ripple 2 N x LVT (um N)", "rise LVT/LOWPASS/KALPOS/LEVANTLP (dB)")


def constant_acceleration_strokes(rate, duration, amplitude, speed, accel, dwell):
    """Positions (m): 0 -> +A, then between +-A; each stroke accelerates at ``accel`` to ``speed``, cruises,
    decelerates at ``accel`` and dwells."""
    n = int(duration * rate)
    parts, total, first = [], 0, True
    while total < n:
        length = amplitude if first else 2.0 * amplitude
        direction = 1.0 if first or len(parts) % 2 == 0 else -1.0
        first = False
        ramp = int(round(speed / accel * rate))
        cruise = int(round(max(length - speed * speed / accel, 0.0) / speed * rate))
        up = np.arange(ramp) / rate * accel
        profile = np.r_[up, np.full(cruise, speed), speed - up, np.zeros(int(round(dwell * rate)))]
        parts.append(direction * profile)
        total += profile.size
    return np.cumsum(np.concatenate(parts)[:n]) / rate


def apply(cfg):
    """Replace the model's constants in this process for one trial."""
    from studyapp.model import bowed_string, calibration, contact_mic, hand
    from studyapp.model import breakdown as breakdown_module
    from studyapp.model import loop as loop_module
    from studyapp.model.gestures import Playback, Strokes
    from studyapp.model.simulated_device import SimulatedDevice

    calibration.VELOCITY_SCALE = cfg["s"]
    calibration.F0 = cfg["f0"]
    breakdown_module.F0 = cfg["f0"]
    bowed_string.StringDesign = functools.partial(bowed_string.StringDesign, beta=cfg["beta"])
    # issue 11's rigid handle: the hand lumped with the device through a grip too stiff and damped to move
    impedance = hand.HandImpedance(0.8 * cfg["mass"], calibration.HAND_STIFFNESS, calibration.HAND_DAMPING,
                                   calibration.HAND_REACTION, grip_stiffness=RIGID_GRIP[0],
                                   grip_damping=RIGID_GRIP[1])
    loop_module.SimulatedDevice = functools.partial(SimulatedDevice, mass=0.2 * cfg["mass"],
                                                    hand_impedance=impedance)
    mic_params = contact_mic.params
    contact_mic.params = lambda rate, gain=None: mic_params(rate, cfg["mic"])
    make_gesture = loop_module.make_gesture

    def strokes(name, rate, trajectory=None, position=0.0):
        if name != "strokes":
            return make_gesture(name, rate, trajectory, position)
        if cfg["accel"] is None:
            return Strokes(calibration.STROKE_AMPLITUDE, cfg["speed"], calibration.STROKE_RAMP, cfg["dwell"])
        return Playback(constant_acceleration_strokes(rate, 12.0, calibration.STROKE_AMPLITUDE, cfg["speed"],
                                                      cfg["accel"], cfg["dwell"]), rate)

    loop_module.make_gesture = strokes


def band_db(audio, low=100.0, high=400.0):
    f, p = signal.welch(audio, fs=RATE, nperseg=4096)
    band = (f >= low) & (f <= high)
    return 10.0 * np.log10(np.sum(p[band]) * (f[1] - f[0]))


def pitch(x, fmin=30.0):
    x = np.asarray(x) - np.mean(x)
    n = 1 << int(np.ceil(np.log2(x.size * 16)))
    spec = np.abs(np.fft.rfft(x * np.hanning(x.size), n))
    f = np.fft.rfftfreq(n, 1.0 / RATE)
    spec[f < fmin] = 0.0
    return float(f[int(np.argmax(spec))])


def cruise_pitch(string_velocity, cruise):
    """The pitch of the string over the longest cruise segment after 0.5 s (Hz)."""
    cruise = cruise.copy()
    cruise[: int(0.5 * RATE)] = False
    edges = np.flatnonzero(np.diff(np.r_[0, cruise.astype(np.int8), 0]))
    starts, ends = edges[0::2], edges[1::2]
    longest = int(np.argmax(ends - starts))
    return pitch(string_velocity[starts[longest]:ends[longest]])


def run_trial(trial):
    name, lever, changes = trial
    cfg = dict(BASE, **changes)
    apply(cfg)
    from studyapp.model import bowing_measures as bm
    from studyapp.model.breakdown import breakdown_fmax
    from studyapp.model.loop import ClosedLoop, LoopConfig

    def loop(source, fmax, gesture):
        estimators = {} if source in ("LVT", "TRUE") else {source: {}}
        return ClosedLoop(LoopConfig(rate=RATE, estimators=estimators, source=source, fmax=fmax, gesture=gesture,
                                     f0=cfg["f0"], seed=SEED))

    ripples = []
    for fmax in (2.0, 5.0, 8.0):
        lp = loop("LVT", fmax, "strokes")
        b = lp.run(int(3.0 * RATE))
        target_v = lp._gesture.block(0, b["t"].size, RATE)[1]
        ripples.append(1e6 * bm.ripple_rms(b["position_true"], target_v, RATE, start=0.5))
        if fmax == 2.0:
            stick = bm.stick_fraction(b["stick"], target_v, RATE, start=0.5)
            formed = [t for t in bm.formation_times(b["stick"], target_v, RATE, lp.string.f0, lp.string.beta)[1:]
                      if math.isfinite(t)]
            formation = float(np.median(formed)) if formed else math.inf
            f_pitch = cruise_pitch(b["string_velocity"], bm.cruise_mask(target_v, RATE))
    levels = {src: breakdown_fmax(src, tolerance=0.05, seed=SEED) for src in ("LVT", "LOWPASS", "KALPOS", "LEVANTLP")}
    rise = []
    for src, level in levels.items():
        db = []
        for fraction in (0.5, 1.5):
            lp = loop(src, fraction * level, "strokes")
            lp.run(int(RATE))
            db.append(band_db(lp.run(int(4 * RATE))["audio"]))
        rise.append(db[1] - db[0])
    return (name, lever, "/".join(f"{r:.2g}" for r in ripples), f"{stick:.2f}",
            "never" if math.isinf(formation) else f"{formation:.2f}", f"{f_pitch:.1f} ({cfg['f0']:g})",
            f"{levels['LVT']:.3g}", f"{levels['LOWPASS']:.3g}", f"{levels['LOWPASS'] / levels['LVT']:.2f}",
            f"{ripples[0] * levels['LVT']:.2g}",
            "/".join(f"{r:.1f}" for r in rise))


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("-o", "--output", help="write the Markdown table here as well")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--only", nargs="*", help="trial names")
    parser.add_argument("--seed", type=int, default=0, help="the sensors' noise and the tremor (default 0)")
    args = parser.parse_args(argv)
    global SEED
    SEED = args.seed
    trials = [t for t in TRIALS if not args.only or t[0] in args.only]
    context = multiprocessing.get_context("fork")
    with context.Pool(args.workers, maxtasksperchild=1) as pool:
        rows = []
        for row in pool.imap(run_trial, trials):
            print(" | ".join(row), file=sys.stderr, flush=True)
            rows.append(row)
    lines = ["| " + " | ".join(COLUMNS) + " |", "|" + "---|" * len(COLUMNS)]
    lines += ["| " + " | ".join(row) + " |" for row in rows]
    text = "\n".join(lines) + "\n"
    print(text)
    if args.output:
        with open(args.output, "w") as fh:
            fh.write(text)


if __name__ == "__main__":
    main()
